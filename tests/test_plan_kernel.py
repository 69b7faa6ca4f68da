"""The compiled interior point of the horizon problem (parapend.control._plan_kernel)
against its independent sources: LAPACK's banded Cholesky, the NumPy terms of PlanProblem,
and the Python interior point of parapend.optimal.hermite on the same problem.

Small (K = 16) so that they run in seconds as plain Python (.ci/run runs them under
NUMBA_DISABLE_JIT=1).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg.lapack import dpbtrf, dpbtrs

from parapend.control import _plan_kernel as pk
from parapend.control.plan import PlanProblem, free_motion, gauss_leads, solve_plan
from parapend.optimal.hermite import interior_point

K = 16
GAMMA = 0.05


def _q(t):
    return 0.6 * np.cos(1.1 * t) + 0.2 * np.sin(2.3 * t + 0.4)


def _problem(**kw):
    h = 2 * math.pi / K * 1.5
    lg, lc = gauss_leads(K, h)
    x0 = (0.4, 1.3)
    pr = PlanProblem(x0, h, _q(lg), _q(lc), GAMMA, **kw)
    th, v = free_motion(x0, h, K, GAMMA, _q(0.5 * h * np.arange(2 * K + 1)))
    return pr, pr.start(th, v)


def _band(n, p, rng, shift):
    a = rng.standard_normal((n, n))
    a = a @ a.T
    a[np.abs(np.subtract.outer(np.arange(n), np.arange(n))) > p] = 0.0
    a += shift * np.eye(n)
    ab = np.zeros((p + 1, n))
    for d in range(p + 1):
        ab[d, :n - d] = np.diagonal(a, -d)
    return a, ab


def test_banded_cholesky_matches_lapack():
    rng = np.random.default_rng(3)
    for shift in (5.0, 0.1):
        a, ab = _band(12, 3, rng, shift)
        b = rng.standard_normal(12)
        c = np.empty_like(ab)
        ok = pk.cholesky(ab, 0.25, c)
        ab2 = ab.copy()
        ab2[0] += 0.25
        ref, info = dpbtrf(ab2, lower=1)
        assert ok == (info == 0)
        if ok:
            for d in range(4):  # the band's used part (LAPACK leaves the corner as is)
                np.testing.assert_allclose(c[d, :12 - d], ref[d, :12 - d], rtol=1e-12,
                                           atol=1e-12)
            x = np.empty(12)
            pk.cho_solve(c, b, x)
            np.testing.assert_allclose(x, dpbtrs(ref, b, lower=1)[0], rtol=1e-10)
            np.testing.assert_allclose((a + 0.25 * np.eye(12)) @ x, b, atol=1e-9)


def test_banded_cholesky_refuses_an_indefinite_matrix():
    rng = np.random.default_rng(4)
    a, ab = _band(10, 3, rng, 0.0)
    ab[0, 6] = -1.0  # a negative diagonal entry: not positive definite
    assert dpbtrf(ab.copy(), lower=1)[1] != 0
    assert not pk.cholesky(ab, 0.0, np.empty_like(ab))


@pytest.mark.parametrize("terminal, speed_limit", [("energy", None), ("limited", None),
                                                    ("energy", 2.0)])
def test_extra_terms_match_numpy(terminal, speed_limit):
    pr, x = _problem(torque_limit=1.5, efficiency=(0.9, 0.8), kappa=0.7, terminal=terminal,
                     smoothing=1e-2, speed_limit=speed_limit)
    f = pr.full(x + 0.05 * np.sin(np.arange(x.size)))
    if speed_limit is not None:  # some nodes above the rated speed, some below
        v = np.abs(f[3::2])
        assert np.any(v > speed_limit) and np.any(v < speed_limit)
    args = (pr.k, pr.rows_g[0], pr.rows_g[1], pr.lin_g, np.ascontiguousarray(pr.q1_g), pr.w,
            pr.kappa, pr.eta_g, pr._a, pr.kink, pr.smoothing, *pr._speed_args())
    assert math.isclose(pk.extra(f, *args), pr._extra(f), rel_tol=1e-12, abs_tol=1e-14)
    n = f.size
    ab, rhs = np.zeros((6, n)), np.zeros(n)
    pr._extra_newton(f, ab, rhs)
    ab2, rhs2 = np.zeros((6, n)), np.zeros(n)
    pk.extra_newton(f, ab2, rhs2, *args)
    assert np.max(np.abs(ab)) > 0 and np.max(np.abs(rhs)) > 0
    np.testing.assert_allclose(ab2, ab, rtol=0, atol=1e-12 * np.max(np.abs(ab)))
    np.testing.assert_allclose(rhs2, rhs, rtol=0, atol=1e-12 * np.max(np.abs(rhs)))


@pytest.mark.parametrize("kw", [
    {},
    {"torque_limit": 0.6},
    {"torque_limit": 0.6, "efficiency": (0.9, 0.85), "smoothing": 1e-2},
    {"torque_limit": 0.6, "kappa": 0.8, "terminal": "limited"},
    {"torque_limit": 0.6, "speed_limit": 1.0},
], ids=["free", "limit", "efficiency", "limited-terminal", "rated-speed"])
def test_compiled_solve_matches_the_python_interior_point(kw):
    pr, x = _problem(**kw)
    ref = interior_point(pr, x, gap_tol=1e-10, maxiter=200)
    sol = pr.solve_compiled(x, gap_tol=1e-10, maxiter=200)
    assert ref.status == "converged" and sol.status == "converged"
    assert abs(sol.iterations - ref.iterations) <= 3
    ja, jb = pr.value(sol.x), pr.value(ref.x)
    assert abs(ja - jb) <= 1e-9 * max(1.0, abs(jb))
    np.testing.assert_allclose(sol.x, ref.x, rtol=0, atol=1e-7 * np.max(np.abs(ref.x)))
    if pr.torque_limit is not None:
        assert np.max(np.abs(pr.torque_points(sol.x))) <= pr.torque_limit


def test_solve_plan_reports_an_infeasible_start_of_the_compiled_path():
    pr, x = _problem(torque_limit=0.6)
    bad = x + 5.0  # far outside the limit
    assert np.max(pr.constraints(bad)) >= 0
    assert pr.solve_compiled(bad).status == "infeasible_start"
    # solve_plan repairs such a start (elastic mode from it) and converges
    sol = solve_plan(pr, bad, anchor=x)
    assert sol.success and np.max(np.abs(pr.torque_points(sol.x))) <= 0.6


def test_the_kernel_iterates_with_interior_points_constants():
    """The compiled solve repeats ``parapend.optimal.hermite.interior_point``'s iteration:
    the same fraction to the boundary, barrier update and rounding test (a failed line
    search at the final barrier parameter with a relative Newton decrement below
    ``ROUNDING_DECREMENT`` is converged, not stalled). The kernel holds them as literals
    (numba's cache keys on its own file), so they are compared here."""
    from parapend.control import _plan_kernel as pk
    from parapend.optimal import hermite

    assert pk._FRACTION == hermite._FRACTION
    assert (pk._MU_FACTOR, pk._MU_POWER) == (hermite._MU_FACTOR, hermite._MU_POWER)
    assert pk.ROUNDING_DECREMENT == hermite.ROUNDING_DECREMENT
