"""Figure of a closed-loop run: angle, torque and cumulative extracted energy."""

from __future__ import annotations

import math

import numpy as np

from .closedloop import energy_series

__all__ = ["plot_track"]


def plot_track(result, path=None):
    """Four panels against time in forcing periods: ``theta - omega t`` (``theta`` from the
    upright, unwrapped: bounded on a period-1 rotation) with the target orbit's, the wrapped
    angle error (log scale: the lock shows as the drop below the tolerance), the applied
    torque with ``+-T_max``, and the cumulative extracted energy ``W(t)`` with the predicted
    optimum's slope from the lock on."""
    from ..plotting import _finish, plt
    from ..style import figure_style

    run, tg = result._run, result._target
    m = tg.samples
    per = run.t / tg.period
    k = np.arange(run.t.size)
    ref = tg.theta[k % m] + 2 * math.pi * (k // m)
    err = np.abs((run.theta - ref + math.pi) % (2 * math.pi) - math.pi)
    w = energy_series(run)
    with figure_style():
        fig, (a1, a0, a2, a3) = plt.subplots(4, 1, figsize=(7.5, 8.5), sharex=True)
        a1.plot(per, run.theta - tg.omega * run.t, lw=0.5, color="C0",
                label=r"run")
        a1.plot(per, ref - tg.omega * run.t, lw=0.5, color="C3", alpha=0.6,
                label=r"target $\theta^*$")
        a1.set_ylabel(r"$\theta - \omega t$ (rad)")
        a1.legend(fontsize=8, loc="upper right")
        a1.set_title(f"track: gamma = {result.gamma:g}, omega = {result.omega:g}, "
                     f"T_max = {_num(result.torque_limit)}; "
                     + (f"locked after {result.lock_period} periods" if result.locked
                        else "not locked"), fontsize=9)
        floor = max(1e-12, 0.3 * float(np.percentile(err[err > 0], 1))) if np.any(err > 0) \
            else 1e-12
        a0.semilogy(per, np.maximum(err, floor), lw=0.5, color="C1")
        a0.set_ylim(bottom=floor)
        a0.axhline(result.lock_tolerance, color="k", ls="--", lw=0.7)
        a0.set_ylabel("|angle error| (rad)")
        a2.plot(per, run.torque, lw=0.5, color="C2")
        if result.torque_limit is not None:
            for s in (1, -1):
                a2.axhline(s * result.torque_limit, color="k", ls="--", lw=0.7)
        a2.set_ylabel("torque T (m g l)")
        a3.plot(per, w, color="C0", lw=1.2, label="extracted energy W (run)")
        if result.locked:
            tl = result.lock_period
            a3.plot(per[tl * m:], w[tl * m] + tg.power * (run.t[tl * m:] - run.t[tl * m]),
                    "k:", lw=1, label=f"predicted P = {tg.power:.5g} from the lock")
            for a in (a1, a0, a2, a3):
                a.axvline(tl, color="gray", lw=0.7)
        a3.axhline(0, color="gray", lw=0.5)
        a3.set_ylabel("energy (m g l)")
        a3.set_xlabel("time (forcing periods)")
        a3.legend(fontsize=8)
        for a in (a1, a0, a2, a3):
            a.grid(alpha=0.3)
        a1.set_xlim(0, per[-1])
        return _finish(fig, path)


def _num(x) -> str:
    return "none" if x is None else f"{x:.4g}"
