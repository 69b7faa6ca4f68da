"""Figures (matplotlib, Agg backend), drawn in parapend's style (:mod:`parapend.style`) and
saved as PNG, SVG or PDF by extension through :func:`parapend.fileio.save_figure`: atomically,
reproducibly, with the user's umask."""

from __future__ import annotations

import math

from .style import use_agg

use_agg()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .fileio import save_figure  # noqa: E402
from .model import torque  # noqa: E402
from .optimal.limit import limit  # noqa: E402
from .style import figure_style  # noqa: E402

__all__ = ["plot_damping_sweep", "plot_harmonic_table", "plot_optimum",
           "plot_square_approximations", "plot_theta_panels", "save_figure"]

TAU_LABEL = r"$\tau = \omega t / 2\pi$"
LIMIT_LABEL = r"limit $\gamma \to 0$"


def _horizon_axes(ax, hz, xlim, ylabel: str) -> None:
    """The axes of a curve against the forecast horizon (the pendulum's and the buoy's): the
    optimum (1) and zero marked, the horizons on a log axis labelled as given."""
    ax.axhline(1.0, color="0.5", lw=0.8)
    ax.axhline(0.0, color="0.7", lw=0.6)
    ax.set_xscale("log")
    ax.set_xlim(*xlim)
    ax.set_xticks(hz if hz.size else [])
    ax.set_xticklabels([f"{v:g}" for v in hz])
    ax.minorticks_off()
    ax.set_xlabel("horizon (peak periods)")
    ax.set_ylabel(ylabel)


def _finish(fig, path, layout: bool = True):
    """Lay out (``tight_layout`` unless ``layout`` is false: the figure has its own layout
    engine), save if ``path`` is given, and return the figure."""
    if layout:
        fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig


def _pi_label(v: float) -> str:
    k = int(round(v / np.pi))
    return {0: "$0$", 1: r"$\pi$", -1: r"$-\pi$"}.get(k, rf"${k}\pi$")


def _pi_ticks(ax) -> None:
    """Ticks at the multiples of pi within the axis' range."""
    lo, hi = ax.get_ylim()
    ticks = np.pi * np.arange(math.floor(lo / np.pi), math.ceil(hi / np.pi) + 1)
    ax.set_yticks(ticks)
    ax.set_yticklabels([_pi_label(v) for v in ticks])


def _tau(omega, t):
    return omega * np.asarray(t) / (2 * math.pi)


def si_title(result, units) -> str:
    """The pendulum and its forcing in SI, for a title: length, mass, base frequency (Hz),
    and the damping coefficient (N m s/rad)."""
    f = units.frequency(result.omega)
    desc = f"$l$ = {units.length:g} m, $m$ = {units.mass:g} kg, $f$ = {f:.4g} Hz"
    delta = (result.excitation or {}).get("delta")
    if delta is not None and result.excitation.get("excitation") == "harmonic":
        desc += f", $A$ = {abs(units.amplitude(delta, f)):.4g} m"
    if result.gamma:
        desc += f", $c$ = {units.damping_coefficient(result.gamma):.4g} N m s/rad"
    return desc


@figure_style()
def plot_optimum(result, path=None, points: int = 2000):
    """theta(tau) and torque of an optimum, with the gamma -> 0 limit motion (cf. paper Fig. 4).

    ``tau = omega t / 2 pi`` over one forcing period. With the pendulum in SI
    (``result.physical_units``) the powers are in W, the torque in N m and the title gives
    the pendulum and its forcing in SI. Returns the figure (saved if ``path``).
    """
    exc = result.excitation_function
    motion = result.motion
    units = result.physical_units
    om = exc.omega
    t = exc.period * np.arange(points + 1) / points
    tau = _tau(om, t)
    k = int(getattr(result, "winding", 1) or 1)
    lim = limit(exc, k)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 2]})

    def p(x):  # a power as the legend shows it
        return f"$P = {x:.5f}$" if units is None else f"$P$ = {units.to_watts(x):.4g} W"

    label = f"{result.method}, $N = {result.harmonics}$" if result.method == "fourier" \
        else result.method
    ax1.plot(tau, motion.theta(t), lw=1.8, label=f"optimum ({label}): {p(result.power)}")
    ax1.plot(tau, lim.motion.theta(t), "k--", lw=1, label=f"{LIMIT_LABEL}: {p(lim.power)}")
    from .power import uniform_power

    _, phi = uniform_power(exc, result.gamma, k)
    ax1.plot(tau, k * om * t + phi, ":", color="gray", lw=1,
             label=f"best uniform rotation: {p(result.uniform_power)}")
    ax1.set_ylabel(r"$\theta$ (rad, from upright)")
    if k == 1:
        ax1.set_yticks(np.pi * np.arange(0, 5))
        ax1.set_yticklabels([_pi_label(np.pi * j) for j in range(5)])
    ax1.legend(loc="upper left")
    what = "period-1 rotation" if k == 1 else f"rotation, winding K = {k}"
    if units is None:
        desc = ", ".join(f"{k}={v}" for k, v in result.excitation.items() if k != "terms")
        ax1.set_title(f"Optimal {what} ({desc}, $\\gamma = {result.gamma:g}$)")
    else:
        ax1.set_title(f"Optimal {what} ({si_title(result, units)})", fontsize=10)
    tq = torque(motion, exc, result.gamma, t)
    if units is None:
        ax2.plot(tau, tq, color="C3", lw=1.2)
        ax2.set_ylabel("torque $T$ ($mgl$)")
    else:
        ax2.plot(tau, tq * units.torque, color="C3", lw=1.2)
        ax2.set_ylabel("torque $T$ (N m)")
    ax2.set_xlabel(TAU_LABEL)
    ax2.set_xlim(0, 1)
    return _finish(fig, path)


@figure_style()
def plot_damping_sweep(ds, path=None, extra=None):
    """Optimal and uniform power against damping with the threshold (cf. paper Fig. 6).

    Left: ``P(gamma)`` on linear axes, as in the paper. Right: the deficit below the
    ``gamma -> 0`` limit, ``P_lim - P``, on logarithmic axes, which resolves ``gamma -> 0``.

    Parameters
    ----------
    ds : xarray.Dataset
        Output of :func:`parapend.damping_sweep`.
    path : str or Path, optional
        Save the figure there (PNG, SVG or PDF).
    extra : list of (label, damping, power), optional
        More curves for the right panel (e.g. BVP optima at log-spaced damping).
    """
    fig, (ax, axr) = plt.subplots(1, 2, figsize=(11, 4.2), width_ratios=(1.15, 1))
    g = ds["gamma"].values
    p = ds["power"].values
    n = ds.attrs["harmonics"]
    plim = ds.attrs["limit_power"]
    ax.plot(g, p, "o-", ms=3, label=f"optimal (Fourier, $N = {n}$)")
    ax.plot(g, ds["uniform_power"].values, "--", label="best uniform rotation")
    ax.axhline(0, color="k", lw=0.7)
    gs = ds.attrs["damping_threshold"]
    ax.axvline(gs, color="C3", lw=0.8, ls=":")
    ax.annotate(rf"$\gamma^* = {gs:.6f}$", (gs, 0), xytext=(6, 40), textcoords="offset points",
                color="C3", ha="left", arrowprops={"arrowstyle": "-", "color": "C3", "lw": 0.6})
    ax.plot([0], [plim], "k*", ms=9, label=LIMIT_LABEL, zorder=3)
    ax.set_xlabel(r"damping $\gamma$")
    ax.set_ylabel("mean extracted power $P$ ($mgl/t_0$)")
    ax.set_title("power against damping (linear axes)")
    ax.legend()
    if not extra:
        pos = g > 0
        axr.loglog(g[pos], np.maximum(plim - p[pos], 1e-16), "o-", ms=3,
                   label=f"Fourier, $N = {n}$")
    for i, (label, gx, px) in enumerate(extra or []):
        gx, px = np.asarray(gx), np.asarray(px)
        axr.loglog(gx, np.maximum(plim - px, 1e-16), "s-" if i == 0 else "^-", ms=3,
                   color=f"C{i + 2}", label=label)
    axr.axvline(gs, color="C3", lw=0.8, ls=":")
    axr.set_xlabel(r"damping $\gamma$ (log)")
    axr.set_ylabel(r"$P_{\mathrm{lim}} - P$ ($mgl/t_0$, log)")
    axr.set_title(rf"deficit below the limit $P_{{\mathrm{{lim}}}} = {plim:.6f}$")
    axr.legend(loc="upper left")
    return _finish(fig, path)


@figure_style()
def plot_harmonic_table(ds, path=None):
    """Optimal power against the number of harmonics N, with the uniform and limit powers."""
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(ds["harmonics"].values, ds["power"].values, "o-", ms=3, label="Fourier optimum")
    ax.axhline(ds.attrs["limit_power"], color="k", ls="--", label=LIMIT_LABEL)
    ax.axhline(ds.attrs["uniform_power"], color="gray", ls=":", label="best uniform rotation")
    ax.set_xlabel("harmonics $N$")
    ax.set_ylabel("mean extracted power $P$ ($mgl/t_0$)")
    ax.legend()
    return _finish(fig, path)


@figure_style()
def plot_theta_panels(panels, path=None, ncols: int | None = None):
    """Families of motions theta(tau), one panel each (paper Figs. 4, 5, 7, 9, 10).

    Parameters
    ----------
    panels : list of dict
        ``{"title": str, "curves": [(label, tau, theta), ...], "limit": (tau, theta) or None}``
        with ``tau = omega t / 2 pi`` over one period and theta in radians. Optional keys:
        ``"ylabel"`` (default theta in rad) and ``"pi_ticks"`` (default True: ticks at the
        multiples of pi), ``"legend"`` (legend location, default upper left; ``"below"``
        puts it under the axes).
    """
    n = len(panels)
    ncols = ncols or min(n, 2)
    nrows = int(math.ceil(n / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.4 * ncols, 4.0 * nrows), squeeze=False)
    for ax, panel in zip(axes.flat, panels):
        for label, tau, theta in panel["curves"]:
            ax.plot(tau, theta, lw=1.3, label=label)
        if panel.get("limit") is not None:
            ax.plot(*panel["limit"], "k--", lw=0.9, label=LIMIT_LABEL)
        ax.set_title(panel["title"])
        ax.set_xlabel(TAU_LABEL)
        ax.set_ylabel(panel.get("ylabel", r"$\theta$ (rad)"))
        ax.set_xlim(0, 1)
        if panel.get("pi_ticks", True):
            _pi_ticks(ax)
        if panel.get("legend") == "below":
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
        else:
            ax.legend(loc=panel.get("legend", "upper left"))
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    return _finish(fig, path)


@figure_style()
def plot_square_approximations(omega: float, alphas, path=None):
    """Unit square wave and its tanh approximations of Eq. 26 (paper Fig. 8 right)."""
    from .excitation import square

    fig, ax = plt.subplots(figsize=(7, 3.8))
    period = 2 * np.pi / omega
    t = np.linspace(0, period, 4001)
    ax.plot(t, np.where(t < period / 2, 1.0, -1.0), "k-", lw=2.2, alpha=0.35,
            label="unit square wave")
    for a in alphas:
        ax.plot(t, square(1.0, omega, a).q(t), lw=1.1, label=rf"Eq. 26, $\alpha = {a:g}$")
    ax.set_xlabel(r"$t$ (units of $\sqrt{l/g}$)")
    ax.set_ylabel("$H(t)$ (-)")
    ax.set_title(rf"Square wave and tanh approximations over one period ($\omega = {omega:g}$)")
    ax.legend()
    return _finish(fig, path)
