"""Figures (matplotlib, Agg backend); saved as PNG or SVG by extension, atomically."""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg", force=False)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .model import torque  # noqa: E402
from .optimal.limit import limit  # noqa: E402

__all__ = ["plot_damping_sweep", "plot_harmonic_table", "plot_optimum", "save_figure"]


def save_figure(fig, path) -> Path:
    """Save ``fig`` to ``path`` through a temporary file, so an old file is never half-written."""
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower() or "png"
    fd, tmp = tempfile.mkstemp(dir=path.parent or ".", prefix=".tmp-", suffix=path.suffix)
    os.close(fd)
    try:
        fig.savefig(tmp, format=fmt, dpi=130, bbox_inches="tight")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
        plt.close(fig)
    return path


def _finish(fig, path):
    """Lay out, save if ``path`` is given, and return the figure."""
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig


def _pi_label(v: float) -> str:
    k = int(round(v / np.pi))
    return {0: "0", 1: "π", -1: "-π"}.get(k, f"{k}π")


def _tau(omega, t):
    return omega * np.asarray(t) / (2 * math.pi)


def plot_optimum(result, path=None, points: int = 2000):
    """theta(tau) and torque of an optimum, with the gamma -> 0 limit motion (cf. paper Fig. 4).

    ``tau = omega t / 2 pi`` over one forcing period. Returns the figure (saved if ``path``).
    """
    exc = result._excitation
    motion = result.motion
    om = exc.omega
    t = exc.period * np.arange(points + 1) / points
    tau = _tau(om, t)
    lim = limit(exc)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 2]})
    label = f"{result.method}, N = {result.harmonics}" if result.method == "fourier" \
        else result.method
    ax1.plot(tau, motion.theta(t), lw=1.8, label=f"optimum ({label}): P = {result.power:.5f}")
    ax1.plot(tau, lim.motion.theta(t), "k--", lw=1, label=f"limit gamma -> 0: P = {lim.power:.5f}")
    from .power import uniform_power

    _, phi = uniform_power(exc, result.gamma)
    ax1.plot(tau, om * t + phi, ":", color="gray", lw=1,
             label=f"best uniform: P = {result.uniform_power:.5f}")
    ax1.set_ylabel("theta (rad, from upright)")
    ax1.set_yticks(np.pi * np.arange(0, 5))
    ax1.set_yticklabels([_pi_label(np.pi * k) for k in range(5)])
    ax1.grid(alpha=0.3)
    ax1.legend(loc="upper left", fontsize=8)
    desc = ", ".join(f"{k}={v}" for k, v in result.excitation.items() if k != "terms")
    ax1.set_title(f"Optimal period-1 rotation ({desc}, gamma={result.gamma:g})", fontsize=9)
    tq = torque(motion, exc, result.gamma, t)
    ax2.plot(tau, tq, color="C3", lw=1.2)
    ax2.set_ylabel("torque T (non-dim.)")
    ax2.set_xlabel("tau = omega t / 2 pi")
    ax2.grid(alpha=0.3)
    ax2.set_xlim(0, 1)
    return _finish(fig, path)


def plot_damping_sweep(ds, path=None):
    """Optimal and uniform power against damping with the threshold (cf. paper Fig. 6)."""
    fig, ax = plt.subplots(figsize=(7, 4.2))
    g = ds["gamma"].values
    ax.plot(g, ds["power"].values, "o-", ms=3,
            label=f"optimal (Fourier, N = {ds.attrs['harmonics']})")
    ax.plot(g, ds["uniform_power"].values, "--", label="best uniform rotation")
    ax.axhline(0, color="k", lw=0.7)
    gs = ds.attrs["damping_threshold"]
    ax.axvline(gs, color="C3", lw=0.8, ls=":")
    ax.annotate(f"gamma* = {gs:.6f}", (gs, 0), xytext=(5, 12), textcoords="offset points",
                color="C3")
    ax.plot([0], [ds.attrs["limit_power"]], "k*", label="limit gamma -> 0")
    ax.set_xlabel("damping gamma")
    ax.set_ylabel("mean extracted power P")
    ax.grid(alpha=0.3)
    ax.legend()
    return _finish(fig, path)


def plot_harmonic_table(ds, path=None):
    """Optimal power against the number of harmonics N, with the uniform and limit powers."""
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(ds["harmonics"].values, ds["power"].values, "o-", ms=3, label="Fourier optimum")
    ax.axhline(ds.attrs["limit_power"], color="k", ls="--", label="limit gamma -> 0")
    ax.axhline(ds.attrs["uniform_power"], color="gray", ls=":", label="best uniform")
    ax.set_xlabel("harmonics N")
    ax.set_ylabel("mean extracted power P")
    ax.grid(alpha=0.3)
    ax.legend()
    return _finish(fig, path)


def plot_theta_panels(panels, path=None, ncols: int | None = None):
    """Families of motions theta(tau), one panel each (paper Figs. 4, 5, 7, 9, 10).

    Parameters
    ----------
    panels : list of dict
        ``{"title": str, "curves": [(label, tau, theta), ...], "limit": (tau, theta) or None}``
        with ``tau = omega t / 2 pi`` over one period and theta in radians.
    """
    n = len(panels)
    ncols = ncols or min(n, 2)
    nrows = int(math.ceil(n / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 3.9 * nrows), squeeze=False)
    for ax, panel in zip(axes.flat, panels):
        for label, tau, theta in panel["curves"]:
            ax.plot(tau, theta, lw=1.3, label=label)
        if panel.get("limit") is not None:
            ax.plot(*panel["limit"], "k--", lw=0.9, label="limit gamma -> 0")
        ax.set_title(panel["title"], fontsize=9)
        ax.set_xlabel("tau = omega t / 2 pi")
        ax.set_ylabel("theta (rad)")
        ax.set_xlim(0, 1)
        lo, hi = ax.get_ylim()
        ticks = np.pi * np.arange(math.floor(lo / np.pi), math.ceil(hi / np.pi) + 1)
        ax.set_yticks(ticks)
        ax.set_yticklabels([_pi_label(v) for v in ticks])
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    return _finish(fig, path)


def plot_square_approximations(omega: float, alphas, path=None):
    """Unit square wave and its tanh approximations of Eq. 26 (paper Fig. 8 right)."""
    from .excitation import square

    fig, ax = plt.subplots(figsize=(7, 3.8))
    period = 2 * np.pi / omega
    t = np.linspace(0, period, 4001)
    ax.plot(t, np.where(t < period / 2, 1.0, -1.0), "k-", lw=2.2, alpha=0.35,
            label="unit square wave")
    for a in alphas:
        ax.plot(t, square(1.0, omega, a).q(t), lw=1.1, label=f"Eq. 26, alpha = {a:g}")
    ax.set_xlabel("t")
    ax.set_ylabel("H(t)")
    ax.set_title(f"Square wave and tanh approximations over one period (omega = {omega:g})",
                 fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _finish(fig, path)
