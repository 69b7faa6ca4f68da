"""The hull's receding-horizon controller (:mod:`parapend.hydro.hull_control`) on the
synthetic, exactly causal hull of tests/hull_timedomain.py (no BEM).

- The plant against the frequency domain: the free hull (a 1 kg pendulum hanging, no torque)
  started on its periodic response stays on it, ``Xi_k = Z(k w)^-1 F(k w) a_k`` with the
  hull's ``A(w)``, ``B(w)`` (the time domain has only the kernels and ``A_inf`` made from
  them);
- the memory kernels against the synthetic hull's closed-form ``K(t)``;
- the plant's energy balance, converging at the scheme's order as the step halves;
- the horizon problem's gradient against central differences of its objective;
- causality: altering the sea after ``t0 + H`` leaves every torque held before ``t0``
  bit-identical (perfect forecast), after ``t0`` with the AR forecast; a controller that
  peeks one horizon further fails the same check.
"""

import math

import numpy as np
import pytest
from hull_timedomain import synthetic_hull, synthetic_kernel

from parapend.hydro import control as bc
from parapend.hydro import hull_control as hc
from parapend.hydro.bem import HullHydro
from parapend.hydro.coupled import Pendulum, Wave
from parapend.hydro.hull import make_case

SYN = synthetic_hull()
HULL = HullHydro(omega=SYN["omega_data"], added_mass=SYN["A"], radiation_damping=SYN["B"],
                 excitation=SYN["F"], hydrostatic_stiffness=SYN["C"], mass=1025.0 * 40.0,
                 pitch_inertia=float(SYN["Mh"][2, 2]), description="synthetic hull")
PIVOT = SYN["pivot"]
PEND = Pendulum(SYN["m"], SYN["l"], SYN["I"], SYN["c"])
TR, TP = 10.0, 5.0
AMPS = np.zeros(4, complex)
AMPS[1], AMPS[2] = 0.5, 0.25j
WAVE = Wave(2 * math.pi / TR, AMPS)
OPTS = {"peak_period": TP, "pivot": PIVOT, "horizon": 0.5, "update_interval": 0.125,
        "warmup": 1.0, "samples": 16, "plant_steps": 4, "memory": 6.0, "max_iter": 15,
        "planner": "lbfgsb"}


def _plant(pendulum, h, steps, memory=8.0):
    kw = WAVE.amplitudes.size
    case = make_case(HULL, pendulum, WAVE, winding=0, harmonics=kw, hull_harmonics=kw,
                     pivot=PIVOT)
    xi0, xid0, history = hc._free_start(case)
    plant = hc.HullPlant(HULL, pendulum, case, h, steps, memory, xi0, xid0, history)
    return plant, case, history


def test_kernels_are_the_synthetic_hulls():
    """The per-entry cosine transform of the sampled ``B(w)`` against the closed-form kernel
    of the synthetic hull's modes, from 0.5 s on (the cut of ``B`` at 25 rad/s, where it is
    still some 6 % of its peak, shifts ``K`` near 0 alone)."""
    t = np.linspace(0.5, 8.0, 31)
    k = hc.radiation_kernels(HULL, t)
    ref = synthetic_kernel(t)
    assert np.max(np.abs(k - ref)) < 2e-2 * np.max(np.abs(ref))


def test_free_hull_follows_the_frequency_domain():
    """One record of the free hull (a 1 kg pendulum, no torque) from its periodic response:
    surge, heave and pitch stay on ``Re sum Xi_k exp(i k w t)``, the surge up to a uniform
    drift ``x0 + v t`` (free in surge, the hull's periodic motion is not unique: the tapered
    memory's slightly different ``B(w)`` starts it drifting, 5 mm/s here, 1.6 cm/s with an
    8 s memory)."""
    light = Pendulum(1.0, 1.0, 1.0, 0.0)
    per, ps = 64, 8
    h = TR / per / ps
    plant, case, history = _plant(light, h, per * ps, memory=16.0)
    fn = bc.force_nodes(HULL, WAVE, per, ps, 2 * per * ps + 1)
    ok, ys = plant.step(np.zeros(per), ps, fn)
    assert ok
    t = TR / per * np.arange(per + 1)
    nh = case.hull_harmonics
    fk = case.wave_force()
    xk = np.array([np.linalg.solve(case.impedance(k), fk[k]) if k else np.zeros(3)
                   for k in range(nh + 1)])
    ref = np.real(np.exp(1j * np.multiply.outer(t, case.omega * np.arange(nh + 1))) @ xk)
    scale = np.max(np.abs(ref), axis=0)
    diff = ys[:, :3] - ref
    drift = np.column_stack((np.ones_like(t), t))
    diff[:, 0] -= drift @ np.linalg.lstsq(drift, diff[:, 0], rcond=None)[0]
    err = np.max(np.abs(diff), axis=0) / scale
    assert np.all(err < 2e-2), err


@pytest.mark.parametrize("steps", [8])
def test_energy_balance(steps):
    """``W + c int v^2 + dE = int (F - mu) . xi'`` over a record under a torque that swings
    the pendulum: the residual is the scheme's, and falls at least 8-fold as the step
    halves."""
    out = []
    for ps in (steps, 2 * steps):
        per = 32
        plant, _, _ = _plant(PEND, TR / per / ps, per * ps)
        fn = bc.force_nodes(HULL, WAVE, per, ps, 2 * per * ps + 1)
        e0 = plant.energy()
        u = 4000.0 * np.sin(2 * math.pi * np.arange(per) / 16)
        ok, _ = plant.step(u, ps, fn)
        assert ok
        ab, damp, work = plant.acc
        out.append(abs(work + damp + plant.energy() - e0 - ab) / abs(ab))
    assert out[0] < 1e-3 and out[1] < out[0] / 8


@pytest.mark.parametrize("terminal", ["pendulum", "total"])
def test_horizon_gradient_is_exact(terminal):
    """The tangent-mode gradient against central differences of the objective."""
    per, ps, n = 32, 4, 12
    plant, _, _ = _plant(PEND, TR / per / ps, 4 * per * ps, memory=4.0)
    fn = bc.force_nodes(HULL, WAVE, per, ps, 2 * n * ps + 1)
    tu = PEND.mass * 9.81 * PEND.length
    prob = hc.HullHorizon(plant, n, ps, tu, 4.0, (0.9, 0.9), terminal=terminal)
    u = 0.4 * np.random.default_rng(0).standard_normal(n)
    f, g = prob.fun(u, None, fn)
    eps = 1e-6
    for k in range(n):
        e = np.zeros(n)
        e[k] = eps
        fd = (prob.fun(u + e, None, fn)[0] - prob.fun(u - e, None, fn)[0]) / (2 * eps)
        assert abs(fd - g[k]) <= 1e-5 * max(1.0, np.max(np.abs(g)))


def test_the_free_barge_follows_the_frequency_domain():
    """The embedded barge with the default tapered memory (a 1 kg pendulum, no torque), 3
    records of 24 s with harmonics 3 to 6 (Tp 6 s): surge (up to its uniform drift), heave
    and pitch within 0.2, 0.1 and 0.1 % of their ranges (measured 0.12, 0.055, 0.038 %)."""
    tp, tr, per = 6.0, 24.0, 96
    amps = np.zeros(9, complex)
    amps[3], amps[4], amps[5], amps[6] = 0.2, 0.5, 0.3j, 0.2
    wave = Wave(2 * math.pi / tr, amps)
    light = Pendulum(1.0, 1.0, 1.0, 0.0)
    hull = _barge()
    ps = hc.PLANT_STEPS
    h = tr / per / ps
    case = make_case(hull, light, wave, winding=0, harmonics=9, hull_harmonics=9,
                     pivot=_barge("pivot"))
    xi0, xid0, history = hc._free_start(case)
    plant = hc.HullPlant(hull, light, case, h, 3 * per * ps, hc.MEMORY_PERIODS * tp, xi0,
                         xid0, history)
    fn = bc.force_nodes(hull, wave, per, ps, 6 * per * ps + 1)
    ok, ys = plant.step(np.zeros(3 * per), ps, fn)
    assert ok
    t = tr / per * np.arange(3 * per + 1)
    fk = case.wave_force()
    xk = np.array([np.linalg.solve(case.impedance(k), fk[k]) if k else np.zeros(3)
                   for k in range(case.hull_harmonics + 1)])
    ref = np.real(np.exp(1j * np.multiply.outer(t, case.omega * np.arange(xk.shape[0]))) @ xk)
    diff = ys[:, :3] - ref
    drift = np.column_stack((np.ones_like(t), t))
    diff[:, 0] -= drift @ np.linalg.lstsq(drift, diff[:, 0], rcond=None)[0]
    err = np.max(np.abs(diff), axis=0) / np.ptp(ref, axis=0)
    assert np.all(err < [2e-3, 1e-3, 1e-3]), err


def _run(monkeypatch, cut=None, peek=False, forecast="perfect"):
    """A short closed loop with the excitation altered from plant node ``cut`` on; ``peek``:
    the planner is handed, beside its horizon's force, a trace (1e-3) of the force one
    horizon further on."""
    real = bc.force_nodes
    store = {}

    def altered(*a):
        fn = real(*a).copy()
        if cut is not None:
            fn[cut:] += 3e4 * np.sin(0.7 * np.arange(fn.shape[0] - cut))[:, None]
        store["fn"] = fn
        return fn
    monkeypatch.setattr(bc, "force_nodes", altered)
    if peek:
        plan = hc._plan

        def peeking(prob, plant, fseg, u0, max_iter):
            fn, a, w = store["fn"], 2 * plant.k0, fseg.shape[0] - 1
            far = fn[a + w:a + 2 * w + 1]
            far = np.pad(far, ((0, fseg.shape[0] - far.shape[0]), (0, 0)))
            return plan(prob, plant, fseg + 1e-3 * far, u0, max_iter)
        monkeypatch.setattr(hc, "_plan", peeking)
    return hc.hull_mpc(HULL, PEND, WAVE, **OPTS, forecast=forecast)


@pytest.mark.parametrize("peek, causal", [(False, True), (True, False)])
def test_torques_before_t0_ignore_the_sea_after_t0_plus_h(monkeypatch, peek, causal):
    """``t0`` three updates into the run: the torques before it were planned at ``t0 - u``
    at the latest on the force up to ``t0 - u + H`` (plant node ``2 (j0 - m + n) ps``);
    the sea altered from the next node on leaves them bit-identical, unless the controller
    looks further."""
    base = _run(monkeypatch, peek=peek)
    assert base.solves > 0 and base.catch_time_s == 0.0
    dt, ps = base.dt_s, OPTS["plant_steps"]
    n = int(round(base.horizon_s / dt))
    m = int(round(base.update_interval_s / dt))
    j0 = 3 * m
    last = 2 * (j0 - m + n) * ps
    after = _run(monkeypatch, cut=last + 1, peek=peek)
    a, b = base.series["torque"][:j0], after.series["torque"][:j0]
    assert np.any(a != 0)
    assert np.array_equal(a, b) is causal
    assert not np.array_equal(base.series["torque"], after.series["torque"])


@pytest.mark.parametrize("forecast, causal", [("ar", True), ("perfect", False)])
def test_ar_torques_before_t0_ignore_the_sea_after_t0(monkeypatch, forecast, causal):
    """The AR forecast (fitted at each update on the force measured so far): the sea altered
    after ``t0 - u`` (plant node ``2 (j0 - m) ps``) leaves the torques before ``t0``
    bit-identical; the perfect forecast, which reads the horizon, fails the same check."""
    base = _run(monkeypatch, forecast=forecast)
    dt, ps = base.dt_s, OPTS["plant_steps"]
    m = int(round(base.update_interval_s / dt))
    j0 = 3 * m
    after = _run(monkeypatch, cut=2 * (j0 - m) * ps + 1, forecast=forecast)
    a, b = base.series["torque"][:j0], after.series["torque"][:j0]
    assert np.any(a != 0)
    assert np.array_equal(a, b) is causal


@pytest.mark.slow
def test_the_command_runs_the_hull_beside_its_record_optimum(tmp_path, capsys):
    """``parapend buoy --dofs surge,heave,pitch --controller mpc``: the record's optimum is
    the plain command's on the same record, the fraction is the causal electrical power
    over it, the plant's energy balance closes and the update times are reported."""
    import json

    from hull_timedomain import synthetic_hull_netcdf

    from parapend.cli import main

    path = synthetic_hull_netcdf(tmp_path / "hull.nc")
    sea = ["--dofs", "surge,heave,pitch", "--hydro", path, "--hs", "1", "--tp", "5",
           "--repeat-period", "10", "--seed", "0"]
    assert main(["buoy", *sea, "--json"]) == 0
    opt = json.loads(capsys.readouterr().out)
    rc = main(["buoy", *sea, "--controller", "mpc", "--json", "--plot", str(tmp_path / "f")])
    r = json.loads(capsys.readouterr().out)
    assert rc == (0 if r["success"] else 3)  # a run that loses energy is a measurement
    assert r["optimum_power_w"] == opt["power_w"]
    assert r["optimum_winding"] == opt["winding"]
    start = hc.start_mode(opt["winding"], opt["mean_angle_deg"], opt["swing_amplitude_deg"])
    assert r["planner"] == f"hull-collocation-{start}"  # the default planner
    if r["status"] == "ok":
        assert math.isclose(r["optimum_fraction"], r["electrical_power_w"] / opt["power_w"])
    assert r["energy_balance_residual"] < 1e-3
    assert r["update_time_p99_s"] is not None and r["solves"] > 0
    # --plot drew the run's time series (PNG and SVG)
    assert {p.name for p in (tmp_path / "f").iterdir()} == {"buoy_mpc.png", "buoy_mpc.svg"}


def test_the_runs_figure_is_its_series():
    """``plot()`` of a closed-loop run: heave, the generator's speed, the held torque and
    the harvested energy against time (the series' own numbers: the energy the running sum
    of the sample powers), the averaging window's start marked on each."""
    import matplotlib

    matplotlib.use("Agg")
    r = hc.hull_mpc(HULL, PEND, WAVE, **OPTS)
    fig = r.plot()
    ax = fig.axes
    assert [a.get_ylabel().split(" ")[0] for a in ax] == ["heave", "generator", "torque",
                                                          "harvested"]
    s = r._samples
    assert np.array_equal(ax[0].lines[0].get_ydata(), s["z"])
    assert np.array_equal(ax[1].lines[0].get_ydata(), s["theta_dot"])
    assert np.array_equal(ax[2].lines[0].get_ydata()[:-1], s["torque"])
    e = ax[3].lines[0].get_ydata()
    assert e[-1] == pytest.approx(np.sum(s["power"] * np.diff(s["t"])), rel=1e-12)
    for a in ax:
        assert a.lines[-1].get_xdata()[0] == r.average_from_s
    assert "hull" in ax[0].get_title()
    # and its text report names the hull, not the heaving buoy
    from parapend.hydro.control import mpc_text

    text = "\n".join(mpc_text(r))
    assert "absorbed by the hull" in text and "(hull and pendulum)" in text
    assert "buoy" not in text


@pytest.mark.parametrize("args, mode", [
    ((1, None, None), "rotate"),       # a rotation
    ((-1, None, None), "rotate-reversed"),  # against the sense of a positive pitch
    ((-3, 180.0, 200.0), "rotate-reversed"),  # a swing with net turns against it
    ((0, 180.0, 60.0), "swing"),       # a swing about hanging, below the upright
    ((0, 308.7, 153.5), "rotate"),     # the default barge's seed 0: through the upright
    ((0, 200.0, 150.0), "swing"),      # 50 .. 350 degrees: short of the upright
    ((0, -40.0, 50.0), "rotate"),      # -90 .. 10 degrees holds 0
    ((0, None, None), "swing"),
])
def test_the_start_follows_the_optimums_motion(args, mode):
    """The pump's start where the optimum turns over the top, the hanging start where it
    swings below it."""
    assert hc.start_mode(*args) == mode


def test_the_reversed_start_is_the_mirrored_hulls_forward_start():
    """The pump mirrored (``rotate-reversed``) in the hull mirrored (``x -> -x``: ``S A S``,
    ``S B S``, ``S C S``, ``S F``, ``S = diag(-1, 1, -1)``, the pivot's offset negated) is
    the forward pump in the hull: until the catch the motion mirrored (``phi -> -phi``,
    ``x``, ``beta`` negated) and the torque negated, to rounding, and it catches on the
    same sample turning the other way."""
    sm = np.diag([-1.0, 1.0, -1.0])
    mirror = HullHydro(omega=SYN["omega_data"], added_mass=sm @ SYN["A"] @ sm,
                       radiation_damping=sm @ SYN["B"] @ sm, excitation=SYN["F"] @ sm,
                       hydrostatic_stiffness=sm @ SYN["C"] @ sm, mass=1025.0 * 40.0,
                       pitch_inertia=float(SYN["Mh"][2, 2]), description="mirrored")
    opts = dict(OPTS, warmup=3.0, torque_limit=3000.0)  # a weak pump: 57 samples
    fwd = hc.hull_mpc(HULL, PEND, WAVE, **opts, mode="rotate")
    back = hc.hull_mpc(mirror, PEND, WAVE, **dict(opts, pivot=(-PIVOT[0], PIVOT[1])),
                       mode="rotate-reversed")
    assert fwd.catch_time_s == back.catch_time_s and fwd.catch_time_s > 0
    a, b = fwd._samples, back._samples
    pump = a["t"] < fwd.catch_time_s
    assert pump.sum() > 10
    # both start hanging, phi = pi, whose mirror image -pi is the same angle
    turn = np.remainder(b["phi"][pump] + a["phi"][pump] + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(turn)) <= 1e-9
    for key, sign in (("x", -1), ("beta", -1), ("z", 1), ("torque", -1)):
        at = pump[:a[key].size]  # the torque: one a sample, the states one more
        scale = np.max(np.abs(a[key][at]))
        assert np.max(np.abs(b[key][at] - sign * a[key][at])) <= 1e-9 * scale, key
    caught = np.searchsorted(a["t"], fwd.catch_time_s)
    assert a["theta_dot"][caught] > 0 > b["theta_dot"][caught]


def _barge(key="hull"):
    from parapend.performance import matrix_spec
    from parapend.performance.hull_device import problem

    return problem(matrix_spec(hs="0.5,1", te="5,6,7,8", device="buoy",
                               dofs="surge,heave,pitch"))[key]


def _memory_damping(w, h, omega):
    """The damping of the discrete memory ``sum_q W_q cos(w q h)`` (nw, 3, 3)."""
    return np.einsum("wq,qij->wij", np.cos(np.multiply.outer(omega, h * np.arange(len(w)))), w)


@pytest.mark.parametrize("tp", [5.54, 6.0, 6.64, 7.75, 8.86])
def test_the_plants_memory_is_passive(tp):
    """The plant's memory damps no motion at any frequency, zero included, up to its step's
    Nyquist frequency: ``sum_q W_q cos(w q h)`` is positive semi-definite (relative to
    ``B``'s largest eigenvalue). Cut without its taper, at two peak periods, it is not: its
    integral in surge (which has no restoring force) was -369 N s/m at Tp 5.54 s, where the
    hull drifted 302 m in a 200-peak-period causal run."""
    hull = _barge()
    h = tp / 24 / hc.PLANT_STEPS
    w, _ = hc.memory_weights(hull, h, hc.MEMORY_PERIODS * tp)
    omega = np.linspace(0.0, math.pi / h, 4001)
    lo = np.linalg.eigvalsh(_memory_damping(w, h, omega)).min()
    top = np.linalg.eigvalsh(hull.radiation_damping).max()
    assert lo >= -1e-9 * top, (tp, lo)
    assert np.all(np.diag(w.sum(0)) >= 0.0)
    if tp == 5.54:  # without the taper, cut at two peak periods: drifting surge
        nk = math.ceil(2 * tp / h)
        bare = hc.radiation_kernels(hull, np.arange(nk + 1) * h) * h
        bare[0] *= 0.5
        bare[-1] *= 0.5
        assert bare.sum(0)[0, 0] < -300.0


@pytest.mark.parametrize("tp", [5.54, 6.0, 8.86])
def test_the_tapered_memory_keeps_the_waves_damping(tp):
    """Between 0.5 and 2.5 times the peak frequency the tapered memory's damping is the
    hull's ``B(w)`` (interpolated) within 1 % of each diagonal entry's largest."""
    hull = _barge()
    h = tp / 24 / hc.PLANT_STEPS
    w, _ = hc.memory_weights(hull, h, hc.MEMORY_PERIODS * tp)
    wp = 2 * math.pi / tp
    omega = np.linspace(0.5 * wp, 2.5 * wp, 200)
    got = np.diagonal(_memory_damping(w, h, omega), axis1=1, axis2=2)
    ref = np.array([np.interp(omega, hull.omega, hull.radiation_damping[:, i, i])
                    for i in range(3)]).T
    scale = np.max(np.diagonal(hull.radiation_damping, axis1=1, axis2=2), axis=0)
    assert np.all(np.max(np.abs(got - ref), axis=0) <= 0.01 * scale)
