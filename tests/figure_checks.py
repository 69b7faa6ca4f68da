"""What a referee checks in a figure, computed from the drawn matplotlib Figure.

Used by tests/test_figures.py; each function returns a list of problems (empty: fine), so a
test can report every problem of a figure at once.

- :func:`label_problems`: every axes with data has an x and a y label (an axes may leave
  its x label to an axes it shares x with), with a unit in brackets or after a comma, or
  only SI units when ``si`` is set.
- :func:`legend_problems`: a legend inside an axes covers less than ``threshold`` of the
  plotted points (lines densified in display space, so a legend over a straight segment
  counts).
- :func:`colorbar_problems`: every colour bar's limits cover its mappable's data.
- :func:`text_problems`: titles, axis labels, tick labels, annotations and legends do not
  overlap one another.
"""

from __future__ import annotations

import math
import re

import numpy as np

__all__ = ["all_problems", "axes_with_data", "colorbar_problems", "label_problems",
           "legend_problems", "render", "si_axis_problems", "text_problems"]

#: a unit in brackets, ``(rad)``, ``(m g l / t0)``, or after a comma, ``, s``
UNIT = re.compile(r"\([^()]*\S[^()]*\)|\[[^\]]+\]|,\s*\S+\s*$")
#: units that make a label SI
SI_UNIT = re.compile(r"\b(s|m|W|J|kJ|MJ|kg|N\s*m|Hz|rad|turns)\b|\(-\)|N m s/rad")
#: units of the non-dimensional model, not SI
MODEL_UNIT = re.compile(r"m\s*g\s*l|t_?0|\\sqrt|units of|forcing period|non-dim")


def render(fig, dpi: float = 200):
    """Draw ``fig`` on an Agg canvas at ``dpi`` (that of the saved files: tick locators
    depend on it) in parapend's style, so every position is final; return the renderer."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from parapend.style import figure_style

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    with figure_style():
        fig.canvas.draw()
    return fig.canvas.get_renderer()


def _is_colorbar(ax) -> bool:
    return getattr(ax, "_colorbar", None) is not None


def axes_with_data(fig) -> list:
    """Visible axes (not colour bars) holding lines, collections or images."""
    return [ax for ax in fig.axes if ax.get_visible() and not _is_colorbar(ax)
            and (ax.lines or ax.collections or ax.images)]


def _plain(label: str) -> str:
    return label.replace("$", "").strip()


def label_problems(fig, *, units: bool = True, unitless=(), si: bool = False) -> list[str]:
    """Axes with data and no x or y label, or (``units``) a label without a unit.

    ``unitless``: regular expressions of labels allowed without a unit (counts such as the
    number of harmonics, non-dimensional parameters). ``si``: each unit must be SI.
    """
    out = []
    for i, ax in enumerate(axes_with_data(fig)):
        for axis in ("x", "y"):
            label = getattr(ax, f"get_{axis}label")()
            if not label.strip():
                shared = getattr(ax, f"get_shared_{axis}_axes")().get_siblings(ax)
                if any(getattr(o, f"get_{axis}label")().strip() for o in shared if o is not ax):
                    continue
                out.append(f"axes {i} ({ax.get_title()!r}): no {axis} label")
                continue
            if not units or any(re.fullmatch(u, _plain(label)) for u in unitless):
                continue
            unit = UNIT.search(label)
            if unit is None:
                out.append(f"axes {i}: {axis} label {label!r} has no unit")
            elif si and (not SI_UNIT.search(unit.group(0))
                         or MODEL_UNIT.search(unit.group(0))):
                out.append(f"axes {i}: {axis} label {label!r} has no SI unit")
    return out


#: a time counted in forcing periods: a count, read the same in any units
FORCING_PERIODS = re.compile(r"^\(forcing periods")


def _last_unit(label: str) -> str | None:
    """The unit of ``label``: its last bracket (``$\\varphi(t_0 + mT)$ (rad)`` is in rad)."""
    found = [m.group(0) for m in UNIT.finditer(label)]
    return found[-1] if found else None


def _is_si(unit: str) -> bool:
    return bool(SI_UNIT.search(unit)) and not MODEL_UNIT.search(unit)


def si_axis_problems(fig, *, unitless=()) -> list[str]:
    """Axes with data whose x or y label has a non-SI unit (the model's ``m g l``, ``t0``)
    and no SI scale beside it: a secondary axis of the same direction (``secondary_xaxis``
    or ``secondary_yaxis``, a child of the axes) labelled with an SI unit. A figure made
    with physical options then reads in SI on every axis that carries a dimension (a time
    counted in forcing periods is a count, the same in any units)."""
    out = []
    for i, ax in enumerate(axes_with_data(fig)):
        for axis in ("x", "y"):
            label = getattr(ax, f"get_{axis}label")()
            if not label.strip() or any(re.fullmatch(u, _plain(label)) for u in unitless):
                continue
            unit = _last_unit(label)
            if unit is None or _is_si(unit) or FORCING_PERIODS.search(unit):
                continue
            beside = [getattr(c, f"get_{axis}label")() for c in ax.child_axes
                      if type(c).__name__ == "SecondaryAxis"]
            if not any((u := _last_unit(b)) and _is_si(u) for b in beside):
                out.append(f"axes {i}: {axis} label {label!r} has no SI scale beside it")
    return out


def _display_points(ax, step: float = 2.0, cap: int = 400) -> np.ndarray:
    """Display coordinates of the plotted points of ``ax``: every line densified to about
    ``step`` pixels, scatter offsets; only those inside the axes box."""
    pts = []
    for line in ax.lines:
        if not line.get_visible():
            continue
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=float))
        if line.get_linestyle() in ("None", "none", " ", ""):  # markers only
            pts.append(xy[np.isfinite(xy).all(axis=1)])
            continue
        for a, b in zip(xy[:-1], xy[1:]):
            if not (np.isfinite(a).all() and np.isfinite(b).all()):
                continue
            n = min(cap, max(1, math.ceil(float(np.hypot(*(b - a))) / step)))
            s = np.linspace(0.0, 1.0, n, endpoint=False)[:, None]
            pts.append(a + s * (b - a))
        if len(xy) and np.isfinite(xy[-1]).all():
            pts.append(xy[-1:])
    for coll in ax.collections:
        offsets = np.asarray(coll.get_offsets(), dtype=float)
        if type(coll).__name__ == "PathCollection" and offsets.size:
            pts.append(coll.get_offset_transform().transform(offsets))
    if not pts:
        return np.zeros((0, 2))
    p = np.concatenate(pts)
    box = ax.get_window_extent()
    inside = ((p[:, 0] >= box.x0) & (p[:, 0] <= box.x1) & (p[:, 1] >= box.y0)
              & (p[:, 1] <= box.y1))
    return p[inside]


def legend_fraction(ax) -> float:
    """Fraction of the plotted points of ``ax`` under its legend (0 without one)."""
    leg = ax.get_legend()
    if leg is None or not leg.get_visible():
        return 0.0
    box = leg.get_window_extent()
    p = _display_points(ax)
    if not p.size:
        return 0.0
    under = ((p[:, 0] > box.x0) & (p[:, 0] < box.x1) & (p[:, 1] > box.y0)
             & (p[:, 1] < box.y1))
    return float(under.mean())


def legend_problems(fig, threshold: float = 0.01) -> list[str]:
    """Legends covering ``threshold`` or more of their axes' plotted points."""
    out = []
    for i, ax in enumerate(axes_with_data(fig)):
        f = legend_fraction(ax)
        if f >= threshold:
            out.append(f"axes {i} ({ax.get_title()!r}): legend covers {100 * f:.1f}% of "
                       "the plotted points")
    return out


def colorbar_problems(fig, rtol: float = 1e-9) -> list[str]:
    """Colour bars whose limits do not cover their mappable's finite data."""
    out = []
    for ax in fig.axes:
        cb = getattr(ax, "_colorbar", None)
        if cb is None:
            continue
        m = cb.mappable
        if hasattr(m, "zmin") and hasattr(m, "zmax"):  # contours: the contoured field
            lo, hi = float(m.zmin), float(m.zmax)
        else:
            a = np.ma.masked_invalid(np.ma.asarray(m.get_array(), dtype=float))
            if a.count() == 0:
                continue
            lo, hi = float(a.min()), float(a.max())
        vmin, vmax = float(cb.norm.vmin), float(cb.norm.vmax)
        tol = rtol * max(1.0, abs(lo), abs(hi))
        if vmin > lo + tol or vmax < hi - tol:
            out.append(f"colour bar {ax.get_ylabel() or ax.get_xlabel()!r}: limits "
                       f"[{vmin:.4g}, {vmax:.4g}] do not cover the data [{lo:.4g}, {hi:.4g}]")
    return out


def _in_view(axis, tick_label) -> bool:
    lo, hi = sorted(axis.get_view_interval())
    v = tick_label.get_position()[0 if axis.axis_name == "x" else 1]
    span = max(hi - lo, 1e-300)
    return lo - 1e-9 * span <= v <= hi + 1e-9 * span


def _texts(fig) -> list[tuple[str, object, object]]:
    """``(name, owner, bbox)`` of every visible, non-empty text and legend of ``fig``."""
    items = []

    def add(name, owner, artist):
        if artist is None or not artist.get_visible():
            return
        if hasattr(artist, "get_text") and not artist.get_text().strip():
            return
        bb = artist.get_window_extent()
        if bb.width > 0 and bb.height > 0:
            items.append((name, owner, bb))

    add("suptitle", fig, getattr(fig, "_suptitle", None))
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        for t in (ax.title, getattr(ax, "_left_title", None), getattr(ax, "_right_title", None)):
            add(f"axes {i} title", ax, t)
        add(f"axes {i} x label", ax, ax.xaxis.label)
        add(f"axes {i} y label", ax, ax.yaxis.label)
        for axis in (ax.xaxis, ax.yaxis):
            for t in axis.get_ticklabels():
                if _in_view(axis, t):
                    add(f"axes {i} {axis.axis_name} tick {t.get_text()!r}", (ax, axis), t)
        for t in ax.texts:
            add(f"axes {i} text {t.get_text()!r}", ax, t)
        leg = ax.get_legend()
        if leg is not None and leg.get_visible():
            add(f"axes {i} legend", ax, leg)
    for leg in fig.legends:
        add("figure legend", fig, leg)
    return items


def text_problems(fig, min_overlap: float = 1.0) -> list[str]:
    """Pairs of texts (or legends) whose boxes overlap by more than ``min_overlap`` px^2."""
    items = _texts(fig)
    out = []
    for a in range(len(items)):
        for b in range(a + 1, len(items)):
            (na, _, ba), (nb, _, bb) = items[a], items[b]
            w = min(ba.x1, bb.x1) - max(ba.x0, bb.x0)
            h = min(ba.y1, bb.y1) - max(ba.y0, bb.y0)
            if w > 0 and h > 0 and w * h > min_overlap:
                out.append(f"{na} overlaps {nb}")
    return out


def all_problems(fig, **label_options) -> list[str]:
    """Every check above on a drawn figure."""
    render(fig)
    return (label_problems(fig, **label_options) + legend_problems(fig)
            + colorbar_problems(fig) + text_problems(fig))
