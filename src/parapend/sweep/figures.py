"""Heat maps of a sweep: :func:`map_data` (the 2-D slice of a store's Dataset) and
:func:`plot_map`. They read a Dataset (:func:`open_sweep`), not a result object.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .spec import _AXIS_ATTRS, _CODE, _SUCCESS, AXES, VARIABLES

__all__ = ["MAP_QUANTITIES", "map_data", "plot_map"]


# -- heat maps -----------------------------------------------------------------------------

#: What ``parapend map`` can draw: a variable of the store, or ``gain`` (over uniform).
MAP_QUANTITIES = ("power", "gain", "damping_threshold", "uniform_power", "limit_power",
                  "electrical_power", "branch_gap")
_PAPER = {"omega": 1.8, "delta": -0.3, "gamma": 0.0}
_SHORT = {"power": "optimal power P", "gain": "gain over the best uniform rotation",
          "damping_threshold": "damping threshold gamma*",
          "uniform_power": "power of the best uniform rotation",
          "limit_power": "limit power (gamma -> 0)", "electrical_power": "electrical power",
          "branch_gap": "continued branch above the global search"}
_LABELS = {"omega": r"$\omega$", "delta": r"$\delta$", "gamma": r"$\gamma$",
           "torque_limit": r"$T_{max}$", "efficiency": r"$\eta$"}


def map_data(ds, quantity: str = "power", x: str | None = None, y: str | None = None,
             at: dict | None = None):
    """The 2-D slice a heat map shows: ``(values over (y, x), failed mask, title, label)``.

    ``gain`` is ``power / uniform_power - 1`` in percent. Points not computed are NaN;
    failed points (status other than converged and no_power) are NaN and flagged.
    Dimensions other than ``x`` and ``y`` are selected by ``at`` (nearest value; default
    their first value).
    """
    if quantity not in MAP_QUANTITIES:
        raise ParameterError(f"variable: expected one of {', '.join(MAP_QUANTITIES)}, got "
                             f"{quantity!r:.40}")
    need = "power" if quantity == "gain" else quantity
    if need not in ds:
        raise ParameterError(f"variable: {quantity!r} is not in this store (threshold maps "
                             "need a sweep with --threshold)")
    dims = [d for d in AXES if d in ds.dims]
    if len(dims) < 2:
        raise ParameterError(f"store: a heat map needs two swept axes, this store has "
                             f"{', '.join(dims) or 'none'}")
    x = x or dims[0]
    y = y or next(d for d in dims if d != x)
    for name, v in (("x", x), ("y", y)):
        if v not in dims:
            raise ParameterError(f"{name}: expected one of the store's axes "
                                 f"{', '.join(dims)}, got {v!r:.40}")
    if x == y:
        raise ParameterError("x, y: expected two different axes")
    at = dict(at or {})
    for k in at:
        if k not in dims or k in (x, y):
            raise ParameterError(f"at: {k!r:.40} is not another axis of the store "
                                 f"({', '.join(d for d in dims if d not in (x, y)) or 'none'})")
    sel = {d: ds[d].values[0] for d in dims if d not in (x, y)}
    sel.update(at)
    sub = ds.sel(sel, method="nearest") if sel else ds
    sub = sub.transpose(y, x)
    status = sub["status"]
    ok = sub["done"].values & np.isin(status.values, [_CODE[s] for s in _SUCCESS])
    failed = sub["done"].values & ~ok
    if quantity == "gain":  # as optimize's gain_over_uniform: none where uniform <= 0
        pu = sub["uniform_power"].values
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(pu > 0, 100.0 * (sub["power"].values / pu - 1.0), np.nan)
    else:
        z = np.array(sub[quantity].values, dtype=float)
    label = _SHORT[quantity]
    units = "%" if quantity == "gain" else VARIABLES[quantity][1]
    label = f"{label} ({units})" if units else label
    if quantity == "damping_threshold":
        ok = sub["done"].values & np.isin(sub["threshold_status"].values,
                                          [_CODE[s] for s in _SUCCESS])
        failed = sub["done"].values & ~ok
    z = np.where(ok, z, np.nan)
    fixed = {**{a: float(ds[a]) for a in AXES if a in ds.coords and ds[a].ndim == 0},
             **{k: float(sub[k]) for k in sel}}
    if quantity == "damping_threshold":  # gamma* depends on the excitation only
        fixed = {k: v for k, v in fixed.items() if k in ("omega", "delta")}
    title = ", ".join(f"{k} = {v:.4g}" for k, v in fixed.items())
    return z, failed, sub[x].values, sub[y].values, x, y, label, title


def plot_map(ds, quantity: str = "power", x=None, y=None, at=None, path=None):
    """Heat map of ``quantity`` over two axes, with labelled contour lines, the zero
    contour of the power (where it crosses gamma*) in black, failed points crossed, and the
    paper's case (omega = 1.8, delta = -0.3, gamma = 0) marked when inside the map."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..fileio import save_figure
    from ..style import figure_style

    z, failed, xs, ys, xn, yn, label, title = map_data(ds, quantity, x, y, at)
    with figure_style():
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
        cmap = plt.get_cmap("viridis").with_extremes(bad="0.85")
        finite = np.isfinite(z)
        lo, hi = (np.percentile(z[finite], [1, 99]) if finite.sum() >= 100 else
                  (np.nanmin(z), np.nanmax(z)) if finite.any() else (0.0, 1.0))
        # a few extreme points (the gain where the uniform rotation's power tends to 0)
        # would flatten the rest: the colours span the 1st to 99th percentile
        clipped = finite.any() and (np.nanmin(z) < lo or np.nanmax(z) > hi)
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(z), shading="nearest", cmap=cmap,
                             vmin=lo, vmax=hi)
        cb = fig.colorbar(mesh, ax=ax, extend="both" if clipped else "neither")
        cb.set_label(label)
        if min(z.shape) >= 3 and finite.sum() >= 9 and hi > lo:
            cs = ax.contour(xs, ys, np.ma.masked_invalid(z), levels=np.linspace(lo, hi, 9)[1:-1],
                            colors="white", linewidths=0.7)
            ax.clabel(cs, fontsize=7, fmt="%.3g")
            if quantity in ("power", "electrical_power") and np.nanmin(z) < 0 < np.nanmax(z):
                ax.contour(xs, ys, np.ma.masked_invalid(z), levels=[0.0], colors="black",
                           linewidths=1.2)
        if failed.any():
            yy, xx = np.nonzero(failed)
            ax.plot(xs[xx], ys[yy], "x", color="red", ms=4, label="failed (see status)")
        px, py = _PAPER.get(xn), _PAPER.get(yn)
        if (px is not None and py is not None and xs.min() <= px <= xs.max()
                and ys.min() <= py <= ys.max()):
            ax.plot([px], [py], marker="*", color="red", ms=12, mec="white", ls="none",
                    label=r"paper's case ($\omega$ = 1.8, $\delta$ = -0.3)")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best")
        for name, setter in ((xn, ax.set_xlabel), (yn, ax.set_ylabel)):
            unit = _AXIS_ATTRS[name][1]
            setter(_LABELS[name] + ("" if unit == "1" else f" ({unit})"))
        ax.grid(False)
        if title:
            ax.set_title(title)
        fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig
