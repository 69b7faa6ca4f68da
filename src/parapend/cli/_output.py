"""Every file the command line writes goes through this module.

Kept thin on purpose: the functions here are the one place to rewire when file writing
changes (e.g. umask-respecting atomic writes in ``parapend.fileio``).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["save_figure", "write_dataset", "write_text"]


def write_text(path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file (an old file is never half-written)."""
    p = Path(path)
    fd, tmp = tempfile.mkstemp(dir=p.parent if str(p.parent) else ".", prefix=".tmp-")
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_dataset(ds, path) -> None:
    """Write a Dataset to NetCDF through a temporary file (an old file is never half-written)."""
    p = Path(path)
    fd, tmp = tempfile.mkstemp(dir=p.parent if str(p.parent) else ".", prefix=".tmp-",
                               suffix=".nc")
    os.close(fd)
    try:
        ds.to_netcdf(tmp)
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def save_figure(fig, path) -> None:
    """Save a matplotlib figure by extension (PNG, SVG, PDF) via :mod:`parapend.plotting`."""
    from ..plotting import save_figure as _save

    _save(fig, path)
