"""The buoy's motion-as-unknown horizon planner (hydro/_buoy_plan.py, ``controller="plan"`` of
hydro/control.py): its derivatives against central differences, its heave and torque against
an independent integrator of the buoy's equation, its horizon optimum against the
L-BFGS-B problem of the ``coupled`` controller, and causality in the closed loop (synthetic,
exactly causal dataset of tests/buoy_synthetic.py, no BEM)."""

import math

import numpy as np
import pytest
from buoy_synthetic import synthetic
from scipy.integrate import solve_ivp

from parapend.control.plan import HorizonPlan
from parapend.errors import ParameterError
from parapend.hydro import control as bc
from parapend.hydro._buoy_plan import CoupledPlan
from parapend.hydro.coupled import Pendulum, Wave

# (M + A_inf, C, m l, I, c, g): a heavy pendulum (80 kg, 0.3 m) in a 0.5 m cylinder
P = np.array([500.0, 7900.0, 24.0, 7.2, 1.0, 9.81])
K, H = 16, 5.0 / 16
Y0 = np.array([0.1, -0.2, 2.0, 3.0])


def _force(t):
    t = np.asarray(t, dtype=float)
    return 3000.0 * np.sin(2.5 * t + 0.3) + 1000.0 * np.cos(4.0 * t)


def _problem(leads=None, limit=400.0, k=K, h=H):
    pr = CoupledPlan(k, h, P, limit, sample_leads=leads)
    pr.set_start(Y0, _force)
    tn = h * np.arange(1, k + 1)
    x = np.empty(2 * k)
    x[0::2] = 2.0 + 2.5 * tn + 0.3 * np.sin(tn)
    x[1::2] = 2.5 + 0.3 * np.cos(tn)
    return pr, x


def _energy(y):
    """``_Plant.energy``: buoy and pendulum (J)."""
    z, zd, th, om = y
    mt, cst, ml, inertia, _, g = P
    return (0.5 * mt * zd * zd - ml * math.sin(th) * zd * om + 0.5 * inertia * om * om
            + 0.5 * cst * z * z + ml * g * math.cos(th))


@pytest.mark.slow  # its first run compiles the planner's evaluation (6 s)
def test_derivatives_against_central_differences():
    pr, x = _problem()
    nu = np.random.default_rng(0).normal(size=3 * K)
    phi, g, hess, tau, jac = pr.derivatives(x, nu)
    assert phi == pytest.approx(pr.objective(x), rel=1e-14)
    assert np.array_equal(tau, pr.constraint_torques(x).ravel())
    eye = np.eye(2 * K)
    e = 1e-6
    gfd = np.array([(pr.objective(x + e * d) - pr.objective(x - e * d)) / (2 * e)
                    for d in eye])
    jfd = np.array([(pr.constraint_torques(x + e * d).ravel()
                     - pr.constraint_torques(x - e * d).ravel()) / (2 * e) for d in eye]).T
    # central differences of O(1e3) values at 1e-6: truncation ~1e-9, round-off ~1e-10
    assert np.max(np.abs(g - gfd)) < 1e-7 * np.max(np.abs(g))
    assert np.max(np.abs(jac - jfd)) < 1e-7 * np.max(np.abs(jac))

    def lagrangian_gradient(v):
        _, gv, _, _, jv = pr.derivatives(v)
        return gv + jv.T @ nu
    e = 1e-5
    hfd = np.array([(lagrangian_gradient(x + e * d) - lagrangian_gradient(x - e * d)) / (2 * e)
                    for d in eye])
    assert np.max(np.abs(hess - hfd)) < 1e-7 * np.max(np.abs(hess))
    # the compiled kernel that the solver uses: the same to round-off
    for a, b in zip(pr.derivatives(x, nu), pr.compiled(x, nu)):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(a)))
    v0, v1 = pr.values(x), pr.compiled(x, order=0)
    assert v1[0] == pytest.approx(v0[0], rel=1e-12)
    assert np.allclose(v1[1], v0[1], rtol=1e-12, atol=1e-9)
    # the objective's Hessian alone is banded (one interval's nodes per term)
    h0 = pr.derivatives(x)[2]
    band = np.abs(np.subtract.outer(np.arange(2 * K), np.arange(2 * K))) > 3
    assert not np.any(h0[band])


@pytest.mark.slow  # its first run compiles the planner's interior point (35 to 60 s)
def test_compiled_solver_follows_the_reference_loop():
    # the interior point compiled (solve) and in Python (solve_python): the same iterates
    # to round-off (the same formulas; BLAS and loop sums differ in order)
    pr, x = _problem(limit=300.0)
    xa, sa, ia = pr.solve_python(x)
    xb, sb, ib = pr.solve(x)
    assert sa == sb == "converged" and ia == ib
    assert np.max(np.abs(xa - xb)) < 1e-7 * np.max(np.abs(xa))
    assert np.max(np.abs(pr.constraint_torques(xb))) <= 300.0 * (1 + 1e-6)


def test_a_nan_in_the_hessian_ends_the_solve_not_finite():
    # the inertia correction shifts the Newton matrix until Cholesky succeeds: a NaN in the
    # Hessian (finite objective and gradient) made no shift succeed, and the loop never ended
    # (a controller's run hung in a compiled solve): now the solve stops, not finite, at the
    # point it had. The Python reference loop here; the compiled one has the same bound.
    pr, x = _problem(limit=300.0)
    real = pr.compiled

    def nan_hessian(x, nu=None, order=2):
        out = real(x, nu, order)
        if order != 2:
            return out
        phi, gr, h, tau, jac = out
        h = h.copy()
        h[0, 0] = np.nan
        return phi, gr, h, tau, jac

    pr.compiled = nan_hessian
    xs, status, it = pr.solve_python(x)
    assert (status, it) == ("nonfinite", 1) and np.array_equal(xs, x)


def _reference_heave(plan, t_eval):
    """``M z'' + C z = f - m l (cos theta)''`` by an adaptive integrator on the plan's angle
    (each interval's cubic written out), interval by interval (``theta''`` jumps at the
    nodes); ``z`` and ``z''`` at ``t_eval``."""
    t_eval = np.asarray(t_eval, dtype=float)
    z, zdd = np.empty(t_eval.size), np.empty(t_eval.size)
    y = Y0[:2].copy()
    h = plan.h
    for j in range(plan.intervals):
        a = j * h
        ta, va, tb, vb = plan.theta[j], plan.v[j], plan.theta[j + 1], plan.v[j + 1]
        c2 = (3.0 * (tb - ta) / h - 2.0 * va - vb) / h
        c3 = (2.0 * (ta - tb) / h + va + vb) / h ** 2

        def rhs(t, y, a=a, ta=ta, va=va, c2=c2, c3=c3):
            s = t - a
            th = ta + s * (va + s * (c2 + s * c3))
            thd = va + s * (2.0 * c2 + 3.0 * c3 * s)
            thdd = 2.0 * c2 + 6.0 * c3 * s
            cdd = -math.cos(th) * thd ** 2 - math.sin(th) * thdd
            f = 3000.0 * math.sin(2.5 * t + 0.3) + 1000.0 * math.cos(4.0 * t)
            return [y[1], (f - P[1] * y[0] - P[2] * cdd) / P[0]]
        sol = solve_ivp(rhs, (a, a + h), y, method="DOP853", rtol=1e-12, atol=1e-12,
                        dense_output=True)
        last = j == plan.intervals - 1
        for i in np.flatnonzero((t_eval >= a) & ((t_eval < a + h) | last)):
            yi = sol.sol(t_eval[i])
            z[i], zdd[i] = yi[0], rhs(t_eval[i], yi)[1]
        y = sol.y[:, -1]
    return z, zdd


def test_heave_and_torque_against_an_independent_integrator():
    leads = np.linspace(0.0, 1.3, 9)
    pr, x = _problem(leads)
    f = pr.full(x)
    plan = HorizonPlan(H, f[0::2], f[1::2], 0.0)
    ts = np.linspace(0.0, K * H, 41)
    z, _ = _reference_heave(plan, ts)
    # the convolution by 4-point Gauss rules: error ~ (h w)^8, far below 1e-6 m
    assert np.max(np.abs(pr.heave(x, ts) - z)) < 1e-6
    _, zdd = _reference_heave(plan, leads)
    th, thd, thdd = plan.evaluate(leads)
    tau = P[3] * thdd + P[4] * thd - P[2] * np.sin(th) * (P[5] + zdd)
    assert np.max(np.abs(pr.torques(x) - tau)) < 1e-6 * np.max(np.abs(tau))


def test_horizon_optimum_is_not_beaten_by_the_coupled_controllers_problem():
    # one horizon of 1 s (8 intervals, 4 held torques each, as buoy_mpc), no memory (f = F),
    # solved by the motion planner; its held torques are a start of the L-BFGS-B problem of
    # controller="coupled" (8 RK4 steps per torque), which must not find much better
    from parapend.control.mpc import _gauss3
    from parapend.hydro._control_kernel import plan_objective

    k, h = 8, 0.125
    n, steps = 4 * k, 8
    dt = k * h / n
    tu = 80 * 9.81 * 0.3
    limit = 1.5 * tu
    off, w3 = _gauss3(dt)
    leads = ((dt * np.arange(n))[:, None] + off[None, :]).ravel()
    pr, x = _problem(leads, limit, k, h)
    xs, status, _ = pr.solve(x)
    assert status == "converged"
    assert np.max(np.abs(pr.constraint_torques(xs))) <= limit * (1 + 1e-6)
    j_plan = _energy(Y0) - pr.objective(xs)  # W + E(end) of the planned motion
    u = np.clip(pr.torques(xs).reshape(n, 3) @ w3, -limit, limit) / tu
    hs = dt / steps
    fnet = _force(0.5 * hs * np.arange(2 * n * steps + 1))
    grad, ys = np.empty(n), np.empty((n * steps + 1, 4))

    def j_old(v):
        return -tu * plan_objective(v, Y0, fnet, hs, steps, P, tu, 1.0, 1.0, 1.0,
                                    np.zeros(2), 1.0, grad, ys)
    # the plan's held torques on the RK4 model: J to the held torque's discretization
    # (its sample means of a torque that varies on the scale of h; measured 1.3e-4)
    assert j_old(u) == pytest.approx(j_plan, rel=1e-3)
    res = bc.CoupledHorizon(n, hs, steps, P, tu, torque_limit=limit / tu).solve(
        Y0, fnet, u, max_iter=500)
    # a local optimum of the same problem: L-BFGS-B gains no more than that (measured 7e-4)
    assert j_old(res.x) <= j_plan * (1 + 2e-3)


SYN = synthetic()
TR, TP = 5.0, 2.5  # a record of 5 s: components of 2.5 s and 1.67 s
AMPS = np.zeros(6, complex)
AMPS[1], AMPS[2] = 0.25, 0.12j
WAVE = Wave(2 * math.pi / TR, AMPS)
OPTS = {"peak_period": TP, "horizon": 0.5, "update_interval": 0.125, "warmup": 1.0,
        "samples": 32, "memory": 8.0, "controller": "plan", "iterations": 1}


def _run(monkeypatch, cut=None):
    """A short closed loop with the excitation altered from node ``cut`` on (None: not)."""
    real = bc.force_nodes

    def altered(*a):
        fn = real(*a).copy()
        if cut is not None:
            fn[cut:] += 500.0 * np.sin(0.7 * np.arange(fn.size - cut))
        return fn
    monkeypatch.setattr(bc, "force_nodes", altered)
    return bc.buoy_mpc(SYN, Pendulum(20.0, 0.3, 1.8, 0.25), WAVE, **OPTS)


def test_closed_loop_is_causal(monkeypatch):
    base = _run(monkeypatch)
    assert base.success and base.catch_time_s is not None
    dt = base.dt_s
    ps = bc.PLANT_STEPS
    n = int(round(base.horizon_s / dt))
    m = int(round(base.update_interval_s / dt))
    j0 = int(round(base.catch_time_s / dt)) + 3 * m  # an update's sample
    # the torques before j0 were planned at j0 - m at the latest, on the excitation up to
    # t0 + H, t0 = (j0 - m) dt: its plant half-step nodes up to 2 (j0 - m + n) ps
    last = 2 * (j0 - m + n) * ps
    after = _run(monkeypatch, cut=last + 1)
    assert np.array_equal(after.series["torque"][:j0], base.series["torque"][:j0])
    # the test has the power to see a look past t0 + H: the same alteration one sample
    # earlier, inside that horizon, changes them
    inside = _run(monkeypatch, cut=last + 1 - 2 * ps)
    assert not np.array_equal(inside.series["torque"][:j0], base.series["torque"][:j0])
    assert np.array_equal(inside.series["torque"][:j0 - m], base.series["torque"][:j0 - m])


def test_marginal_radiation_is_the_derivative_of_the_radiated_energy():
    # R(v) = h sum_i v_i mu_i over the horizon's steps, mu_i = sum_q w_q V_{i-q} with the
    # past speeds before; R is quadratic, so central differences are exact to round-off:
    # dR/dv_i = h (mu_i + a_i), a = marginal_radiation(w, v); w longer than the horizon
    rng = np.random.default_rng(3)
    h, nk, n = 0.01, 50, 30
    w = rng.normal(size=nk + 1) * np.exp(-0.05 * np.arange(nk + 1)) * 100.0
    past = rng.normal(size=nk)

    def mu(v):
        vv = np.concatenate((past, v))
        return np.array([w @ vv[nk + i - np.arange(nk + 1)] for i in range(n)])

    def radiated(v):
        return h * float(v @ mu(v))
    v = rng.normal(size=n)
    e = 1e-3
    fd = np.array([(radiated(v + e * d) - radiated(v - e * d)) / (2 * e) for d in np.eye(n)])
    got = h * (mu(v) + bc.marginal_radiation(w, v))
    assert np.max(np.abs(got - fd)) < 1e-9 * np.max(np.abs(fd))


def test_objective_force_changes_the_objective_alone():
    # fobj = f - g0 (a constant): the dynamics (torques) unchanged, the minimized objective
    # -int (fobj z' - c theta'^2) up by g0 int z' dt = g0 (z(H) - z(0))
    leads = np.linspace(0.0, 1.3, 9)
    pr, x = _problem(leads)
    phi, tq, ts = pr.objective(x), pr.constraint_torques(x), pr.torques(x)
    g0 = 250.0
    pr.set_start(Y0, _force, lambda t: _force(t) - g0)
    assert np.array_equal(pr.constraint_torques(x), tq)
    assert np.array_equal(pr.torques(x), ts)
    dz = pr.heave(x, [K * H])[0] - Y0[0]
    # the Gauss rules integrate the smooth z' to far below 1e-9 of the objective's size
    assert pr.objective(x) - phi == pytest.approx(g0 * dz, abs=1e-9 * abs(phi))


def test_plan_controller_refuses_what_it_does_not_model():
    with pytest.raises(ParameterError, match="controller"):
        bc.buoy_mpc(SYN, Pendulum(20.0, 0.3, 1.8, 0.25), WAVE, **{**OPTS, "efficiency": 0.9})


@pytest.mark.slow
def test_default_design_plan_controller_harvests():
    # docs/buoy.md's measurement, seed 0, 2 peak periods (the acceptance): 91.6 % of
    # the record's coupled optimum (winding 10) with the radiation inside the horizon model
    # (61 % with the memory force frozen in it); the energy balance closes
    import parapend

    opt = parapend.buoy(hs=0.5, tp=2.5, repeat_period=25, seed=0, winding=10)
    pend = Pendulum(mass=80.0, length=0.3, inertia=7.2, damping_coefficient=1.0)
    r = bc.buoy_mpc(opt._hydro, pend, opt._wave, peak_period=2.5, horizon=2.0)
    assert r.success and r.planner == "plan"
    assert 0.88 < r.mean_power_w / opt.power_w < 1.0
    assert r.energy_balance_residual < 1e-6
    assert r.peak_torque_nm <= r.torque_limit_nm * (1 + 1e-12)


# -- the radiation inside the horizon model (Cummins' memory through the impulse response) --
def _radiation_response(h=0.005, memory=12.0, length=K * H + 0.01):
    """The synthetic dataset's exact kernel ``K(t)`` (tests/buoy_synthetic.py) on the plant's
    weights (trapezoid, halved ends) and the horizon model's impulse response from them."""
    from buoy_synthetic import kernel

    from parapend.hydro._buoy_plan import Response

    nk = int(round(memory / h))
    w = kernel(h * np.arange(nk + 1)) * h
    w[0] *= 0.5
    w[-1] *= 0.5
    return Response(P[0], P[1], w, h, length)


def _cummins(plan, t_eval, ml):
    """``M z'' + mu + C z = F - m l (cos theta)''`` with the synthetic memory as its exact
    state-space form (``mu = k xi'``, ``xi'' + 2 zeta w0 xi' + w0^2 xi = z'``, the speed at
    rest before the start) by an adaptive integrator on the plan's angle, interval by
    interval; ``z, z', z''`` at ``t_eval``."""
    from buoy_synthetic import W0, ZETA
    from buoy_synthetic import K as KR

    t_eval = np.asarray(t_eval, dtype=float)
    out = np.empty((3, t_eval.size))
    y = np.array([Y0[0], Y0[1], 0.0, 0.0])
    h = plan.h
    for j in range(plan.intervals):
        a = j * h
        ta, va, tb, vb = plan.theta[j], plan.v[j], plan.theta[j + 1], plan.v[j + 1]
        c2 = (3.0 * (tb - ta) / h - 2.0 * va - vb) / h
        c3 = (2.0 * (ta - tb) / h + va + vb) / h ** 2

        def rhs(t, y, a=a, ta=ta, va=va, c2=c2, c3=c3):
            s = t - a
            th = ta + s * (va + s * (c2 + s * c3))
            thd = va + s * (2.0 * c2 + 3.0 * c3 * s)
            thdd = 2.0 * c2 + 6.0 * c3 * s
            cdd = -math.cos(th) * thd ** 2 - math.sin(th) * thdd
            mu = KR * y[3]
            zdd = (float(_force(t)) - mu - P[1] * y[0] - ml * cdd) / P[0]
            return [y[1], zdd, y[3], y[1] - 2 * ZETA * W0 * y[3] - W0 * W0 * y[2]]
        sol = solve_ivp(rhs, (a, a + h), y, method="DOP853", rtol=1e-12, atol=1e-13,
                        dense_output=True)
        last = j == plan.intervals - 1
        for i in np.flatnonzero((t_eval >= a) & ((t_eval < a + h) | last)):
            yi = sol.sol(t_eval[i])
            out[:, i] = yi[0], yi[1], rhs(t_eval[i], yi)[1]
        y = sol.y[:, -1]
    return out


def _radiation_problem(leads=None, limit=400.0):
    pr, x = _problem(leads, limit)
    f = pr.full(x)
    plan = HorizonPlan(H, f[0::2], f[1::2], 0.0)
    # the buoy without the pendulum from the start under F (what buoy_mpc takes from the
    # plant's model), by the same integrator
    tf = np.linspace(0.0, K * H, 2001)
    zf = _cummins(plan, tf, 0.0)

    def free(s):
        return tuple(np.interp(s, tf, v) for v in zf)
    rp = CoupledPlan(K, H, P, limit, sample_leads=leads, response=_radiation_response())
    rp.set_start(Y0, _force, free=free)
    return rp, x, plan


def test_radiation_response_is_the_cummins_impulse_response():
    # g against the state-space form's own impulse response (z(0) = 0, z'(0) = 1 / M)
    from buoy_synthetic import W0, ZETA
    from buoy_synthetic import K as KR

    resp = _radiation_response()

    def rhs(t, y):
        return [y[1], (-KR * y[3] - P[1] * y[0]) / P[0], y[3],
                y[1] - 2 * ZETA * W0 * y[3] - W0 * W0 * y[2]]
    ts = np.linspace(0.0, 5.0, 101)
    sol = solve_ivp(rhs, (0, 5.0), [0.0, 1.0 / P[0], 0.0, 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-15, t_eval=ts)
    acc = np.array([rhs(t, y)[1] for t, y in zip(ts, sol.y.T)])
    # the plant's scheme on its step 0.005 s (RK4, trapezoidal memory): O(h^2), measured 3e-5
    for order, ref in ((0, sol.y[0]), (1, sol.y[1]), (2, acc)):
        assert np.max(np.abs(resp(ts, order) - ref)) < 1e-4 * np.max(np.abs(ref))
    assert resp.point() == pytest.approx((KR + P[1]) / P[0] ** 2, rel=1e-12)


def test_radiation_heave_and_torque_against_cummins():
    # the plan's heave (and torque) with the radiation inside the model against Cummins'
    # equation integrated on the same angle: the memory's convolution by the impulse
    # response, exact to the plant's discretization of g (measured 1.5e-6 of the heave)
    leads = np.linspace(0.0, 1.3, 9)
    rp, x, plan = _radiation_problem(leads)
    ts = np.linspace(0.0, K * H, 41)
    z = _cummins(plan, ts, P[2])[0]
    assert np.max(np.abs(rp.heave(x, ts) - z)) < 1e-5 * np.max(np.abs(z))
    zdd = _cummins(plan, leads, P[2])[2]
    th, thd, thdd = plan.evaluate(leads)
    tau = P[3] * thdd + P[4] * thd - P[2] * np.sin(th) * (P[5] + zdd)
    assert np.max(np.abs(rp.torques(x) - tau)) < 1e-5 * np.max(np.abs(tau))
    # the frozen model (no memory in the dynamics) is far off: the test can see it
    pr, _ = _problem(leads)
    assert np.max(np.abs(pr.heave(x, ts) - z)) > 1e-2 * np.max(np.abs(z))


@pytest.mark.slow  # compiles the planner's evaluation on first use (6 s)
def test_radiation_derivatives_against_central_differences():
    rp, x, _ = _radiation_problem()
    nu = np.random.default_rng(1).normal(size=3 * K)
    phi, g, hess, tau, jac = rp.derivatives(x, nu)
    assert phi == pytest.approx(rp.objective(x), rel=1e-14)
    eye = np.eye(2 * K)
    e = 1e-6
    gfd = np.array([(rp.objective(x + e * d) - rp.objective(x - e * d)) / (2 * e)
                    for d in eye])
    jfd = np.array([(rp.constraint_torques(x + e * d).ravel()
                     - rp.constraint_torques(x - e * d).ravel()) / (2 * e) for d in eye]).T
    assert np.max(np.abs(g - gfd)) < 1e-7 * np.max(np.abs(g))
    assert np.max(np.abs(jac - jfd)) < 1e-7 * np.max(np.abs(jac))

    def lagrangian_gradient(v):
        _, gv, _, _, jv = rp.derivatives(v)
        return gv + jv.T @ nu
    e = 1e-5
    hfd = np.array([(lagrangian_gradient(x + e * d) - lagrangian_gradient(x - e * d)) / (2 * e)
                    for d in eye])
    assert np.max(np.abs(hess - hfd)) < 1e-7 * np.max(np.abs(hess))
    for a, b in zip(rp.derivatives(x, nu), rp.compiled(x, nu)):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(a)))
    v0, v1 = rp.values(x), rp.compiled(x, order=0)
    assert v1[0] == pytest.approx(v0[0], rel=1e-12)


def test_radiated_energy_term_is_the_double_integral():
    # 1/2 z'^T wrad z' against 1/2 int int K(|t - s|) z'(t) z'(s) by a fine trapezoid, for
    # the model's own z' (its objective minus the same objective without the term)
    from buoy_synthetic import kernel

    rp, x, _ = _radiation_problem()
    with_term = rp.objective(x)
    wrad, rp.wrad = rp.wrad, np.zeros((0, 0))
    without = rp.objective(x)
    rp.wrad = wrad
    ts = np.linspace(0.0, K * H, 801)
    zs = rp.heave(x, ts)
    zd = np.gradient(zs, ts, edge_order=2)
    wt = np.full(ts.size, ts[1] - ts[0])
    wt[[0, -1]] *= 0.5
    ref = 0.5 * (wt * zd) @ kernel(np.abs(np.subtract.outer(ts, ts))) @ (wt * zd)
    # Gauss rules against a trapezoid of 800 steps of a differenced z': ~1e-4
    assert with_term - without == pytest.approx(ref, rel=1e-3)


def _replay(plant, hp, fseg, ns):
    """The plant's scheme (RK4 on its step, the memory a trapezoid over the stored speeds,
    extrapolated quadratically inside a step) on the heave with the angle PRESCRIBED as the
    plan's; ``z`` at the steps."""
    h = plant.h
    th, thd, thdd = hp.evaluate(0.5 * h * np.arange(2 * ns + 1))
    cdd = -np.cos(th) * thd ** 2 - np.sin(th) * thdd
    mtot, cst, ml = plant.p[0], plant.p[1], plant.p[2]
    w, nk = plant.w, plant.nk
    vel = np.concatenate((plant.vel[plant.k0:plant.k0 + nk + 1], np.zeros(ns)))
    m0, m1, m2 = plant.mus
    z, zd = plant.y[0], plant.y[1]
    zs = [z]
    for i in range(ns):
        d1 = 0.5 * (3.0 * m0 - 4.0 * m1 + m2)
        d2 = 0.5 * (m0 - 2.0 * m1 + m2)
        mh, me = m0 + 0.5 * d1 + 0.25 * d2, m0 + d1 + d2

        def acc(zz, mu, k):
            return (fseg[k] - mu - cst * zz - ml * cdd[k]) / mtot
        a1 = acc(z, m0, 2 * i)
        z2, zd2 = z + 0.5 * h * zd, zd + 0.5 * h * a1
        a2 = acc(z2, mh, 2 * i + 1)
        z3, zd3 = z + 0.5 * h * zd2, zd + 0.5 * h * a2
        a3 = acc(z3, mh, 2 * i + 1)
        z4, zd4 = z + h * zd3, zd + h * a3
        a4 = acc(z4, me, 2 * i + 2)
        z = z + h / 6.0 * (zd + 2 * zd2 + 2 * zd3 + zd4)
        zd = zd + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
        vel[nk + i + 1] = zd
        m2, m1, m0 = m1, m0, float(w @ vel[i + 1:nk + i + 2][::-1])
        zs.append(z)
    return np.array(zs)


def test_radiation_model_heave_against_the_plants_replay():
    # the horizon model's heave against the plant's own scheme replaying the same
    # motion over 2 peak periods, from a state with a radiation memory of a rotating past
    # (synthetic dataset, its BEM-like piecewise-linear B): with the radiation inside the
    # model the two agree to the plant's discretization (measured 9e-5 of the rms heave);
    # with the past's memory force frozen in an undamped oscillator they do not (32 %)
    pend = Pendulum(20.0, 0.3, 1.8, 0.25)
    dt, ps = TP / 32, 8
    h = dt / ps
    n = 64  # 2 peak periods
    plant = bc._Plant(SYN, pend, h, 400 * ps, 8.0, None, 0.05, 0.1, None)
    tt = 0.5 * h * np.arange(2 * (400 + n) * ps + 1)
    fn = 2000.0 * np.sin(2.5 * tt) + 800.0 * np.cos(3.7 * tt + 1.0)
    plant.y[2], plant.y[3] = 0.5, 4.0
    plant.step(np.full(200, 5.0), ps, fn[:2 * 200 * ps + 1])  # a rotating past
    fseg = fn[2 * 200 * ps:2 * (200 + n) * ps + 1]
    mp = bc._MotionPlanner(n, dt, ps, plant.p, 50.0, 1.0, True, (plant.w, h))
    pr = mp.prob
    y0 = plant.y.copy()
    ts = h * np.arange(n * ps + 1)
    mem = mp.past_memory(plant)

    def fm(s):
        return np.interp(s, mp.tf, fseg) - np.interp(s, ts, mem)
    pr.set_start(y0, fm, None, mp.free_heave(plant, fseg))
    x = mp.start(y0, 0.0)
    x[0::2] += 0.4 * np.sin(mp.tn[1:])  # an uneven rotation
    full = pr.full(x)
    hp = HorizonPlan(mp.hh, full[0::2], full[1::2], 0.0)
    z = _replay(plant, hp, fseg, n * ps)
    rms = np.sqrt(np.mean(z ** 2))
    err = np.sqrt(np.mean((pr.heave(x, ts) - z) ** 2)) / rms
    assert err < 3e-4
    # the memory force of the past frozen in an undamped oscillator, no radiation of the
    # plan's own motion (the planner before froze the one predicted under its previous plan)
    old = bc._MotionPlanner(n, dt, ps, plant.p, 50.0, 1.0, True)
    old.prob.set_start(y0, fm)
    assert np.sqrt(np.mean((old.prob.heave(x, ts) - z) ** 2)) / rms > 30 * err


class _Stop(Exception):
    pass


@pytest.mark.slow  # compiles the planner's interior point on first use (35 to 60 s)
def test_horizon_solves_converge_riding_the_torque_limit(monkeypatch):
    """Steep short seas (Hs 0.8 m, Tp 3 s, the command line's buoy and default torque limit,
    perfect forecast): the first horizon solves after the catch plan a pendulum turning at
    up to 14 rad/s against the torque limit. Each must meet its KKT conditions (status
    ``converged``: the residuals below the tolerance) with its torques inside the limit
    (checked here from the plan itself); an exact penalty held at the largest multiplier of
    the first iterations made the line search crawl into the iteration limit."""
    from parapend.hydro import _buoy_plan as bp
    from parapend.hydro import api

    got = {}

    def grab(hydro, pendulum, wave, info, **kw):
        got.update(hydro=hydro, pend=pendulum, wave=wave)
        raise _Stop

    monkeypatch.setattr(bc, "mpc_command", grab)
    with pytest.raises(_Stop):
        api.buoy(hs=0.8, tp=3.0, seed=0, repeat_period=36.0, controller="mpc")
    rec = []
    orig = bp.CoupledPlan.solve

    def solve(self, x, **kw):
        xs, st, it = orig(self, x, **kw)
        rec.append((st, float(np.max(np.abs(self.constraint_torques(xs)))) / self.tmax))
        if len(rec) == 3:
            raise _Stop
        return xs, st, it

    monkeypatch.setattr(bp.CoupledPlan, "solve", solve)
    with pytest.raises(_Stop):
        bc.buoy_mpc(got["hydro"], got["pend"], got["wave"], peak_period=3.0,
                    controller="plan")
    assert [st for st, _ in rec] == ["converged"] * 3
    assert max(t for _, t in rec) <= 1.0 + 1e-6
