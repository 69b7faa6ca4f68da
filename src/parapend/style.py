"""One look for every parapend figure, applied in a context (matplotlib's global state is not
changed at import, nor left changed after a figure is drawn).

Text uses matplotlib's own mathtext (``$\\gamma$``), never LaTeX (``text.usetex``), so figures
render the same on every machine without a TeX installation.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = ["RC", "figure_style", "use_agg"]

#: rcParams of every figure; :func:`figure_style` applies them while a figure is built, and
#: :func:`parapend.fileio.save_figure` while it is rendered.
RC = {
    "text.usetex": False,
    "mathtext.fontset": "dejavusans",
    "font.family": "DejaVu Sans",
    "font.size": 10,
    "axes.titlesize": 10,
    "axes.labelsize": 10,
    "legend.fontsize": 8,
    "legend.framealpha": 0.9,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "lines.linewidth": 1.4,
    "savefig.dpi": 200,
    "svg.fonttype": "path",
}


@contextlib.contextmanager
def figure_style() -> Iterator[None]:
    """Context (also usable as a decorator) in which figures get parapend's look."""
    from matplotlib import rc_context

    with rc_context(RC):
        yield


def use_agg() -> None:
    """Draw with matplotlib's Agg backend (figures are written to files), except in a Jupyter
    kernel: there ``MPLBACKEND`` names the inline backend, which shows the figures the
    plotting functions return, and switching to Agg would hide them."""
    import os

    import matplotlib

    if "inline" not in os.environ.get("MPLBACKEND", ""):
        matplotlib.use("Agg", force=False)
