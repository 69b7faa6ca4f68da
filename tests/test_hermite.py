"""The time-domain PTO solver: Hermite motion, banded Newton system, interior point."""

from __future__ import annotations

import math

import numpy as np
import pytest

import parapend
from parapend.excitation import harmonic
from parapend.optimal.hermite import (
    HermiteMotion,
    HermiteProblem,
    _fold,
    minimum_peak_torque,
    solve_hermite,
)
from parapend.power import uniform_power
from parapend.trajectory import FourierMotion

EXC = harmonic(-0.3, 1.8)


def _uniform(gamma):
    _, phi = uniform_power(EXC, gamma)
    return FourierMotion(1.8, phi, np.zeros(1), np.zeros(1))


def _dense(ab, perm):
    """The full symmetric matrix (variable order) from the folded lower band."""
    n = ab.shape[1]
    m = np.zeros((n, n))
    for d in range(ab.shape[0]):
        i = np.arange(n - d)
        m[i + d, i] = ab[d, : n - d]
        m[i, i + d] = ab[d, : n - d]
    return m[np.ix_(perm, perm)]


def test_fold_makes_the_cycle_banded():
    for k in (5, 6, 7, 64):
        pos = _fold(k)
        assert sorted(pos) == list(range(k))
        gaps = np.abs(pos - np.roll(pos, -1))  # neighbours on the cycle, incl. (K-1, 0)
        assert gaps.max() <= 2


@pytest.mark.parametrize("kw", [{"torque_limit": 1.6}, {"torque_limit": 1.6, "copper_loss": 0.02},
                                {"phase1": True}, {"torque_limit": 1.2, "elastic": 7.0}])
def test_newton_system_is_the_barrier_hessian(kw):
    """With lambda = mu / s the primal-dual matrix is the barrier function's Hessian and the
    right-hand side minus its gradient: both checked by central differences, which also
    checks the folded banded assembly and the wrap of the last interval."""
    gamma, mu = 0.04, 1e-3
    pr = HermiteProblem(EXC, 7, gamma, **kw)
    rng = np.random.default_rng(3)
    x = pr.start(_uniform(gamma)) + 0.01 * rng.normal(size=14)
    t = 1.7 if kw.get("phase1") else (0.5 if "elastic" in kw else None)

    def barrier(x):
        c = pr.constraints(x, t)
        assert np.max(c) < 0
        return pr.objective(x, mu, t) - mu * np.sum(np.log(-c))

    lam = mu / -pr.constraints(x, t)
    ab, rhs, _, _, _ = pr.newton(x, t, lam, mu)
    grad = -rhs[pr.perm]
    hess = _dense(ab, pr.perm)
    e = 1e-5
    eye = np.eye(x.size)
    gn = np.array([(barrier(x + e * v) - barrier(x - e * v)) / (2 * e) for v in eye])
    assert np.max(np.abs(grad - gn)) <= 1e-6 * np.max(np.abs(gn))  # O(e^2) truncation

    def g(x):
        lam_x = mu / -pr.constraints(x, t)
        return -pr.newton(x, t, lam_x, mu)[1][pr.perm]

    hn = np.array([(g(x + e * v) - g(x - e * v)) / (2 * e) for v in eye])
    assert np.max(np.abs(hess - 0.5 * (hn + hn.T))) <= 1e-6 * np.max(np.abs(hn))
    if t is not None:  # the border variable: its gradient, diagonal and coupling column
        _, _, border, rhs_t, d_tt = pr.newton(x, t, lam, mu)

        def bt(tt):
            c = pr.constraints(x, tt)
            return pr.objective(x, mu, tt) - mu * np.sum(np.log(-c))

        assert -rhs_t == pytest.approx((bt(t + e) - bt(t - e)) / (2 * e), rel=1e-6)

        def gt(tt):  # the barrier gradient in x at fixed lambda = mu / s(x, t)
            lam_t = mu / -pr.constraints(x, tt)
            return -pr.newton(x, tt, lam_t, mu)[1][pr.perm]

        np.testing.assert_allclose(border[pr.perm], (gt(t + e) - gt(t - e)) / (2 * e),
                                   rtol=1e-5, atol=1e-7 * np.max(np.abs(border)))
        def gtt(tt):  # the barrier gradient in t, at lambda = mu / s(x, t)
            lam_t = mu / -pr.constraints(x, tt)
            return -pr.newton(x, tt, lam_t, mu)[3]

        # (a central difference of the exact gradient: a second difference of the barrier
        # itself is at the rounding noise of the objective's sum for e = 1e-5)
        assert d_tt == pytest.approx((gtt(t + e) - gtt(t - e)) / (2 * e), rel=1e-7)


def test_hermite_motion_is_a_c1_rotation():
    rng = np.random.default_rng(0)
    k = 12
    t = 2 * math.pi / 1.8 * np.arange(k) / k
    m = HermiteMotion(1.8, 1.8 * t + 0.2 * rng.normal(size=k), 1.8 + 0.3 * rng.normal(size=k))
    s = np.linspace(-4, 9, 997)
    assert np.allclose(m.theta(s + m.period), m.theta(s) + 2 * math.pi, atol=1e-12)
    e = 1e-6
    assert np.allclose((m.theta(s + e) - m.theta(s - e)) / (2 * e), m.theta_dot(s), atol=1e-6)
    nodes = m.period * np.arange(k) / k
    assert np.allclose(m.theta_dot(nodes - 1e-12), m.theta_dot(nodes), atol=1e-9)  # C^1
    assert np.allclose(m.theta_dot(nodes), m.v_nodes)


def test_peak_torque_from_the_motion_itself():
    """The refined interval maxima against brute force (4000 points per interval)."""
    sol = solve_hermite(EXC, 0.03, 32, parapend.optimize(gamma=0.03).motion, torque_limit=1.0)
    m = HermiteMotion(1.8, sol.x[0::2], sol.x[1::2])
    _, th, thd, thdd = m.profile_on(np.linspace(0, 1, 4001))
    tt = m.period * (np.arange(32)[:, None] + np.linspace(0, 1, 4001)[None, :]) / 32
    brute = np.abs(thdd + 0.03 * thd - (1 + EXC.q(tt)) * np.sin(th)).max()
    assert m.peak_torque(EXC, 0.03) == pytest.approx(brute, rel=1e-9)
    assert m.peak_torque(EXC, 0.03) <= 1.0 * (1 + 1e-9)


@pytest.mark.parametrize("gamma,tmax", [(0.03, 1.0), (0.05, 2.0)])
def test_converges_under_refinement(gamma, tmax):
    """Second order in the intervals: successive changes fall by about 4 per doubling, and
    the limit holds on every motion's dense evaluation."""
    ideal = parapend.optimize(gamma=gamma)
    p = []
    for k in (64, 128, 256):
        s = solve_hermite(EXC, gamma, k, ideal.motion, torque_limit=tmax)
        assert s.status == "converged"
        assert s.peak_torque <= tmax * (1 + 1e-9)
        p.append(s.power)
    ratio = (p[1] - p[0]) / (p[2] - p[1])
    assert 2.5 < ratio < 7
    assert p[0] < p[1] < p[2] < ideal.power


def test_phase1_finds_a_rotation_below_the_uniform_peak():
    """Minimizing the peak torque from the uniform rotation lowers it (a free rotating
    attractor exists here, so the minimum is small) and the motion is a genuine rotation."""
    uni = _uniform(0.03)
    pr = HermiteProblem(EXC, 64, 0.03)
    start_peak = float(np.max(np.abs(pr.torque_points(pr.start(uni)))))
    sol, pr = minimum_peak_torque(EXC, 0.03, 64, uni, stop_below=0.5)
    assert start_peak > 1.2
    assert sol.status == "feasible"
    assert sol.t < 0.5
    assert sol.peak_torque < 0.5 * (1 + 1e-2)
    m = pr.motion(sol.x)
    assert m.theta(m.period) - m.theta(0.0) == pytest.approx(2 * math.pi)


def test_infeasible_limit_is_a_status():
    """gamma = 0.3: no free rotation; a limit far below the smallest peak is reported."""
    ideal = parapend.optimize(gamma=0.3)
    s = solve_hermite(EXC, 0.3, 64, ideal.motion, torque_limit=1e-3)
    assert s.status == "infeasible"
    assert s.t > 1e-3


def test_small_limit_reaches_the_constant_brake():
    """Below a free rotation's reach (gamma = 0.01, T_max = 0.1) the best motion brakes with
    -T_max all the way round: P <= T_max <|theta'|> = T_max omega for a monotone rotation,
    and the solver comes within 1e-3 of that bound from a start far away (the ideal optimum,
    peak torque 8.3), through elastic mode."""
    ideal = parapend.optimize(gamma=0.01)
    s = solve_hermite(EXC, 0.01, 256, ideal.motion, torque_limit=0.1)
    assert s.status == "converged"
    assert "elastic" in [st[0] for st in s.stages]
    assert s.peak_torque <= 0.1 * (1 + 1e-9)
    _, _, thd, _ = s.motion.profile_on(np.linspace(0, 1, 9))
    assert np.all(thd > 0)  # monotone: the bound applies
    assert 0.18 * (1 - 1e-3) < s.power <= 0.18
