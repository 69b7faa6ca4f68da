"""Heat maps of a sweep: :func:`map_data` (the 2-D slice of a store's Dataset) and
:func:`plot_map`. They read a Dataset (:func:`open_sweep`), not a result object.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from .spec import _AXIS_ATTRS, _CODE, _SUCCESS, AXES, VARIABLES

__all__ = ["MAP_QUANTITIES", "map_data", "plot_map", "plot_sweep"]


# -- heat maps -----------------------------------------------------------------------------

#: What ``parapend map`` can draw: a variable of the store, or ``gain`` (over uniform).
MAP_QUANTITIES = ("power", "gain", "damping_threshold", "uniform_power", "limit_power",
                  "electrical_power", "mechanical_power", "branch_gap")
_PAPER = {"omega": 1.8, "delta": -0.3, "gamma": 0.0}
_SHORT = {"power": "optimal power P", "gain": "gain over the best uniform rotation",
          "damping_threshold": "damping threshold gamma*",
          "uniform_power": "power of the best uniform rotation",
          "limit_power": "limit power (gamma -> 0)", "electrical_power": "electrical power",
          "mechanical_power": "mechanical power of the electrical optimum",
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
    if ds.attrs.get("product") == "power matrix":
        raise ParameterError("store: it holds a power matrix, not a design map; draw it with "
                             "parapend power-matrix --plot PREFIX (the same options and "
                             "--store resume it without computing)")
    if quantity not in MAP_QUANTITIES:
        raise ParameterError(f"variable: expected one of {', '.join(MAP_QUANTITIES)}, got "
                             f"{quantity!r:.40}")
    # with an efficiency, power is the electrical power (the headline) and the gain stays the
    # mechanical power's over the (ideal) uniform rotation's, as before
    lossy = "mechanical_power" in ds
    top = "mechanical_power" if lossy else "power"
    need = top if quantity == "gain" else quantity
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
            z = np.where(pu > 0, 100.0 * (sub[top].values / pu - 1.0), np.nan)
    else:
        z = np.array(sub[quantity].values, dtype=float)
    label = ("optimal electrical power" if quantity == "power" and lossy else
             "gain of the mechanical power over the best uniform rotation"
             if quantity == "gain" and lossy else _SHORT[quantity])
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


#: a tail of the values beyond the 1st (99th) percentile longer than this fraction of the
#: span between them is drawn compressed into the end of the colour bar
_TAIL = 0.5
#: the share of the colour bar a compressed tail takes
_TAIL_SHARE = 0.15
#: contour labels stay this far (a fraction of the axes) from the edges
_EDGE = 0.08
#: a contour line shorter than this (a fraction of the axes' diagonal) gets no label
_SHORT_LINE = 0.2


def colour_scale(z):
    """The colour scale of a heat map of ``z``: ``(knots, shares)``, increasing.

    The colours run from ``z``'s minimum to its maximum, linearly between the knots (values)
    and the shares of the colour bar they take (0 to 1). When the values beyond the 1st or
    99th percentile reach further than half the span between them (the gain where the
    uniform rotation's power tends to 0), that tail takes the last 15 % of the bar, so that
    it does not flatten the rest: knots ``(min, p1, p99, max)`` at ``(0, 0.15, 0.85, 1)``,
    without the tail that is not long. Otherwise two knots, ``(min, max)``: one linear scale.
    """
    finite = np.asarray(z, dtype=float)[np.isfinite(z)]
    if not finite.size:
        return (0.0, 1.0), (0.0, 1.0)
    zmin, zmax = float(finite.min()), float(finite.max())
    if zmax <= zmin:
        return (zmin - 0.5, zmax + 0.5), (0.0, 1.0)
    knots, shares = [zmin], [0.0]
    if finite.size >= 100:
        p1, p99 = (float(v) for v in np.percentile(finite, [1, 99]))
        span = p99 - p1
        if span > 0 and p1 - zmin > _TAIL * span:
            knots.append(p1)
            shares.append(_TAIL_SHARE)
        if span > 0 and zmax - p99 > _TAIL * span:
            knots.append(p99)
            shares.append(1.0 - _TAIL_SHARE)
    knots.append(zmax)
    shares.append(1.0)
    return tuple(knots), tuple(shares)


def _label_points(ax, cs, avoid=()) -> tuple[list, list]:
    """Where the contour labels go: for each level, on its longest line, at the point
    nearest the line's middle that is at least ``_EDGE`` inside the axes and as far from
    the points ``avoid`` (data coordinates: a marker); no label on a line shorter than
    ``_SHORT_LINE`` of the axes (where many levels crowd into a steep strip). Returns
    (levels, points in data coordinates)."""
    to_axes = ax.transData + ax.transAxes.inverted()
    marks = to_axes.transform(np.reshape(np.asarray(avoid, dtype=float), (-1, 2)))
    levels, points = [], []
    for level, segs in zip(cs.levels, cs.allsegs):
        best = None
        for seg in segs:
            if len(seg) < 2:
                continue
            a = to_axes.transform(seg)
            step = np.hypot(*np.diff(a, axis=0).T)
            if best is None or step.sum() > best[0]:
                best = (float(step.sum()), seg, a, step)
        if best is None or best[0] < _SHORT_LINE * math.sqrt(2):
            continue
        length, seg, a, step = best
        along = np.concatenate([[0.0], np.cumsum(step)])
        inside = np.all((a > _EDGE) & (a < 1 - _EDGE), axis=1)
        for m in marks:
            inside &= np.hypot(*(a - m).T) > _EDGE
        if not inside.any():
            continue
        k = int(np.argmin(np.where(inside, np.abs(along - length / 2), np.inf)))
        levels.append(level)
        points.append(tuple(seg[k]))
    return levels, points


def _axis_label(name: str) -> str:
    unit = _AXIS_ATTRS[name][1]
    if name == "delta":
        return _LABELS[name] + " (base acceleration / $g$)"
    return _LABELS[name] + (" (dimensionless)" if unit == "1" else f" ({unit})")


def plot_map(ds, quantity: str = "power", x=None, y=None, at=None, path=None, scale=None):
    """Heat map of ``quantity`` over two axes, with labelled contour lines, the zero
    contour of the power (where it crosses gamma*) in black, failed points crossed, and the
    paper's case (omega = 1.8, delta = -0.3, gamma = 0) marked when inside the map.
    ``scale``: ``(factor, unit)`` to draw the quantity in another unit (SI: W for a power,
    N m s/rad for gamma*), named on the colour bar.

    The colour bar covers the whole range of the values; a long tail is compressed into its
    end, and the bar says so (:func:`colour_scale`). The contours are at round values inside
    the uncompressed part, labelled away from the edges."""
    from ..style import use_agg

    use_agg()
    import matplotlib.pyplot as plt
    from matplotlib.colors import FuncNorm, Normalize
    from matplotlib.ticker import MaxNLocator

    from ..fileio import save_figure
    from ..style import figure_style

    z, failed, xs, ys, xn, yn, label, title = map_data(ds, quantity, x, y, at)
    if scale is not None:
        z = z * float(scale[0])
        label = f"{label.split(' (')[0]} ({scale[1]})"
    with figure_style():
        fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
        cmap = plt.get_cmap("viridis").with_extremes(bad="0.85")
        finite = np.isfinite(z)
        knots, shares = colour_scale(z)
        lo = knots[1] if shares[1] == _TAIL_SHARE else knots[0]
        hi = knots[-2] if shares[-2] == 1.0 - _TAIL_SHARE else knots[-1]
        if len(knots) == 2:
            norm = Normalize(vmin=knots[0], vmax=knots[-1])
        else:
            norm = FuncNorm((lambda v: np.interp(v, knots, shares),
                             lambda s: np.interp(s, shares, knots)),
                            vmin=knots[0], vmax=knots[-1])
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(z), shading="nearest", cmap=cmap,
                             norm=norm)
        cb = fig.colorbar(mesh, ax=ax)
        nice = [v for v in MaxNLocator(nbins=7, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
                if lo <= v <= hi]
        if len(knots) > 2:  # the ends of the range, where the compression starts, and
            # the round values not too close to those
            ticks = [*knots, *(v for v in nice
                               if np.min(np.abs(np.interp(v, knots, shares) - np.array(shares)))
                               > 0.04)]
            ticks = sorted(ticks)
            cb.set_ticks(ticks, labels=[f"{v:.3g}" for v in ticks])
            where = []
            if lo > knots[0]:
                where.append(f"below {lo:.3g}")
                cb.ax.axhline(lo, color="black", lw=0.8, ls="--")
            if hi < knots[-1]:
                where.append(f"above {hi:.3g}")
                cb.ax.axhline(hi, color="black", lw=0.8, ls="--")
            label += f"\n(scale compressed {' and '.join(where)})"
        cb.set_label(label)
        px, py = _PAPER.get(xn), _PAPER.get(yn)
        paper = (px is not None and py is not None and xs.min() <= px <= xs.max()
                 and ys.min() <= py <= ys.max())
        # the power's zero contour is drawn black (where gamma crosses gamma*), not white
        zero = (quantity in ("power", "electrical_power", "mechanical_power") and finite.any()
                and np.nanmin(z) < 0 < np.nanmax(z))
        levels = [v for v in nice if lo < v < hi and not (zero and v == 0)]
        avoid = [(px, py)] if paper else []
        if min(z.shape) >= 3 and finite.sum() >= 9:
            for lev, colour, width in ((levels, "white", 0.7), ([0.0] if zero else [], "black",
                                                                1.2)):
                if not lev:
                    continue
                cs = ax.contour(xs, ys, np.ma.masked_invalid(z), levels=lev, colors=colour,
                                linewidths=width)
                labelled, points = _label_points(ax, cs, avoid)
                if points:
                    ax.clabel(cs, labelled, manual=points, inline=True, inline_spacing=4,
                              fontsize=7, fmt="%g")
        if failed.any():
            yy, xx = np.nonzero(failed)
            ax.plot(xs[xx], ys[yy], "x", color="red", ms=4, label="failed (see status)")
        if paper:
            ax.plot([px], [py], marker="*", color="red", ms=12, mec="white", ls="none",
                    label=r"paper's case ($\omega$ = 1.8, $\delta$ = -0.3)")
        if ax.get_legend_handles_labels()[0]:  # below the axes, not over the map
            fig.legend(loc="outside lower center", ncols=2, frameon=False)
        ax.set_xlabel(_axis_label(xn))
        ax.set_ylabel(_axis_label(yn))
        ax.grid(False)
        if title:
            ax.set_title(title)
    if path is not None:
        save_figure(fig, path)
    return fig


#: the curves of a map with one swept axis, in the order drawn: name -> (legend, style)
_CURVES = {"limit_power": ("limit (gamma -> 0)", ":"), "power": ("optimum", "-"),
           "mechanical_power": ("mechanical power of the electrical optimum", "-."),
           "uniform_power": ("best uniform rotation", "--")}


def plot_sweep(ds, path=None, units=None):
    """The figure of a sweep's result (``parapend.sweep(...).plot()``): the heat map of the
    power over the first two swept axes (:func:`plot_map`), or, over one swept axis, the
    power, the uniform rotation's and the limit against it (with an efficiency ``power`` is
    the electrical power and the mechanical one is drawn too), failed points crossed.
    ``units`` (a :class:`parapend.units.Units`, the pendulum the sweep was given): SI scales
    beside the non-dimensional ones, as ``parapend map`` draws them."""
    from ..fileio import save_figure
    from ..style import figure_style

    dims = [d for d in AXES if d in ds.dims]
    if len(dims) >= 2:
        if units is None:
            return plot_map(ds, "power", path=path)
        from ..units import add_si_axes

        fig = plot_map(ds, "power", scale=(float(units.power), "W"))
        with figure_style():
            add_si_axes(fig, units)
        if path is not None:
            save_figure(fig, path)
        return fig
    from ..style import use_agg

    use_agg()
    import matplotlib.pyplot as plt

    x = dims[0]
    xs = ds[x].values
    done = ds["done"].values
    ok = done & np.isin(ds["status"].values, [_CODE[s] for s in _SUCCESS])
    lossy = "mechanical_power" in ds
    with figure_style():
        fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
        for name, (legend, style) in _CURVES.items():
            if name not in ds:
                continue
            mask = ok if name in ("power", "mechanical_power") else done
            y = np.where(mask, ds[name].values, np.nan)
            if name == "power" and lossy:
                legend = "optimum, electrical power"
            ax.plot(xs, y, style, lw=1.2, label=legend)
        failed = done & ~ok
        if failed.any():
            ax.plot(xs[failed], np.zeros(int(failed.sum())), "x", color="red", ms=5,
                    label="failed (see status)")
        ax.set_xlabel(_axis_label(x))
        ax.set_ylabel(f"mean power ({VARIABLES['power'][1]})")
        fixed = {a: float(ds[a]) for a in AXES if a in ds.coords and ds[a].ndim == 0}
        if fixed:
            ax.set_title(", ".join(f"{k} = {v:.4g}" for k, v in fixed.items()))
        ax.legend(frameon=False, fontsize=8)
    if units is not None:
        from ..units import si_figure

        si_figure(fig, units)
    if path is not None:
        save_figure(fig, path)
    return fig
