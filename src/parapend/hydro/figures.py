"""Figures of ``parapend buoy`` (house style: :mod:`parapend.style`): the coupled optimum over
one wave period, and power against wave period with the radiation bound."""

from __future__ import annotations

import numpy as np

from ..style import figure_style

__all__ = ["plot_hull", "plot_hull_sweep", "plot_motion", "plot_sweep"]


def _finish(fig, path):
    fig.align_ylabels()  # one column of labels, clear of the widest tick labels
    fig.tight_layout()
    if path is not None:
        from ..fileio import save_figure

        save_figure(fig, path, close=False)
    return fig


@figure_style()
def plot_motion(result, path=None, points: int = 600):
    """theta, the buoy's heave and the generator torque over one period of the coupled
    optimum (a :class:`~parapend.hydro.result.BuoyResult`), with the free buoy's heave."""
    import matplotlib.pyplot as plt

    s = result.samples(points)
    t = s["t"]
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    ax1.plot(t, s["theta"], lw=1.6, color="C0")
    ax1.set_ylabel(r"$\theta$ (rad, from upright)")
    w = result.wave
    what = (f"H = {w['height_m']:g} m, T = {w['period_s']:g} s" if w.get("kind") == "regular"
            else "irregular record")
    ax1.set_title(f"Coupled optimum ({what}): P = {result.power_w:.4g} W, "
                  f"one-way {_w(result.one_way_power_w)}")
    ax2.plot(t, s["z"], lw=1.6, color="C1", label="coupled (with the pendulum)")
    ax2.plot(t, s["z_free"], "--", lw=1.0, color="gray", label="free buoy")
    ax2.set_ylabel("heave z (m)")
    ax2.legend(loc="best", fontsize="small")
    return _torque_panel(fig, ax3, t, s["tau"], path)


def _torque_panel(fig, ax, t, tau, path):
    """The generator torque over the period, the bottom panel of the motion figures."""
    ax.plot(t, tau, lw=1.4, color="C3")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel(r"torque $\tau$ (N m)")
    ax.set_xlabel("time t (s)")
    ax.set_xlim(t[0], t[-1])
    return _finish(fig, path)


def _w(p):
    return "-" if p is None else f"{p:.4g} W"


def _pos(y):
    """A log axis draws no power as a gap."""
    y = np.asarray(y, dtype=float)
    return np.where(y > 0, y, np.nan)


def _power_against_period(t, powers, title, amplitudes, amp_label, path):
    """Two panels over wave period ``t``: powers on a log axis (``(values, style, kwargs)``
    per curve) and amplitudes below (the same)."""
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 2]})
    for values, style, kw in powers:
        ax1.plot(t, _pos(values), style, **kw)
    ax1.set_yscale("log")
    ax1.set_ylabel("power (W)")
    ax1.legend(loc="best", fontsize="small")
    ax1.set_title(title)
    for values, style, kw in amplitudes:
        ax2.plot(t, values, style, **kw)
    ax2.set_ylabel(amp_label)
    ax2.set_xlabel("wave period T (s)")
    ax2.legend(loc="best", fontsize="small")
    ax2.set_xlim(t[0], t[-1])
    return _finish(fig, path)


@figure_style()
def plot_sweep(sweep, path=None):
    """Power against wave period (a :class:`~parapend.hydro.result.BuoySweepResult`): the
    coupled optimum, the one-way answer, the radiation bound and the coupled limit."""
    return _power_against_period(
        np.asarray(sweep.period_s),
        [(sweep.radiation_bound_w, "k-", {"lw": 1.0, "label": "radiation bound"}),
         (sweep.limit_w, "k:", {"lw": 1.2, "label": "coupled limit (c = 0)"}),
         (sweep.one_way_power_w, "--", {"color": "C2", "lw": 1.4, "marker": "s", "ms": 3,
                                        "label": "one-way (reaction left out)"}),
         (sweep.power_w, "-", {"color": "C0", "lw": 1.8, "marker": "o", "ms": 3,
                               "label": "coupled optimum"})],
        f"Power against wave period, H = {sweep.wave_height_m:g} m",
        [(sweep.heave_amplitude_m, "-", {"color": "C1", "lw": 1.6, "label": "coupled"}),
         (sweep.free_heave_amplitude_m, "--", {"color": "gray", "lw": 1.0,
                                               "label": "free buoy"})],
        "heave amplitude (m)", path)


@figure_style()
def plot_hull(result, path=None, points: int = 600):
    """The best mode of a pendulum in a surging, heaving, pitching hull over one period (a
    :class:`~parapend.hydro.result.BuoyResult` of a hull): the pendulum's angle, the hull's
    motion, the generator torque."""
    import matplotlib.pyplot as plt

    s = result.samples(points)
    t = s["t"]
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    ax1.plot(t, np.degrees(s["phi"]), lw=1.6, color="C0")
    ax1.set_ylabel(r"$\varphi$ (deg, from upright)")
    w = result.wave
    what = (f"H = {w['height_m']:g} m, T = {w['period_s']:g} s" if w.get("kind") == "regular"
            else "irregular record")
    lossy = result.efficiency is not None or bool(result.copper_loss_w_per_nm2)
    power = ("P none (no resolved answer)" if result.headline_reason else
             f"P_el = {result.power_w:.4g} W (mechanical {result.mechanical_power_w:.4g} W)"
             if lossy else f"P = {result.power_w:.4g} W")
    ax1.set_title(f"{result.mode.capitalize()} ({what}): {power},"
                  + ("\n" if lossy else " ") + f"one-way {_w(result.one_way_power_w)}")
    ax2.plot(t, s["xi"][0], lw=1.4, color="C1", label="surge (m)")
    ax2.plot(t, s["xi"][1], lw=1.4, color="C2", label="heave (m)")
    ax2.plot(t, np.degrees(s["xi"][2]), lw=1.4, color="C4", label="pitch (deg)")
    ax2.set_ylabel("hull motion")
    ax2.legend(loc="best", fontsize="small")
    return _torque_panel(fig, ax3, t, s["tau"], path)


@figure_style()
def plot_hull_sweep(sweep, path=None):
    """Rotation against swinging over wave period (a
    :class:`~parapend.hydro.result.BuoySweepResult` of a hull): each mode's optimum, the one-way
    answer and the radiation bound; the hull's heave and pitch."""
    return _power_against_period(
        np.asarray(sweep.period_s),
        [(sweep.radiation_bound_w, "k-", {"lw": 1.0, "label": "radiation bound"}),
         (sweep.rotation_power_w, "-", {"color": "C0", "lw": 1.8, "marker": "o", "ms": 3,
                                        "label": "rotation (one turn per wave, the better sense)"}),
         (sweep.swinging_power_w, "-", {"color": "C3", "lw": 1.8, "marker": "s", "ms": 3,
                                        "label": "swinging"}),
         (sweep.one_way_power_w, "--", {"color": "C2", "lw": 1.2,
                                        "label": "one-way, best mode (reaction left out)"})],
        f"Rotate or swing: power against wave period, H = {sweep.wave_height_m:g} m",
        [(sweep.heave_amplitude_m, "-", {"color": "C1", "lw": 1.6, "label": "heave (m)"}),
         (sweep.pitch_amplitude_deg, "-", {"color": "C4", "lw": 1.6,
                                           "label": "pitch (deg)"})],
        "hull amplitude, best mode", path)
