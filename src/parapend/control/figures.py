"""Figure of a closed-loop run: angle, torque and cumulative extracted energy."""

from __future__ import annotations

import math

import numpy as np

from .closedloop import energy_series

__all__ = ["plot_track"]


def plot_track(result, path=None, zoom_periods: int = 3):
    """Swing-up and catch, the locked orbit against its target, the tracking error and the
    extracted energy of a closed-loop run.

    Panels, against time in forcing periods: top row, ``theta - omega t`` (``theta`` from the
    upright, unwrapped: bounded on a period-1 rotation) from rest to a few periods past the
    lock (left) and over the last ``zoom_periods`` periods (right), the target orbit
    dashed (shifted by the whole turns the run gained or lost while it was caught); second
    row, the applied (held) torque over the same windows with ``+-T_max``; third, the
    largest wrapped angle error of each period on a log axis with the lock tolerance;
    bottom, the cumulative extracted energy ``W`` at the end of each period with the
    predicted optimum's slope from the lock on.
    """
    from ..plotting import _finish, plt
    from ..style import figure_style

    run, tg = result.run, result.target
    units = result.physical_units  # torque in N m, energy in J, an SI title: SI given
    kt = 1.0 if units is None else units.torque
    m = tg.samples
    per = run.t / tg.period
    k = np.arange(run.t.size)
    ref = tg.theta[k % m] + 2 * math.pi * (k // m)
    err = np.abs((run.theta - ref + math.pi) % (2 * math.pi) - math.pi)
    total = (run.t.size - 1) // m
    tail = slice(max(0, run.t.size - m - 1), run.t.size)
    ref = ref + 2 * math.pi * round(float(np.median(run.theta[tail] - ref[tail])) / (2 * math.pi))
    w = energy_series(run)
    rel, rel_ref = run.theta - tg.omega * run.t, ref - tg.omega * run.t
    locked = bool(result.locked)
    head = min(total, (int(result.lock_period) + 5) if locked else 20)
    zoom = max(1, min(int(zoom_periods), total))
    first = per <= head + 1e-9
    last = per >= per[-1] - zoom - 1e-9
    with figure_style():
        fig = plt.figure(figsize=(9.0, 9.5), layout="constrained")
        grid = fig.add_gridspec(4, 2, height_ratios=(1.2, 1, 1, 1))
        a_up = fig.add_subplot(grid[0, 0])
        a_zoom = fig.add_subplot(grid[0, 1])
        t_up = fig.add_subplot(grid[1, 0], sharex=a_up)
        t_zoom = fig.add_subplot(grid[1, 1], sharex=a_zoom)
        a_err = fig.add_subplot(grid[2, :])
        a_w = fig.add_subplot(grid[3, :], sharex=a_err)
        for ax, sel in ((a_up, first), (a_zoom, last)):
            ax.plot(per[sel], rel[sel], lw=1.2, color="C0")
            ax.plot(per[sel], rel_ref[sel], lw=1.2, ls="--", color="C3")
            ax.set_ylabel(r"$\theta - \omega t$ (rad)")
        key = r"(solid: run; dashed: target $\theta^*$)"
        a_up.set_title(("swing-up and catch " if locked else f"first {head} periods ") + key,
                       fontsize=9)
        a_zoom.set_title(f"last {zoom} period{'s' if zoom > 1 else ''} {key}", fontsize=9)
        for ax, sel in ((t_up, first), (t_zoom, last)):
            ax.plot(per[sel], kt * run.torque[sel], lw=1.0, color="C2",
                    drawstyle="steps-post")
            if result.torque_limit is not None:
                for s in (1, -1):
                    ax.axhline(s * kt * result.torque_limit, color="k", ls="--", lw=0.7)
            ax.set_ylabel("torque $T$ ($mgl$)" if units is None else "torque $T$ (N m)")
            ax.set_xlabel("time (forcing periods)")
        a_up.set_xlim(0, per[first][-1])
        a_zoom.set_xlim(per[last][0], per[-1])
        a_up.tick_params(labelbottom=False)
        a_zoom.tick_params(labelbottom=False)
        # the largest error of each period: one point per period instead of a band
        n = max(1, total)
        emax = np.array([err[i * m:(i + 1) * m + 1].max() for i in range(n)])
        floor = max(1e-12, 0.3 * float(emax[emax > 0].min())) if np.any(emax > 0) else 1e-12
        a_err.semilogy(np.arange(n) + 1, np.maximum(emax, floor), ".-", ms=3, lw=0.8,
                       color="C1", label="largest |angle error| of the period")
        a_err.axhline(result.lock_tolerance, color="k", ls="--", lw=0.7,
                      label=f"lock tolerance {result.lock_tolerance:g} rad")
        a_err.set_ylabel("angle error (rad)")
        a_err.set_xlabel("time (forcing periods)")
        a_err.legend(loc="best")
        ends = m * np.arange(n + 1)
        ke = 1.0 if units is None else units.energy
        a_w.plot(per[ends], ke * w[ends], ".-", ms=3, color="C0", lw=1.0,
                 label="extracted energy $W$ at the end of each period")
        if locked:
            tl = int(result.lock_period)
            pred = (f"$P = {tg.power:.5g}$" if units is None
                    else f"$P$ = {units.to_watts(tg.power):.4g} W")
            a_w.plot(per[tl * m:], ke * (w[tl * m] + tg.power * (run.t[tl * m:]
                                                               - run.t[tl * m])),
                     "k:", lw=1, label=f"predicted {pred} from the lock")
            for a in (a_up, t_up, a_err, a_w):
                a.axvline(tl, color="gray", lw=0.7)
        a_w.axhline(0, color="gray", lw=0.5)
        a_w.set_ylabel("energy $W$ ($mgl$)" if units is None else "energy $W$ (J)")
        a_w.set_xlabel("time (forcing periods)")
        a_w.legend(loc="best")
        a_err.set_xlim(0, per[-1])
        if units is None:
            case = (f"$\\gamma$ = {result.gamma:g}, $\\omega$ = {result.omega:g}, "
                    f"$T_{{\\max}}$ = {_num(result.torque_limit)}")
        else:
            from ..plotting import si_title

            case = si_title(result, units) + ", $T_{\\max}$ = " + (
                "none" if result.torque_limit is None
                else f"{units.to_newton_metres(result.torque_limit):.4g} N m")
        fig.suptitle(f"track: {case}; "
                     + (f"locked after {result.lock_period} periods" if locked
                        else "not locked"), fontsize=10)
        return _finish(fig, path, layout=False)


def _num(x) -> str:
    return "none" if x is None else f"{x:.4g}"


def plot_mpc_track(result, zoom_periods: float = 3.0):
    """A receding-horizon run: ``theta - omega t``, the held torque with ``+-T_max``, the
    excitation ``q`` and the cumulative harvested energy, against time in forcing periods
    (the whole run on the left, the last ``zoom_periods`` on the right).

    ``result`` is a ``track --controller mpc`` result (``run``, ``q``, ``omega``) or a bare
    :class:`~parapend.control.mpc.MPCResult` (no ``q`` panel then)."""
    from ..plotting import _finish, plt
    from ..style import figure_style

    run = getattr(result, "run", result)
    omega = getattr(result, "omega", None) or 2 * math.pi / max(run.t[-1], 1e-12)
    period = 2 * math.pi / omega
    per = run.t / period
    held = np.append(run.torque, run.torque[-1])
    work = np.concatenate(([0.0], np.cumsum(run.power_series) * run.dt))
    e = 0.5 * run.theta_dot**2 + np.cos(run.theta)  # stored energy, theta from the upright
    stored = work + e - e[0]
    q = result.q(run.t) if hasattr(result, "q") and callable(result.q) else None
    last = per >= per[-1] - zoom_periods - 1e-9
    rows = 4 if q is not None else 3
    with figure_style():
        fig, axes = plt.subplots(rows, 2, figsize=(9.0, 2.2 * rows + 1), sharex="col",
                                 layout="constrained")
        for col, sel in ((0, slice(None)), (1, last)):
            a = axes[:, col]
            a[0].plot(per[sel], run.theta[sel] - omega * run.t[sel], lw=1.0, color="C0")
            a[0].set_ylabel(r"$\theta - \omega t$ (rad)")
            a[1].step(per[sel], held[sel], where="post", lw=0.9, color="C2")
            if result.torque_limit is not None:
                for s in (1, -1):
                    a[1].axhline(s * result.torque_limit, color="k", ls="--", lw=0.7)
            a[1].set_ylabel("torque $T$ ($mgl$)")
            a[2].plot(per[sel], work[sel], lw=1.0, color="C1", label="harvested $W$")
            a[2].plot(per[sel], stored[sel], lw=0.9, color="C3", ls="--",
                      label=r"$W + E - E_0$ (stored counted)")
            a[2].set_ylabel("energy ($mgl$)")
            if q is not None:
                a[3].plot(per[sel], q[sel], lw=0.8, color="C4")
                a[3].set_ylabel("$q$ (base acc./g)")
            a[-1].set_xlabel("time (forcing periods)")
        axes[2, 0].legend(fontsize=7, loc="best")
        axes[0, 0].set_title("whole run", fontsize=9)
        axes[0, 1].set_title(f"last {zoom_periods:g} periods", fontsize=9)
        fig.suptitle(f"receding-horizon control ({result.forecast} forecast): mean power "
                     f"{result.mean_power:.5g} ($mgl/t_0$, stored energy counted), "
                     f"{result.failed_solves} of "
                     f"{result.solves} solves failed", fontsize=10)
        return _finish(fig, None, layout=False)
