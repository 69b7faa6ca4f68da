"""One motion of the uncontrolled pendulum (paper Eq. 1): time history, phase portrait and
the classification of where it ends up (paper Fig. 1 right).

The trajectory is integrated by DOP853 (:func:`parapend.dynamics.simulate.trajectory`) on a
time grid with ``points_per_period`` samples per forcing period ``T = 2*pi/omega``, so that
every ``points_per_period``-th sample lies on the Poincare section ``t0 + m*T``; those
samples are classified by :func:`parapend.dynamics.classify` (period-k
oscillation, rotation, rest, or "other").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import limits
from ..errors import ParameterError, check_finite, check_int, check_positive, check_range
from .attractors import Classification, classify
from .simulate import CONVENTION, _check_params, energy, trajectory

__all__ = ["Motion", "simulate"]

#: most forcing periods of one simulated motion, and most stored samples (memory, CSV size)
MAX_PERIODS = 20000
MAX_SAMPLES = 2_000_000


@dataclass(frozen=True, eq=False)
class Motion:
    """A simulated motion of paper Eq. 1 and its long-term classification.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times (non-dimensional, unit ``sqrt(l/g)``), ``t0`` to ``t0 + periods*T``.
    phi, dphi : ndarray, shape (n,)
        Angle from the hanging position (rad, unwrapped) and its rate (Eq. 1 convention).
    energy : ndarray, shape (n,)
        ``phi'**2/2 + 1 - cos(phi)`` (per unit ``m g l``).
    poincare_t, poincare_phi, poincare_dphi : ndarray, shape (periods + 1,)
        Samples on the section ``t0 + m*T``.
    classification : Classification
        Of the Poincare samples (see :func:`parapend.dynamics.classify`).
    gamma, p, omega, phi0, dphi0, t0 : float
    periods, points_per_period : int
    success : bool
        The integrator succeeded (``status`` ``"ok"``) -- not whether the motion settled.
    status, message : str
    nfev : int
    """

    t: np.ndarray
    phi: np.ndarray
    dphi: np.ndarray
    energy: np.ndarray
    poincare_t: np.ndarray
    poincare_phi: np.ndarray
    poincare_dphi: np.ndarray
    classification: Classification
    gamma: float
    p: float
    omega: float
    phi0: float
    dphi0: float
    t0: float
    periods: int
    points_per_period: int
    success: bool
    status: str
    message: str
    nfev: int

    def to_dict(self) -> dict:
        """Scalars and the classification (not the time series) as JSON-ready values."""
        c = self.classification
        return {"gamma": self.gamma, "p": self.p, "omega": self.omega, "phi0": self.phi0,
                "dphi0": self.dphi0, "t0": self.t0, "periods": self.periods,
                "points_per_period": self.points_per_period,
                "final": {"name": c.name, "kind": c.kind, "period": c.period,
                          "winding": c.winding, "direction": c.direction,
                          "poincare_phi": [float(x) for x in c.phi],
                          "poincare_dphi": [float(x) for x in c.dphi],
                          "residual": None if math.isnan(c.residual) else c.residual},
                "final_phi": float(self.phi[-1]), "final_dphi": float(self.dphi[-1]),
                "turns": int(np.rint((self.phi[-1] - self.phi[0]) / (2 * math.pi))),
                "success": self.success, "status": self.status, "message": self.message,
                "nfev": self.nfev, "convention": CONVENTION}


def simulate(gamma: float = 0.1, p: float = 0.8, omega: float = 2.1, phi0: float = 0.5,
             dphi0: float = 0.0, periods: int = 200, *, points_per_period: int = 64,
             t0: float = 0.0, tol: float = 1e-6, max_period: int = 8,
             rtol: float = 1e-11, atol: float = 1e-11) -> Motion:
    """Simulate paper Eq. 1, ``phi'' + gamma phi' + (1 + p cos(omega t)) sin(phi) = 0``.

    Parameters
    ----------
    gamma, p, omega : float
        Damping (>= 0), excitation strength and frequency (> 0) of Eq. 1. Defaults: the
        paper's coexistence case (Section 1), gamma = 0.1, p = 0.8, omega = 2.1.
    phi0, dphi0 : float
        Initial angle from the hanging position (rad) and rate at ``t0``, each of absolute
        value at most 1000 (``parapend.limits.SIM_MAX_PHI0``, ``SIM_MAX_DPHI0``); the work
        ``periods * 2 pi/omega * (sqrt(1 + |p|) + |dphi0|)`` is at most
        ``limits.SIM_MAX_WORK`` (DOP853 steps follow the fastest rate of the motion).
    periods : int
        Forcing periods simulated, 1 to ``MAX_PERIODS``. About 100 are needed for the
        classification to settle at gamma = 0.1 (contraction ``exp(-gamma T/2)`` per period).
    points_per_period : int
        Output samples per period, 2 to 1024, with ``periods*points_per_period`` at most
        ``MAX_SAMPLES``.
    t0 : float
        Initial time (forcing phase ``omega t0``).
    tol, max_period : float, int
        Of :func:`~parapend.dynamics.classify`.
    rtol, atol : float
        DOP853 tolerances.

    Returns
    -------
    Motion
    """
    gamma, p, omega = _check_params(gamma, p, omega)
    phi0 = check_range("phi0", phi0, 0.0, limits.SIM_MAX_PHI0, absolute=True)
    dphi0 = check_range("dphi0", dphi0, 0.0, limits.SIM_MAX_DPHI0, absolute=True)
    periods = check_int("periods", periods, 1, MAX_PERIODS)
    work = periods * 2 * math.pi / omega * (math.sqrt(1 + abs(p)) + abs(dphi0))
    if work > limits.SIM_MAX_WORK:
        raise ParameterError(f"periods: expected periods x 2 pi/omega x (sqrt(1 + |p|) + "
                             f"|dphi0|) <= {limits.SIM_MAX_WORK:g}, got {work:.4g}")
    ppp = check_int("points_per_period", points_per_period, 2, 1024)
    if periods * ppp > MAX_SAMPLES:
        raise ParameterError(f"points_per_period: periods x points_per_period must be at most "
                             f"{MAX_SAMPLES}, got {periods} x {ppp}")
    t0 = check_finite("t0", t0)
    tol = check_positive("tol", tol)
    period = 2 * math.pi / omega
    t_eval = t0 + period * np.arange(periods * ppp + 1) / ppp
    tr = trajectory(phi0, dphi0, gamma, p, omega, float(t_eval[-1]), t0=t0, t_eval=t_eval,
                    rtol=rtol, atol=atol)
    ok = tr.success and tr.t.size == t_eval.size
    if ok:
        pphi, pdphi, pt = tr.phi[::ppp], tr.dphi[::ppp], tr.t[::ppp]
        c = classify(pphi, pdphi, tol=tol, max_period=max_period)
    else:
        pphi = pdphi = pt = np.empty(0)
        c = classify(np.empty(0), np.empty(0), tol=tol, max_period=max_period)
    return Motion(tr.t, tr.phi, tr.dphi, energy(tr.phi, tr.dphi), pt, pphi, pdphi, c, gamma,
                  p, omega, phi0, dphi0, t0, periods, ppp, ok, "ok" if ok else "failed",
                  "" if ok else f"the integrator stopped: {tr.message}", int(tr.nfev))
