"""Receding-horizon control of the pendulum inside the buoy (hydro/control.py), on the synthetic,
exactly causal dataset of tests/buoy_synthetic.py (no BEM): the plant against the pendulum
alone and against hydro/timedomain.simulate, its energy balance, the horizon problem's
gradient, and the input checks."""

import math

import numpy as np
import pytest
from buoy_synthetic import synthetic

from parapend.control.mpc import mpc_run
from parapend.errors import ParameterError
from parapend.hydro import control as bc
from parapend.hydro import timedomain as td
from parapend.hydro._control_kernel import plan_objective
from parapend.hydro.coupled import Pendulum, Wave

HYDRO = synthetic()
TR, TP = 10.0, 2.5
AMPS = np.zeros(12, complex)
AMPS[3], AMPS[4], AMPS[5] = 0.25, 0.15j, 0.08
WAVE = Wave(2 * math.pi / TR, AMPS)
MEMORY = 8.0
OPTS = {"peak_period": TP, "horizon": 0.5, "warmup": 2.0, "samples": 32, "memory": MEMORY}


def _pendulum(m):
    return Pendulum(m, 0.3, m * 0.09, m / 80)


def _free_start():
    zk, wk = bc.free_motion(HYDRO, WAVE)

    def history(t):
        return np.real(np.exp(1j * np.multiply.outer(t, wk)) @ (1j * wk * zk))
    return float(np.real(zk.sum())), float(np.real((1j * wk * zk).sum())), history


@pytest.fixture(scope="module")
def one_way():
    return bc.buoy_mpc(HYDRO, _pendulum(20.0), WAVE, controller="one-way", **OPTS)


def _light_pendulum_errors(ps):
    m = 1e-7
    pend = _pendulum(m)
    g = HYDRO.g
    t0 = math.sqrt(pend.inertia / (m * g * pend.length))
    tu = m * g * pend.length
    dt, per = TR / 80, 80
    total = 24
    fn = bc.force_nodes(HYDRO, WAVE, per, ps, 2 * (total + 40) * ps + 1)
    z0, zd0, hist = _free_start()
    free = bc._Plant(HYDRO, pend, dt / ps, (total + 40) * ps, MEMORY, None, z0, zd0, hist)
    zdd = free.predict(np.zeros(total + 40), ps, fn)
    dtn = dt / t0
    tq = 0.5 * (dtn / ps) * np.arange(zdd.size)
    ref = mpc_run((tq, zdd / g), gamma=pend.damping_coefficient * t0 / pend.inertia,
                  horizon=20 * dtn, update_interval=4 * dtn, dt=dtn, torque_limit=2.0,
                  t_end=total * dtn, plant_steps=ps)
    assert ref.success and ref.catch_time is not None
    plant = bc._Plant(HYDRO, pend, dt / ps, total * ps, MEMORY, None, z0, zd0, hist)
    ok, ys = plant.step(ref.torque * tu, ps, fn[:2 * total * ps + 1])
    assert ok
    p = -ref.torque * tu * np.diff(ys[:, 2]) / dt
    return (np.max(np.abs(ys[:, 2] - ref.theta)), np.max(np.abs(ys[:, 3] * t0 - ref.theta_dot)),
            abs(np.mean(p) - ref.harvested_power * tu / t0) / (ref.harvested_power * tu / t0))


def test_light_pendulum_on_the_buoy_is_the_pendulum_on_the_free_heave():
    # m -> 0: the torque of the pendulum MPC (parapend.control.mpc) run on the free buoy's
    # heave, applied to the buoy with a 1e-7 kg pendulum, gives the pendulum MPC's motion and
    # power (over the swing-up and three turns, 3 s), to the integrators' difference: the
    # buoy's RK4 takes z'' at each stage, the pendulum's q at the nodes; it falls by about 16
    # when the steps are halved (4th order)
    e8 = _light_pendulum_errors(8)
    e16 = _light_pendulum_errors(16)
    assert e8[0] < 5e-3 and e8[1] < 5e-3 and abs(e8[2]) < 1e-3
    assert e16[0] < e8[0] / 8 and e16[1] < e8[1] / 8 and abs(e16[2]) < abs(e8[2]) / 4


def test_the_plant_energy_balance_closes(one_way):
    r = one_way
    # this short run loses energy (a measurement, marked: status loses_energy, a warning)
    assert r.status == "loses_energy" and r.mean_power_w < 0 and r.warnings
    # harvested + damping + stored = absorbed from the waves (the plant's RK4 quadrature)
    assert r.energy_balance_residual < 1e-5
    assert r.damping_w > 0


def test_saved_torque_reintegrated_by_simulate(one_way):
    # hydro/timedomain.simulate, given the saved torque held over each sample, the record's
    # force and the free buoy's past, reproduces the saved motion and power
    r = one_way
    s = r.series
    pend = _pendulum(20.0)
    z0, zd0, hist = _free_start()
    h = r.units["plant_step_s"]
    ps = int(round(r.dt_s / h))
    n = s["torque"].size
    calls = [0]

    def torque(t, th, om):
        c = calls[0]
        calls[0] += 1
        i = c // 4 if c < 4 * n * ps else min(c - 4 * n * ps, n * ps - 1)
        return s["torque"][min(i // ps, n - 1)]
    out = td.simulate(HYDRO, mass=pend.mass, length=pend.length, inertia=pend.inertia,
                      damping_coefficient=pend.damping_coefficient, torque=torque,
                      wave=bc.record_force(HYDRO, WAVE), t_end=r.t_end_s, theta0=math.pi,
                      z0=z0, zdot0=zd0, history=hist, dt=h, memory=MEMORY,
                      a_inf=r.units["a_inf_kg"])
    # the same scheme summed in another order: they differ by round-off (1e-13), which the
    # rotating pendulum amplifies (1e-12 rad at 5 s, 2e-8 rad at 7.5 s, 0.25 rad at 15 s);
    # compared over 5 s
    k = int(round(5.0 / r.dt_s))
    th = out["theta"][::ps][:k + 1]
    assert np.max(np.abs(th - s["theta"][:k + 1])) < 1e-8
    assert np.max(np.abs(out["omega"][::ps][:k + 1] - s["theta_dot"][:k + 1])) < 1e-7
    assert np.max(np.abs(out["z"][::ps][:k + 1] - s["z"][:k + 1])) < 1e-10
    p = -s["torque"][:k] * np.diff(th) / r.dt_s
    assert np.max(np.abs(p - s["power"][:k])) < 1e-6 * np.max(np.abs(p))


def test_coupled_horizon_gradient_is_exact():
    rng = np.random.default_rng(1)
    n, steps = 6, 4
    p = np.array([640.0, 7880.0, 24.0, 7.2, 1.0, 9.81])
    tu = 80 * 9.81 * 0.3
    u = rng.normal(size=n) * 0.5
    y0 = np.array([0.1, 0.3, 2.0, 3.0])
    fnet = rng.normal(size=2 * n * steps + 1) * 500
    grad, ys = np.empty(n), np.empty((n * steps + 1, 4))
    ref = np.array([0.05, -0.2])
    for eta, total in (((1.0, 1.0), 1.0), ((0.8, 0.7), 1.0), ((0.9, 0.9), 0.0)):
        def f(v, eta=eta, total=total):
            return plan_objective(v, y0, fnet, 0.01, steps, p, tu, eta[0], eta[1], 0.9, ref,
                                  total, grad, ys)
        f(u)
        g = grad.copy()
        fd = np.array([(f(u + e) - f(u - e)) / 2e-6 for e in np.eye(n) * 1e-6])
        assert np.max(np.abs(g - fd)) < 1e-6 * np.max(np.abs(fd))


def test_coupled_controller_runs_on_a_heavy_pendulum():
    r = bc.buoy_mpc(HYDRO, _pendulum(20.0), WAVE, controller="coupled", iterations=2,
                    **OPTS)
    assert r.success and r.solves == 2 * len(r.fixed_point_change) or r.solves > 0
    assert r.energy_balance_residual < 1e-5
    assert r.peak_torque_nm <= r.torque_limit_nm * (1 + 1e-12)
    assert r.fixed_point_residual is not None


@pytest.mark.parametrize("kw, name", [({"controller": "lqr"}, "controller"),
                                      ({"horizon": 0.1, "update_interval": 0.5},
                                       "update-interval"),
                                      ({"terminal": "none"}, "terminal"),
                                      ({"torque_limit": -1.0}, "torque-limit"),
                                      ({"iterations": 0}, "iterations"),
                                      ({"efficiency": 0.0}, "efficiency")])
def test_bad_input(kw, name):
    opts = {**OPTS, **kw}
    with pytest.raises(ParameterError, match=name):
        bc.buoy_mpc(HYDRO, _pendulum(20.0), WAVE, **opts)
    with pytest.raises(ParameterError, match="mass"):
        bc.buoy_mpc(HYDRO, _pendulum(2000.0), WAVE, **OPTS)


@pytest.mark.parametrize("argv, name", [
    (["--controller", "mpc"], "controller"),                       # no irregular sea
    (["--controller", "mpc", "--wave-period", "1.5"], "controller"),
    (["--controller", "pid", "--hs", "0.5", "--tp", "2.5"], "controller"),
    # the planner: with mpc only, and the model's own
    (["--planner", "coupled", "--hs", "0.5", "--tp", "2.5"], "planner"),
    (["--controller", "one-way-mpc", "--planner", "plan", "--hs", "0.5", "--tp", "2.5"],
     "planner"),
    (["--controller", "mpc", "--planner", "collocation", "--hs", "0.5", "--tp", "2.5"],
     "planner"),
    (["--controller", "mpc", "--planner", "plan", "--efficiency", "0.9", "--hs", "0.5",
      "--tp", "2.5"], "efficiency"),
    (["--dofs", "surge,heave,pitch", "--controller", "mpc", "--planner", "coupled", "--hs",
      "1", "--tp", "6"], "planner"),
    (["--dofs", "surge,heave,pitch", "--planner", "collocation", "--hs", "1", "--tp", "6"],
     "planner"),
])
def test_cli_bad_input_is_one_line(argv, name, capsys):
    from parapend.cli import main

    assert main(["buoy", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and name in err[0]


@pytest.mark.slow
def test_default_design_coupled_controller_harvests_where_one_way_loses():
    # docs/buoy.md's table, seed 0, one peak period: the coupled controller 29.6 W (57 % of
    # the record's optimum), the one-way controller -80.8 W; both energy balances close
    import parapend

    opt = parapend.buoy(hs=0.5, tp=2.5, repeat_period=25, seed=0, winding=9)
    pend = Pendulum(mass=80.0, length=0.3, inertia=7.2, damping_coefficient=1.0)
    runs = {c: bc.buoy_mpc(opt._hydro, pend, opt._wave, peak_period=2.5, horizon=1.0,
                           controller=c) for c in ("coupled", "one-way")}
    c, o = runs["coupled"], runs["one-way"]
    # the one-way controller's loss is measured and marked: status loses_energy, a warning
    assert c.success and o.status == "loses_energy" and o.warnings
    assert 0.3 < c.mean_power_w / opt.power_w < 0.8
    assert o.mean_power_w < 0 < c.mean_power_w
    assert c.energy_balance_residual < 1e-6 and o.energy_balance_residual < 1e-4
    assert c.fixed_point_residual < 0.05


def test_the_headline_is_storage_corrected_over_whole_repeats(one_way):
    """The energy account from the saved series alone: the harvested energy is the integral
    of the saved (held) power over the window after the start-up, the stored energy's
    change is the state's mechanical energy of buoy and pendulum at its ends (recomputed
    here from the saved z, z', theta, theta'), and the headline is their sum per unit
    time; the timings report the first update apart and the failed solves what was
    applied."""
    r = one_way
    s = r.series
    pend = _pendulum(20.0)
    t, p = s["t"], s["power"]
    i0 = int(round(r.average_from_s / r.dt_s))
    assert t[i0] == pytest.approx(r.average_from_s, abs=1e-9)
    span = t[-1] - t[i0]
    assert span == pytest.approx(TR, rel=1e-9)  # one whole repeat of the record
    w = float(np.sum(p[i0:]) * r.dt_s)
    assert r.harvested_energy_j == pytest.approx(w, rel=1e-12)
    assert r.harvested_power_w == pytest.approx(w / span, rel=1e-12)
    # the mechanical energy of buoy and pendulum, written out here: the floating mass M
    # (pendulum included) with the infinite-frequency added mass, the hydrostatic spring,
    # and the pendulum (point of mass m at l, inertia I about the pivot, which heaves with
    # the buoy; theta from the upright): its change between the saved states at the
    # window's ends
    m, ell, inertia, g = pend.mass, pend.length, pend.inertia, HYDRO.g
    mt = HYDRO.mass + r.units["a_inf_kg"]

    def energy(k):
        z, zd, th, om = s["z"][k], s["z_dot"][k], s["theta"][k], s["theta_dot"][k]
        return (0.5 * mt * zd**2 - m * ell * math.sin(th) * zd * om + 0.5 * inertia * om**2
                + 0.5 * HYDRO.hydrostatic_stiffness * z**2 + m * g * ell * math.cos(th))

    de = energy(-1) - energy(i0)
    scale = abs(energy(i0)) + abs(energy(-1))
    assert r.stored_energy_change_j == pytest.approx(de, abs=1e-12 * scale)
    assert r.stored_w == pytest.approx(r.stored_energy_change_j / span, rel=1e-12)
    assert r.mean_power_w == pytest.approx((w + de) / span, rel=1e-9)
    assert r.electrical_power_w == pytest.approx(r.mean_power_w)  # no efficiency
    assert r.update_time_first_s is not None and r.update_time_median_s is not None
    assert r.update_time_p99_s <= r.update_time_max_s
    assert r.realtime_fits == (r.update_time_p99_s <= r.update_interval_s)
    assert 0 <= r.failed_kept_previous <= r.failed_solves


@pytest.mark.slow  # the embedded buoy's BEM (cached), its reference optimum and two runs
def test_cli_planner_chooses_the_heaving_buoys_planner(capsys):
    """``parapend buoy --controller mpc --planner coupled``: the run is planned by the
    held-torque planner (the default, ``plan``, without it), as ``horizon --planner``."""
    import json

    from parapend.cli import main

    argv = ["buoy", "--controller", "mpc", "--hs", "0.5", "--tp", "2.5", "--repeat-period",
            "5", "--json"]
    for extra, planner in (([], "plan"), (["--planner", "coupled"], "coupled")):
        main([*argv, *extra])
        assert json.loads(capsys.readouterr().out)["planner"] == planner
