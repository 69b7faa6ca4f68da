"""Figures of the uncontrolled dynamics (paper Figs. 1 right and 2), matplotlib Agg.

Every function builds a :class:`matplotlib.figure.Figure` on an explicit Agg canvas
(no pyplot, the global backend is not switched) in parapend's style
(:func:`parapend.style.figure_style`), returns it, and saves it only when ``path`` is given
(format from the extension: PNG, SVG, PDF; through :func:`parapend.fileio.save_figure`).
Angles follow paper Eq. 1 (``phi`` from the hanging position).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ..fileio import save_figure
from ..style import figure_style
from .attractors import find_attractors
from .continuation import periodic_orbit
from .simulate import trajectory

__all__ = ["COEXISTENCE_CASE", "plot_basins", "plot_coexistence", "plot_motion",
           "plot_rotation_boundaries"]

#: Paper Section 1: a period-2 oscillation coexists with the period-1 rotation for
#: gamma = 0.1, p = 0.8, omega = 2.1. Initial conditions (phi, phi') at t = 0 reaching each
#: (checked, with every point of a 7 x 7 neighbourhood of half-width 0.03, in
#: tests/test_dynamics.py).
COEXISTENCE_CASE = {
    "gamma": 0.1, "p": 0.8, "omega": 2.1,
    "initial_conditions": {
        "P2 oscillation": (0.5, 0.0),
        "P1 rotation (+)": (0.0, 2.5),
        "P1 rotation (-)": (0.0, -2.5),
    },
}

_OTHER_COLOR = "#3a3a3a"
# rest, oscillations (blues/greens), rotations + (reds), rotations - (oranges/yellows)
_PALETTE = {
    "rest": ["#7f7f7f"],
    "oscillation": ["#1f77b4", "#9ecae1", "#2ca02c", "#98df8a", "#17becf", "#6baed6"],
    "rotation+": ["#d62728", "#e377c2", "#8c564b", "#ff9896"],
    "rotation-": ["#ff7f0e", "#ffdd57", "#bcbd22", "#ffbb78"],
}


def _save(fig: Figure, path: str | Path | None) -> None:
    if path is not None:
        save_figure(fig, path, close=False)


def _new_figure(size) -> Figure:
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _wrap_for_plot(phi: np.ndarray, *others: np.ndarray) -> list[np.ndarray]:
    """``phi`` wrapped to ``[-pi, pi)``, NaN inserted at the jumps (also into ``others``)."""
    w = phi - 2 * math.pi * np.floor((phi + math.pi) / (2 * math.pi))
    at = np.flatnonzero(np.abs(np.diff(w)) > math.pi) + 1
    return [np.insert(np.asarray(x, dtype=float), at, np.nan) for x in (w, *others)]


def _motions(gamma: float, p: float, omega: float) -> list[tuple[float, float, str]]:
    """Starting points on the attractors to draw: the paper's P2 oscillation and P1
    rotation (+) by shooting; if either is missing or unstable at these parameters, every
    attractor (anticlockwise or oscillating) reached from :data:`COEXISTENCE_CASE`'s
    initial conditions, polished by shooting where that converges."""
    osc = periodic_orbit(gamma, p, omega, phi0=1.28, dphi0=-0.21, period=2, winding=0)
    rot = periodic_orbit(gamma, p, omega, winding=1)
    if osc.success and osc.stable and rot.success and rot.stable:
        return [(osc.phi0, osc.dphi0, "period-2 oscillation"),
                (rot.phi0, rot.dphi0, "period-1 rotation (+)")]
    ics = np.array(list(COEXISTENCE_CASE["initial_conditions"].values()))
    found = find_attractors(ics[:, 0], ics[:, 1], gamma, p, omega)
    out = []
    for a in found.attractors:
        if a.winding < 0:
            continue
        orb = periodic_orbit(gamma, p, omega, phi0=a.phi[0], dphi0=a.dphi[0],
                             period=a.period, winding=a.winding)
        x = (orb.phi0, orb.dphi0) if orb.success else (a.phi[0], a.dphi[0])
        out.append((*x, a.name))
    return out


@figure_style()
def plot_coexistence(gamma: float = 0.1, p: float = 0.8, omega: float = 2.1, *,
                     periods: int = 6, path: str | Path | None = None) -> Figure:
    """Paper Fig. 1 right: a period-2 oscillation and a period-1 rotation of Eq. 1.

    Both motions are started on the attractors themselves (found by shooting,
    :func:`parapend.dynamics.continuation.periodic_orbit`) and integrated with DOP853. At
    other parameters, the attractors reached from the initial conditions of
    :data:`COEXISTENCE_CASE` are drawn instead (the clockwise mirror images omitted).

    Parameters
    ----------
    gamma, p, omega : float
        Parameters of Eq. 1 (default: the paper's coexistence case).
    periods : int
        Forcing periods shown.
    path : str or Path, optional
        Save the figure there.

    Returns
    -------
    matplotlib.figure.Figure
        Left: ``phi(t)`` wrapped to ``[-pi, pi)`` against ``t/T``. Right: phase portrait
        ``(phi mod 2 pi, phi')`` with the Poincare points at ``t = m*T`` marked.
    """
    period = 2 * math.pi / omega
    fig = _new_figure((10, 4))
    ax1, ax2 = fig.subplots(1, 2, width_ratios=(1.6, 1))
    colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]
    motions = _motions(gamma, p, omega)
    for (phi0, dphi0, label), color in zip(motions, colors):
        tr = trajectory(phi0, dphi0, gamma, p, omega, periods * period, points_per_period=200)
        wrapped, tau_p, dphi_p = _wrap_for_plot(tr.phi, tr.t / period, tr.dphi)
        ax1.plot(tau_p, wrapped, color=color, lw=1.5, label=label)
        ax2.plot(wrapped, dphi_p, color=color, lw=1.2, label=label)
        strobe = tr.t.size // periods * np.arange(periods + 1)
        strobe = strobe[strobe < tr.t.size]
        ps = tr.phi[strobe] - 2 * math.pi * np.floor((tr.phi[strobe] + math.pi) / (2 * math.pi))
        ax2.plot(ps, tr.dphi[strobe], "o", color=color, mec="k", ms=7, zorder=3)
    ax1.set_xlabel(r"$t/T$ (forcing periods, $T = 2\pi/\omega$)")
    ax1.set_ylabel(r"$\varphi$ (rad, wrapped to $[-\pi, \pi)$)")
    ax1.set_ylim(-math.pi, math.pi)
    ax1.set_yticks([-math.pi, -math.pi / 2, 0, math.pi / 2, math.pi],
                   [r"$-\pi$", r"$-\pi/2$", "0", r"$\pi/2$", r"$\pi$"])
    ax1.grid(alpha=0.3)
    if motions:
        ax1.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=len(motions),
                   frameon=False, fontsize=9, borderaxespad=0.2)
    else:
        ax1.text(0.5, 0.5, "no periodic attractor found", transform=ax1.transAxes,
                 ha="center")
    fig.suptitle(rf"Eq. 1: $\gamma={gamma:g}$, $p={p:g}$, $\omega={omega:g}$", fontsize=10)
    ax2.set_xlabel(r"$\varphi$ mod $2\pi$ (rad)")
    ax2.set_ylabel(r"$\dot\varphi$ (rad per $\sqrt{l/g}$)")
    ax2.set_xlim(-math.pi, math.pi)
    ax2.set_xticks([-math.pi, 0, math.pi], [r"$-\pi$", "0", r"$\pi$"])
    ax2.grid(alpha=0.3)
    ax2.set_title("phase portrait (dots: $t = mT$)")
    _save(fig, path)
    return fig


def _colors(ds) -> list[str]:
    used = {k: 0 for k in _PALETTE}
    colors = [_OTHER_COLOR]
    for c in ds["code"].values[1:]:
        kind = str(ds["kind"].values[c])
        if kind == "rotation":
            kind = "rotation+" if int(ds["winding"].values[c]) > 0 else "rotation-"
        pal = _PALETTE.get(kind, _PALETTE["oscillation"])
        colors.append(pal[used[kind] % len(pal)])
        used[kind] += 1
    return colors


@figure_style()
def plot_basins(ds: xr.Dataset, *, path: str | Path | None = None,
                show_attractors: bool = True, title: str | None = None) -> Figure:
    """Basin-of-attraction picture (paper Fig. 2 right) from :func:`~.basins.basin_map`.

    Parameters
    ----------
    ds : xarray.Dataset
        Output of :func:`parapend.dynamics.basins.basin_map`.
    path : str or Path, optional
        Save the figure there.
    show_attractors : bool
        Mark each attractor's Poincare points (white-edged markers in its colour).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
        Colours by attractor code; the legend lists each attractor with its share of the
        grid.
    """
    colors = _colors(ds)
    ncode = len(colors)
    phi = ds["phi"].values
    dphi = ds["dphi"].values
    dx = (phi[1] - phi[0]) if phi.size > 1 else 1.0
    dy = (dphi[1] - dphi[0]) if dphi.size > 1 else 1.0
    fig = _new_figure((7.8, 5.2))
    ax = fig.add_subplot()
    ax.imshow(ds["attractor"].values, origin="lower", interpolation="nearest",
              cmap=ListedColormap(colors), vmin=-0.5, vmax=ncode - 0.5, aspect="auto",
              extent=(phi[0] - dx / 2, phi[-1] + dx / 2, dphi[0] - dy / 2, dphi[-1] + dy / 2))
    handles = []
    frac = ds["basin_fraction"].values
    err = (ds["basin_fraction_error"].values if "basin_fraction_error" in ds
           else np.full(frac.shape, np.nan))
    for c in range(ncode):
        if c == 0 and frac[0] == 0:
            continue
        pm = "" if not np.isfinite(err[c]) else rf" $\pm$ {100 * err[c]:.1f}"
        handles.append(Patch(facecolor=colors[c], edgecolor="k", lw=0.5,
                             label=f"{ds['name'].values[c]}  ({100 * frac[c]:.1f}{pm}%)"))
    if show_attractors:
        for c in range(1, ncode):
            pp = ds["poincare_phi"].values[c]
            pd = ds["poincare_dphi"].values[c]
            ok = np.isfinite(pp)
            ax.plot(pp[ok], pd[ok], marker="o", ls="none", ms=12, mfc="white", mec="white",
                    zorder=3)
            ax.plot(pp[ok], pd[ok], marker="o", ls="none", ms=7, mfc=colors[c], mec="k",
                    mew=1.2, zorder=4)
        handles.append(Line2D([], [], marker="o", ls="none", ms=7, mfc="white", mec="k",
                              label="attractor on the section"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9,
              frameon=False)
    ax.set_xlabel(r"$\varphi(t_0)$ (rad, from hanging)")
    ax.set_ylabel(r"$\dot\varphi(t_0)$ (rad per $\sqrt{l/g}$)")
    ax.set_xticks([-math.pi, -math.pi / 2, 0, math.pi / 2, math.pi],
                  [r"$-\pi$", r"$-\pi/2$", "0", r"$\pi/2$", r"$\pi$"])
    ax.set_xlim(phi[0] - dx / 2, phi[-1] + dx / 2)
    ax.set_ylim(dphi[0] - dy / 2, dphi[-1] + dy / 2)
    if title is None:
        a = ds.attrs
        title = (rf"Basins, Eq. 1: $\gamma={a['gamma']:g}$, $p={a['p']:g}$, "
                 rf"$\omega={a['omega']:g}$ ({phi.size}$\times${dphi.size}, "
                 f"{a['periods']} periods max)")
        lo, hi = (np.asarray(a["mislabel_interval"], dtype=float).ravel().tolist()
                  if "mislabel_interval" in a else (math.nan, math.nan))
        if math.isfinite(hi):
            title += (f"\nuncertain labels {100 * a['mislabel_fraction']:.1f}% "
                      f"(95% interval {100 * lo:.1f} to {100 * hi:.1f}%)")
    ax.set_title(title, fontsize=10, pad=8)
    _save(fig, path)
    return fig


@figure_style()
def plot_rotation_boundaries(ds: xr.Dataset, *, path: str | Path | None = None,
                             points: dict[str, tuple[float, float]] | None = None) -> Figure:
    """Curves J, G, E of the period-1 rotation in the ``(omega, p)`` plane (Fig. 2 left).

    The band between G and E, where the rotation exists but is unstable, is shaded (up to
    the top of the plot where E was not found below the continuation's ``p_max``).

    Parameters
    ----------
    ds : xarray.Dataset
        Output of :func:`parapend.dynamics.continuation.rotation_boundaries`.
    path : str or Path, optional
    points : dict, optional
        ``{label: (omega, p)}``: operating points to mark (e.g. the paper's cases).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = _new_figure((9.6, 5.0))
    ax = fig.add_subplot()
    om = ds["omega"].values
    pj, pg, pe = (ds[k].values for k in ("p_J", "p_G", "p_E"))
    p_max = float(ds.attrs.get("p_max", np.nan))
    open_top = bool(np.any(np.isfinite(pg) & ~np.isfinite(pe))) and math.isfinite(p_max)
    top = 1.05 * float(np.nanmax(np.concatenate([pj, pg, pe, [1.0],
                                                 [p_max] if open_top else []])))
    for k, (x, y) in enumerate(_unstable_band(om, pg, pe, p_max)):
        ax.fill(x, y, color="C3", alpha=0.13, lw=0,
                label=None if k else "rotation unstable (between G and E)")
    ax.fill_between(om, 0, pj, where=np.isfinite(pj), color="0.5", alpha=0.12, lw=0,
                    label="no period-1 rotation (below J)")
    styles = {"p_J": ("k", "-", "J: birth (fold)"),
              "p_G": ("C3", "--", "G: loss of stability (period doubling)"),
              "p_E": ("C0", "-.", "E: stability regained (period doubling)")}
    for key, (c, ls, lab) in styles.items():
        ax.plot(om, ds[key].values, color=c, ls=ls, lw=1.5, label=lab)
    if open_top:
        ax.axhline(p_max, color="0.4", ls=":", lw=1,
                   label=r"$p_{\max}$ of the continuation (E not found below it)")
    for i, (label, (w, p)) in enumerate((points or {}).items()):
        ax.plot([w], [p], marker="*o^s"[i % 4], ms=11, color="gold", mec="k", ls="none",
                zorder=4)
        ax.annotate(label, (w, p), xytext=(8, -3 if i % 2 else 6), textcoords="offset points",
                    fontsize=8, bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "0.7"})
    if om.size > 1:
        ax.set_xlim(om[0], om[-1])
    ax.set_ylim(0, top)
    ax.set_xlabel(r"forcing frequency $\omega$ (units of $\sqrt{g/l}$)")
    ax.set_ylabel(r"excitation strength $p$ (-)")
    ax.set_title(rf"Period-1 rotation of Eq. 1, $\gamma = {ds.attrs['gamma']:g}$")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0, frameon=False)
    _save(fig, path)
    return fig


def _unstable_band(om, pg, pe, p_max):
    """Polygons ``(x, y)`` of the band between G and E, one per run of omegas where G exists.

    Where E was not found below the continuation's ``p_max`` the band reaches ``p_max``. A
    change between the two (E found at one grid omega, not at its neighbour) is drawn as a
    vertical step halfway between them: E crosses ``p_max`` somewhere in that interval, and
    joining ``p_max`` to E's value by a straight edge would draw a boundary no computation
    found.
    """
    ok = np.isfinite(pg)
    bands = []
    i = 0
    while i < om.size:
        if not ok[i]:
            i += 1
            continue
        j = i
        while j + 1 < om.size and ok[j + 1]:
            j += 1
        found = np.isfinite(pe[i:j + 1])
        upper = np.where(found, pe[i:j + 1], p_max)
        if not np.all(np.isfinite(upper)):
            upper = np.where(np.isfinite(upper), upper, np.nanmax(np.append(pg, 1.0)))
        ux, uy = [om[i]], [upper[0]]
        for a in range(1, j - i + 1):
            if found[a] != found[a - 1]:
                mid = 0.5 * (om[i + a - 1] + om[i + a])
                ux += [mid, mid]
                uy += [upper[a - 1], upper[a]]
            ux.append(om[i + a])
            uy.append(upper[a])
        x = np.concatenate([om[i:j + 1], ux[::-1]])
        y = np.concatenate([pg[i:j + 1], uy[::-1]])
        bands.append((x, y))
        i = j + 1
    return bands


@figure_style()
def plot_motion(motion, *, path: str | Path | None = None, last_periods: int = 5) -> Figure:
    """Time history, stroboscopic samples and phase portrait of one motion of Eq. 1.

    Parameters
    ----------
    motion : parapend.dynamics.motion.Motion
        From :func:`parapend.dynamics.motion.simulate`.
    path : str or Path, optional
        Save the figure there.
    last_periods : int
        Forcing periods shown in the time histories (the last ones of the run).

    Returns
    -------
    matplotlib.figure.Figure
        Left: ``phi`` (wrapped to ``[-pi, pi)``) and ``phi'`` on separate axes over the last
        ``last_periods`` forcing periods. Right, top: the stroboscopic samples
        ``phi(t0 + m T)`` against the period ``m`` over the whole run (the transient and the
        settling). Right, bottom: the phase portrait, the first half of the run light, the
        second half dark, the Poincare points marked.
    """
    m = motion
    period = 2 * math.pi / m.omega
    fig = _new_figure((10.0, 6.2))
    grid = fig.add_gridspec(2, 2, width_ratios=(1.25, 1))
    ax_phi = fig.add_subplot(grid[0, 0])
    ax_dphi = fig.add_subplot(grid[1, 0], sharex=ax_phi)
    ax_strobe = fig.add_subplot(grid[0, 1])
    ax_phase = fig.add_subplot(grid[1, 1])
    tau = (m.t - m.t0) / period
    last = max(1, min(int(last_periods), int(m.periods)))
    sel = tau >= tau[-1] - last - 1e-9
    w, tau_w, dphi_w = _wrap_for_plot(m.phi[sel], tau[sel], m.dphi[sel])
    ax_phi.plot(tau_w, w, color="C0", lw=1.2)
    ax_phi.set_ylabel(r"$\varphi$ (rad, wrapped)")
    ax_phi.set_ylim(-math.pi, math.pi)
    ax_phi.set_yticks([-math.pi, 0, math.pi], [r"$-\pi$", "0", r"$\pi$"])
    ax_phi.tick_params(labelbottom=False)
    ax_phi.set_title(f"last {last} forcing period{'s' if last > 1 else ''}")
    ax_dphi.plot(tau[sel], m.dphi[sel], color="C1", lw=1.2)
    ax_dphi.set_ylabel(r"$\dot\varphi$ (rad per $\sqrt{l/g}$)")
    ax_dphi.set_xlabel(r"$t/T$ (forcing periods, $T = 2\pi/\omega$)")
    ax_dphi.set_xlim(tau[sel][0], tau[sel][-1])
    mm = np.arange(m.poincare_phi.size)
    ps = m.poincare_phi - 2 * math.pi * np.floor((m.poincare_phi + math.pi) / (2 * math.pi))
    ax_strobe.plot(mm, ps, "o", ms=2.5 if mm.size > 60 else 4, color="C0")
    ax_strobe.set_ylim(-math.pi, math.pi)
    ax_strobe.set_yticks([-math.pi, 0, math.pi], [r"$-\pi$", "0", r"$\pi$"])
    ax_strobe.set_xlabel(r"period $m$")
    ax_strobe.set_ylabel(r"$\varphi(t_0 + mT)$ (rad)")
    ax_strobe.set_title("stroboscopic samples, whole run")
    half = m.t.size // 2
    w, dp = _wrap_for_plot(m.phi[:half + 1], m.dphi[:half + 1])
    ax_phase.plot(w, dp, lw=0.5, color="0.75")
    w, dp = _wrap_for_plot(m.phi[half:], m.dphi[half:])
    ax_phase.plot(w, dp, lw=0.8, color="k")
    c = m.classification
    if c.phi.size:
        ax_phase.plot(c.phi, c.dphi, "o", ms=7, mfc="#d62728", mec="k")
    ax_phase.set_xlim(-math.pi, math.pi)
    ax_phase.set_xticks([-math.pi, 0, math.pi], [r"$-\pi$", "0", r"$\pi$"])
    ax_phase.set_xlabel(r"$\varphi$ (rad, from hanging)")
    ax_phase.set_ylabel(r"$\dot\varphi$ (rad per $\sqrt{l/g}$)")
    ax_phase.set_title("phase portrait (light: first half; dots: Poincare points)",
                       fontsize=9)
    fig.suptitle(rf"Eq. 1: $\gamma={m.gamma:g}$, $p={m.p:g}$, $\omega={m.omega:g}$, "
                 rf"$(\varphi_0, \dot\varphi_0) = ({m.phi0:g}, {m.dphi0:g})$: {c.name}",
                 fontsize=10)
    _save(fig, path)
    return fig


def legend_of(ds: xr.Dataset) -> dict[int, str]:
    """``{code: name}`` of a basin dataset (from its JSON ``legend`` attribute)."""
    return {int(k): v for k, v in json.loads(ds.attrs["legend"]).items()}
