r"""Causal baselines for a sea record: what a controller without a forecast gets.

Both run on the full nonlinear Eq. 14 from the hanging rest, sample the state every
``h = Tp / SAMPLES_PER_PEAK`` and hold their torque over the interval (zero-order hold,
classical RK4 with 4 steps per interval, as :mod:`.closedloop`), so the work of an interval
is exactly ``-T_k (theta_{k+1} - theta_k)``. The efficiency model is that of
:mod:`parapend.pto`: an interval that generates ``w > 0`` delivers ``eta_g w``, one that
motors costs ``w / eta_m``.

- :func:`tracker_baseline`: the regular-wave tracker of ``parapend track --irregular``
  (:func:`.track.prepare` and :func:`.closedloop.run_closed_loop` as they are): it holds the
  optimal rotation for the harmonic excitation at the peak frequency whose ``q`` has the
  record's root mean square, ``q = -sqrt(2) rms(q) sin(omega_p t)``, while the record
  drives the plant.
- :func:`extremum_baseline`: a causal rule read off the ``gamma -> 0`` limit motion
  (docs/limit.md): upright while ``q`` rises, hanging while it falls, a half-turn at each
  extremum of ``q``. The extrema are detected as they pass, from the measured
  samples of ``q`` alone: a maximum when ``q`` has fallen by ``hysteresis rms(q)`` below its
  running maximum (a zig-zag filter; 0: every change of sign of the sampled slope). At each
  one the reference angle steps by ``pi`` (the pendulum turns whichever way the error,
  wrapped to a turn, points). The torque is a computed-torque PD law
  toward it, ``T = -(1 + q) sin(theta) + gamma theta' - w^2 e - 2 w theta'`` with the wrapped
  error ``e``, saturated at the torque limit; when a limited torque cannot hold the
  pendulum against gravity the same law pushes it forward through the half-turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError, check_range
from .closedloop import Diverged, held_torque_step, run_closed_loop

__all__ = ["BaselineRun", "electrical_work", "extremum_baseline", "tracker_baseline",
           "BASELINES"]

#: baselines by name (``parapend horizon``)
BASELINES = ("tracker", "extremum")
#: controller samples per peak period
SAMPLES_PER_PEAK = 256
#: RK4 steps per sample interval
SUBSTEPS = 4


@dataclass(frozen=True, eq=False)
class BaselineRun:
    """One baseline run: samples ``k = 0, ..., K`` at ``t_k = k h`` (``torque[k]`` held on
    ``[t_k, t_k + h)``), ``work[k]`` the electrical work of interval ``k`` (positive =
    harvested) and ``mean_power = sum(work) / t[-1]``."""

    name: str
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    torque: np.ndarray
    q: np.ndarray
    work: np.ndarray
    mean_power: float
    success: bool
    status: str
    message: str
    info: dict = field(default_factory=dict)

    @property
    def power_series(self) -> np.ndarray:
        """Mean electrical power of each sample interval."""
        return self.work / np.diff(self.t)


def electrical_work(torque, theta, efficiency=None) -> np.ndarray:
    """Per-interval electrical work of a held torque: ``w = -T_k (theta_{k+1} - theta_k)``,
    times ``eta_g`` when positive and divided by ``eta_m`` when negative
    (``efficiency = (eta_g, eta_m)`` or None: lossless)."""
    w = -np.asarray(torque)[:-1] * np.diff(np.asarray(theta))
    if efficiency is None:
        return w
    eg, em = efficiency
    return np.where(w > 0, eg * w, w / em)


def _efficiency(efficiency):
    if efficiency is None:
        return None
    from ..pto import efficiencies

    return efficiencies(efficiency)


def _grid(peak_period: float, t_end: float):
    h = peak_period / SAMPLES_PER_PEAK
    n = int(math.floor(t_end / h + 1e-9))
    if n < 1:
        raise ParameterError(f"t_end: expected at least one sample interval ({h:.3g}), got "
                             f"{t_end:g}")
    return h, n


def tracker_baseline(q, *, peak_omega: float, gamma: float, t_end: float,
                     torque_limit=None, efficiency=None, torque_margin: float = 0.1,
                     theta0: float = math.pi, theta_dot0: float = 0.0) -> BaselineRun:
    """The tracker of ``track --irregular`` on the record ``q`` (vectorized callable).

    The design is the harmonic excitation ``-sqrt(2) rms sin(peak_omega t)`` (``rms`` of
    ``q`` over ``[0, t_end]``) at ``gamma`` and the torque limit; the run lasts the whole
    design periods in ``t_end`` (its mean power is over them).
    """
    from .track import prepare

    peak_omega = check_range("peak-omega", peak_omega, 1e-6, 1e6)
    period = 2 * math.pi / peak_omega
    periods = int(math.floor(t_end / period + 1e-9))
    if periods < 1:
        raise ParameterError(f"t_end: expected at least one peak period ({period:.4g}), got "
                             f"{t_end:g}")
    ts = np.linspace(0.0, t_end, 4096, endpoint=False)
    rms = math.sqrt(float(np.mean(np.asarray(q(ts), dtype=float) ** 2)))
    d = prepare(torque_limit=torque_limit, torque_margin=torque_margin, gamma=gamma,
                omega=peak_omega, delta=-math.sqrt(2.0) * rms)
    tg = d.target
    info = {"design_delta": -math.sqrt(2.0) * rms, "design_power": tg.power,
            "design_status": d.status, "periods": periods}
    eff = _efficiency(efficiency)
    if d.status == "infeasible":
        return _failed("tracker", "infeasible", f"no rotation within the design torque "
                       f"limit: {d.message}", info)
    try:
        run = run_closed_loop(tg, d.lqr.gains, periods=periods, torque_limit=d.torque_limit,
                              plant_q=q, plant_gamma=gamma, state0=(theta0, theta_dot0))
    except Diverged as exc:
        return _failed("tracker", "diverged", str(exc), info)
    w = electrical_work(run.torque, run.theta, eff)
    return BaselineRun("tracker", run.t, run.theta, run.theta_dot, run.torque, run.q, w,
                       float(np.sum(w) / run.t[-1]), True, "done",
                       f"regular-wave tracker over {periods} peak periods", info)


def _failed(name, status, message, info) -> BaselineRun:
    e = np.zeros(0)
    return BaselineRun(name, e, e, e, e, e, e, math.nan, False, status, message, info)


def extremum_baseline(q, *, peak_omega: float, gamma: float, t_end: float,
                      torque_limit=None, efficiency=None, bandwidth: float = 2.0,
                      hysteresis: float = 0.0, theta0: float = math.pi,
                      theta_dot0: float = 0.0) -> BaselineRun:
    """The causal half-turn rule of the limit motion (module docstring) on the record ``q``.

    Parameters
    ----------
    bandwidth : float
        ``w`` of the PD law (rad per unit time; a half-turn takes a few ``1/w``).
    hysteresis : float
        Zig-zag threshold in units of ``rms(q)`` (0: every change of sign of the slope).
    """
    peak_omega = check_range("peak-omega", peak_omega, 1e-6, 1e6)
    w_pd = check_range("bandwidth", bandwidth, 1e-3, 1e3)
    hyst = check_range("hysteresis", hysteresis, 0.0, 10.0)
    h, n = _grid(2 * math.pi / peak_omega, t_end)
    dt = h / SUBSTEPS
    tq = 0.5 * dt * np.arange(2 * SUBSTEPS * n + 1)
    qg = np.asarray(q(tq), dtype=float)
    rms = math.sqrt(float(np.mean(qg**2)))
    eps = hyst * rms
    qs = qg[:: 2 * SUBSTEPS].tolist()
    qgl = qg.tolist()
    tmax = math.inf if torque_limit is None else float(torque_limit)
    th, om = float(theta0), float(theta_dot0)
    two_pi, sin = 2 * math.pi, math.sin
    # reference: hanging (pi mod 2 pi) until the first extremum
    ref = math.pi * math.floor(th / math.pi + 0.5)
    if round(ref / math.pi) % 2 == 0:
        ref += math.pi
    rising = None
    hi = lo = qs[0]
    flips = 0
    out_th, out_om, out_t = [0.0] * (n + 1), [0.0] * (n + 1), [0.0] * (n + 1)
    k2, k1 = w_pd * w_pd, 2.0 * w_pd
    for k in range(n + 1):
        out_th[k], out_om[k] = th, om
        qk = qs[k]
        # zig-zag detection of the extrema from the samples up to k
        if rising is None:
            if qk > lo + eps and k > 0 and qk > qs[k - 1]:
                rising, hi = True, qk
            elif qk < hi - eps and k > 0 and qk < qs[k - 1]:
                rising, lo = False, qk
            hi, lo = max(hi, qk), min(lo, qk)
            if rising is not None:
                want_up = rising
                is_up = round(ref / math.pi) % 2 == 0
                if want_up != is_up:
                    ref += math.pi
                    flips += 1
        elif rising:
            if qk > hi:
                hi = qk
            elif qk < hi - eps or (eps == 0 and qk < qs[k - 1]):
                rising, lo = False, qk
                ref += math.pi
                flips += 1
        else:
            if qk < lo:
                lo = qk
            elif qk > lo + eps or (eps == 0 and qk > qs[k - 1]):
                rising, hi = True, qk
                ref += math.pi
                flips += 1
        e = th - ref
        e = (e + math.pi) % two_pi - math.pi if abs(e) > math.pi else e
        u = -(1.0 + qk) * sin(th) + gamma * om - k2 * e - k1 * om
        u = tmax if u > tmax else (-tmax if u < -tmax else u)
        out_t[k] = u
        if k == n:
            break
        base = 2 * SUBSTEPS * k
        for s in range(SUBSTEPS):
            th, om = held_torque_step(th, om, u, qgl, base + 2 * s, dt, gamma)
        if not -1e12 < om < 1e12:
            return _failed("extremum", "diverged", f"|theta'| unbounded at sample {k}", {})
    t = h * np.arange(n + 1)
    theta = np.array(out_th)
    torque = np.array(out_t)
    w = electrical_work(torque, theta, _efficiency(efficiency))
    return BaselineRun("extremum", t, theta, np.array(out_om), torque, np.asarray(qs), w,
                       float(np.sum(w) / t[-1]), True, "done",
                       f"{flips} half-turns at the detected extrema of q",
                       {"half_turns": flips, "bandwidth": w_pd, "hysteresis": hyst})
