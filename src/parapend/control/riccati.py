"""Time-varying LQR on the periodic orbit: the discrete periodic Riccati equation.

The controller is sampled (``M`` samples per forcing period, torque held over each
interval), so the design is done for exactly what runs: the linearization of Eq. 14 about
the target motion ``theta*(t)``,

    d/dt (dtheta, dtheta') = A(t) (dtheta, dtheta') + B du,
    A(t) = [[0, 1], [(1 + q(t)) cos theta*(t), -gamma]],   B = [0, 1]^T,

is integrated over each sample interval into the periodic sampled system
``x_{k+1} = Phi_k x_k + Gamma_k u_k`` (``Phi_{k+M} = Phi_k``). The stabilizing periodic
solution of the discrete periodic Riccati equation

    P_k = Q h + Phi_k^T P_{k+1} Phi_k - Phi_k^T P_{k+1} Gamma_k S_k^{-1} Gamma_k^T P_{k+1} Phi_k,
    S_k = R h + Gamma_k^T P_{k+1} Gamma_k,      K_k = S_k^{-1} Gamma_k^T P_{k+1} Phi_k,

is found by sweeping it backwards period after period from ``P = 0`` until ``P_0`` repeats:
for a stabilizable and detectable periodic pair (here ``Q > 0``, and ``B`` acts on
``theta''`` at every instant) the backward iteration converges to the unique symmetric
positive semi-definite periodic solution, which is the stabilizing one (Bittanti, Colaneri
and De Nicolao, "The periodic Riccati equation", 1991; Hench and Laub, IEEE TAC 39, 1994).
The convergence is geometric, at the square of the closed-loop multipliers' modulus.

The open-loop monodromy ``prod Phi_k`` gives the orbit's Floquet multipliers with the
feedforward torque alone (their product is ``exp(-gamma 2 pi/omega)``, Liouville); the
closed-loop monodromy ``prod (Phi_k - Gamma_k K_k)`` those with the feedback.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PeriodicLQR", "periodic_lqr", "sampled_linearization"]


def sampled_linearization(target, excitation=None, gamma=None, substeps: int = 16):
    """``Phi_k, Gamma_k`` (shapes (M, 2, 2), (M, 2)) of Eq. 14 linearized about the target.

    Each interval ``[t_k, t_k + h]`` is integrated with ``substeps`` classical RK4 steps
    (all intervals at once); the motion and ``q`` are evaluated at the stage times.
    ``excitation`` and ``gamma`` default to the target's (the design model).
    """
    exc = target.excitation if excitation is None else excitation
    gamma = target.gamma if gamma is None else float(gamma)
    m, h = target.samples, target.step
    dt = h / substeps
    # stage times t_k + j dt/2, j = 0 .. 2 substeps
    tt = target.t[:, None] + 0.5 * dt * np.arange(2 * substeps + 1)[None, :]
    a21 = (1.0 + exc.q(tt.ravel())) * np.cos(target.motion.theta(tt.ravel()))
    a21 = a21.reshape(tt.shape)
    # Y = [Phi | Gamma], shape (M, 2, 3); dY/dt = A Y + [0 | B]
    y = np.zeros((m, 2, 3))
    y[:, 0, 0] = y[:, 1, 1] = 1.0

    def f(y, c):
        d = np.empty_like(y)
        d[:, 0, :] = y[:, 1, :]
        d[:, 1, :] = c[:, None] * y[:, 0, :] - gamma * y[:, 1, :]
        d[:, 1, 2] += 1.0
        return d

    for s in range(substeps):
        c0, c1, c2 = a21[:, 2 * s], a21[:, 2 * s + 1], a21[:, 2 * s + 2]
        k1 = f(y, c0)
        k2 = f(y + 0.5 * dt * k1, c1)
        k3 = f(y + 0.5 * dt * k2, c1)
        k4 = f(y + dt * k3, c2)
        y = y + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return y[:, :, :2], y[:, :, 2]


@dataclass(frozen=True, eq=False)
class PeriodicLQR:
    """Periodic gains and the orbit's Floquet multipliers.

    Attributes
    ----------
    gains : ndarray, shape (M, 2)
        ``K_k``: feedback ``u_k = -K_k (theta - theta*_k, theta' - theta*'_k)``.
    riccati : ndarray, shape (M, 2, 2)
        ``P_k``, the periodic solution.
    open_loop_multipliers, closed_loop_multipliers : ndarray, shape (2,), complex
        Eigenvalues of the monodromy matrices (largest modulus first).
    sweeps : int
        Backward periods swept until ``P_0`` repeated (relative change <= ``tol``).
    residual : float
        Largest relative change of ``P_k`` over one more sweep (the periodicity check).
    """

    gains: np.ndarray
    riccati: np.ndarray
    phi: np.ndarray
    gamma_in: np.ndarray
    open_loop_multipliers: np.ndarray
    closed_loop_multipliers: np.ndarray
    sweeps: int
    residual: float


def _sorted_eig(m):
    ev = np.linalg.eigvals(m)
    return ev[np.argsort(-np.abs(ev), kind="stable")]


def _sweep(phi, gam, p_end, qh, rh):
    m = phi.shape[0]
    p = np.empty((m, 2, 2))
    k = np.empty((m, 2))
    pn = p_end
    for j in range(m - 1, -1, -1):
        f, g = phi[j], gam[j]
        pg = pn @ g
        s = rh + g @ pg
        kk = (pg @ f) / s
        pj = qh + f.T @ pn @ f - np.outer(f.T @ pg, kk)
        pj = 0.5 * (pj + pj.T)
        p[j], k[j] = pj, kk
        pn = pj
    return p, k


def periodic_lqr(target, q_weight=(1.0, 1.0), r_weight: float = 0.1, tol: float = 1e-12,
                 max_sweeps: int = 2000) -> PeriodicLQR:
    """Solve the discrete periodic Riccati equation by backward sweeps (module docstring).

    Parameters
    ----------
    target : Target
    q_weight : (float, float)
        Diagonal of ``Q`` (angle error rad^2, speed error), per unit time.
    r_weight : float
        ``R`` (torque^2 per unit time), > 0.
    """
    phi, gam = sampled_linearization(target)
    h = target.step
    qh = np.diag(np.asarray(q_weight, dtype=float)) * h
    rh = float(r_weight) * h
    p_end = np.zeros((2, 2))
    sweeps = 0
    change = np.inf
    while sweeps < max_sweeps:
        p, k = _sweep(phi, gam, p_end, qh, rh)
        sweeps += 1
        change = np.max(np.abs(p[0] - p_end)) / max(np.max(np.abs(p[0])), 1e-300)
        p_end = p[0]
        if change <= tol and sweeps > 1:
            break
    p2, _ = _sweep(phi, gam, p[0], qh, rh)
    residual = float(np.max(np.abs(p2 - p)) / np.max(np.abs(p)))
    mono_open = np.eye(2)
    mono_closed = np.eye(2)
    for j in range(phi.shape[0]):
        mono_open = phi[j] @ mono_open
        mono_closed = (phi[j] - np.outer(gam[j], k[j])) @ mono_closed
    return PeriodicLQR(gains=k, riccati=p, phi=phi, gamma_in=gam,
                       open_loop_multipliers=_sorted_eig(mono_open),
                       closed_loop_multipliers=_sorted_eig(mono_closed),
                       sweeps=sweeps, residual=residual)
