"""Hermite-Simpson collocation of the PTO problem (parapend.optimal.collocation), checked
against IPOPT on the same discrete problem (tests/casadi_pto.py), against finite
differences, dense eigenvalues and the collocation equations themselves."""

from __future__ import annotations

import math

import numpy as np
import pytest

import parapend
from parapend import pto
from parapend.model import torque
from parapend.optimal import collocation as C
from parapend.optimal.profile import pto_profile

EXC = parapend.harmonic(-0.3, 1.8)


@pytest.fixture(scope="module")
def ideal():
    return {g: parapend.optimize(gamma=g, harmonics=24) for g in (0.03, 0.05)}


def _dense(ab, n):
    kl = C._KL
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + kl + 1)):
            a[i, j] = ab[2 * kl + i - j, j]
    return a


def test_kkt_matrix_is_the_derivative_of_its_right_hand_side():
    """Without slacks the right-hand side is minus the gradient of the Lagrangian and the
    defects: the matrix must be its Jacobian (central differences), symmetric, banded."""
    rng = np.random.default_rng(0)
    k, h, gamma, wrap = 7, 0.3, 0.05, 2 * math.pi
    th, v, u = rng.normal(size=k), rng.normal(size=k), rng.normal(size=k)
    y = rng.normal(size=2 * k)
    q1n, q1m = 1 + 0.3 * rng.normal(size=k), 1 + 0.3 * rng.normal(size=k)
    pos = C._fold(k).astype(np.int64)
    n = 5 * k

    def kkt(th, v, u, y):
        ab = np.zeros((3 * C._KL + 1, n))
        rhs = np.zeros(n)
        z = np.ones(2 * k)
        C._kkt(th, v, u, z, z, z, z, z, y, np.ones(k), np.ones(k), q1n, q1m, h, gamma, wrap,
               pos, 0.0, 0.9, 0.9, 0.3, -1.0, False, ab, rhs, np.zeros(2 * k),
               np.zeros((2 * k, 6)))
        return _dense(ab, n), rhs

    a, _ = kkt(th, v, u, y)
    assert np.array_equal(a, a.T)
    e = 1e-6
    err = 0.0
    for j in range(k):
        for c in range(3):
            d = [np.zeros(k) for _ in range(3)]
            d[c][j] = e
            rp = kkt(th + d[0], v + d[1], u + d[2], y)[1]
            rm = kkt(th - d[0], v - d[1], u - d[2], y)[1]
            err = max(err, np.max(np.abs(-(rp - rm) / (2 * e) - a[:, 5 * pos[j] + c])))
    for i in range(2 * k):
        d = np.zeros(2 * k)
        d[i] = e
        col = -(kkt(th, v, u, y + d)[1] - kkt(th, v, u, y - d)[1]) / (2 * e)
        err = max(err, np.max(np.abs(col - a[:, 5 * pos[i // 2] + 3 + i % 2])))
    assert err < 1e-7


def test_inertia_counts_negative_eigenvalues():
    rng = np.random.default_rng(3)
    n, kl = 60, C._KL
    a = np.zeros((n, n))
    for d in range(kl + 1):
        vals = rng.normal(size=n - d)
        a += np.diag(vals, -d) + (np.diag(vals, d) if d else 0)
    band = np.array([np.concatenate([np.diag(a, -d), np.zeros(d)]) for d in range(kl + 1)])
    neg, tiny = C._inertia(band, kl)
    assert not tiny
    assert neg == int(np.sum(np.linalg.eigvalsh(a) < 0))


def _casadi(gamma, k, kw):
    pytest.importorskip("casadi")
    from casadi_pto import collocate

    c = collocate(EXC, gamma, intervals=k, **kw)
    assert c["status"] == "Solve_Succeeded"
    return c


def _compare(ideal, gamma, k, kw):
    s = C.solve_collocation(EXC, gamma, k, ideal[gamma].motion, **kw)
    c = _casadi(gamma, k, kw)
    assert s.status == "converged"
    # one discrete problem, two solvers: IPOPT's tol 1e-10 leaves ~1e-9 of barrier
    assert s.electrical_power == pytest.approx(c["electrical_power"], abs=1e-8)
    assert s.power == pytest.approx(c["power"], abs=1e-6)
    return s, c


def test_same_discrete_problem_as_ipopt(ideal):
    """The cheap default case: both efficiencies apart, a torque limit and a copper loss."""
    _compare(ideal, 0.05, 30, {"efficiency": (0.9, 0.7), "torque_limit": 2.0,
                               "copper_loss": 0.01})


SLOW = [(g, {"efficiency": eff, "torque_limit": lim})
        for g in (0.03, 0.05) for eff in ((0.9, 0.9), (0.7, 0.7), (0.9, 0.7), (0.7, 0.9))
        for lim in (None, 2.0)] + [
    (g, kw) for g in (0.03, 0.05) for kw in (
        {"copper_loss": 0.01}, {"copper_loss": 0.01, "efficiency": (0.8, 0.8)},
        {"copper_loss": 0.02, "torque_limit": 1.2})]


@pytest.mark.slow
@pytest.mark.parametrize("gamma,kw", SLOW)
def test_same_discrete_problem_as_ipopt_all(ideal, gamma, kw):
    _compare(ideal, gamma, 50, kw)


def test_motion_satisfies_the_collocation(ideal):
    """The returned motion, evaluated through its own theta / theta_dot / theta_ddot, meets
    the Hermite-Simpson equations; its inverse-dynamics torque is the piecewise-linear u;
    the Simpson mean of -u v is the reported power."""
    k, gamma = 40, 0.05
    s = C.solve_collocation(EXC, gamma, k, ideal[gamma].motion, efficiency=(0.7, 0.7),
                            torque_limit=2.5)
    m = s.motion
    h = EXC.period / k
    t = h * np.arange(2 * k + 1) / 2
    th, v, f = m.theta(t), m.theta_dot(t), m.theta_ddot(t)
    a, mid, b = slice(0, -1, 2), slice(1, None, 2), slice(2, None, 2)
    assert np.max(np.abs(th[b] - th[a] - h / 6 * (v[a] + 4 * v[mid] + v[b]))) < 1e-9
    assert np.max(np.abs(v[b] - v[a] - h / 6 * (f[a] + 4 * f[mid] + f[b]))) < 1e-9
    assert th[-1] - th[0] == pytest.approx(2 * math.pi, abs=1e-9)
    u = torque(m, EXC, gamma, t)
    assert np.max(np.abs(u[mid] - 0.5 * (u[a] + u[b]))) < 1e-12
    assert np.max(np.abs(u[::2][:-1] - m.u_nodes)) < 1e-9
    w = np.ones(2 * k + 1)
    w[1::2] = 4
    w[2:-1:2] = 2
    assert float(w @ (-u * v)) * h / 6 / EXC.period == pytest.approx(s.power, abs=1e-10)
    assert s.peak_torque <= 2.5 * (1 + 1e-12)
    # the peak of a piecewise-linear torque is at a node: a dense sample finds no more
    dense = np.linspace(0, EXC.period, 20001)
    assert np.max(np.abs(torque(m, EXC, gamma, dense))) <= s.peak_torque * (1 + 1e-12)


def test_solver_trouble_is_a_status(ideal):
    s = C.solve_collocation(EXC, 0.05, 30, ideal[0.05].motion, efficiency=(0.7, 0.7),
                            maxiter=3)
    assert s.status == "max_iterations"
    assert math.isfinite(s.electrical_power)


def test_optimize_pto_routes_and_reports_the_collocation():
    r = pto.optimize_pto(gamma=0.05, efficiency=0.7, torque_limit=3.0)
    assert (r.method, r.status) == ("collocation", "converged")
    assert r.refinement_change <= 1e-6
    m = r.motion
    assert isinstance(m, C.CollocationMotion) and m.intervals == r.intervals
    assert r.peak_torque == pytest.approx(float(np.max(np.abs(m.u_nodes))), rel=1e-15)
    prof = pto_profile(m, r._excitation, r.gamma, efficiency=(0.7, 0.7))
    assert prof["peak_torque"] == r.peak_torque
    # the dense profile of the motion integrates to the Simpson power of the nodes
    assert np.mean(prof["power"]) == pytest.approx(r.power, abs=1e-5)
    assert np.mean(prof["electrical_power"]) == pytest.approx(r.electrical_power, abs=1e-5)
    assert r.motoring_energy == prof["motoring_energy"]
    # with efficiency 0.7 the optimum (almost) never motors
    assert r.motoring_energy < 1e-3


def test_limit_below_the_smallest_peak_is_infeasible_not_an_exception():
    """At gamma = 0.3 no rotation has a peak torque below 0.4165 (phase 1 of the Hermite
    method, docs/units.md): with an efficiency and T_max = 0.3 the status says so."""
    r = pto.optimize_pto(gamma=0.3, efficiency=0.7, torque_limit=0.3)
    assert (r.method, r.status, r.success) == ("collocation", "infeasible", False)
    assert "raise the torque limit" in r.message
    with pytest.raises(parapend.errors.SolverError, match="infeasible"):
        pto.optimize_pto(gamma=0.3, efficiency=0.7, torque_limit=0.3, throw=True)
    ok = pto.optimize_pto(gamma=0.3, efficiency=0.7, torque_limit=0.5)
    assert ok.status == "no_power" and ok.success  # feasible, and every rotation costs
    assert ok.peak_torque <= 0.5 * (1 + 1e-12)
