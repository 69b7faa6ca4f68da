"""The hull's collocation planner (``hull_mpc(planner="collocation")``,
:mod:`parapend.hydro._hull_collocation`) on the synthetic hull of tests/hull_timedomain.py:

- its model is the plant's: the collocation's motion under fixed held torques converges to
  the plant's (RK4 on a finer step) as the interval halves;
- the plan is one the plant follows: the plant re-integrated under the plan's own torques
  stays on the planned motion over the update interval it is applied for;
- causality, bit for bit, as the L-BFGS-B planner's (tests/test_hull_mpc.py);
- a solve IPOPT ends at its iteration cap is reported as capped, not failed.
"""

import numpy as np
import pytest

pytest.importorskip("casadi")

import test_hull_mpc as th  # noqa: E402

from parapend.hydro import control as bc  # noqa: E402
from parapend.hydro import hull_control as hc  # noqa: E402
from parapend.hydro._hull_collocation import HullCollocation  # noqa: E402

PER, PS, N = 32, 8, 6  # samples a record, plant steps a sample, horizon samples
TU = th.PEND.mass * 9.81 * th.PEND.length


def _horizon(intervals, steps=PS):
    """A plant of ``steps`` steps a sample advanced two samples under a swinging torque,
    its force nodes over the horizon, and the collocation problem of ``N`` samples on it
    (``intervals`` 0: none)."""
    plant, _, _ = th._plant(th.PEND, th.TR / PER / steps, 4 * PER * steps,
                            memory=hc.MEMORY_PERIODS * th.TP)
    fn = bc.force_nodes(th.HULL, th.WAVE, PER, steps, 2 * 3 * PER * steps + 1)
    plant.step(np.array([0.8, -0.8]) * TU, steps, fn)
    a = 2 * plant.k0
    fseg = fn[a:a + 2 * N * steps + 1]
    prob = (HullCollocation(plant, N, steps, TU, 4.0, intervals=intervals, max_iter=200)
            if intervals else None)
    return plant, fseg, prob


def test_collocation_converges_to_the_plant():
    """Under fixed torques the collocation's only feasible motion approaches the plant's
    (RK4 on 64 steps a sample, itself converged to 1e-5) as the Hermite-Simpson interval
    halves (2, 4, 8 intervals a sample): the error of the angles and the hull's motion at
    the samples' ends falls at least 3-fold a halving (second order: the memory's trapezoid,
    linear between its nodes; Hermite-Simpson is fourth), to below 5e-4."""
    u = np.array([0.5, -0.3, 0.9, -0.6, 0.2, 0.4])
    plant, fseg, _ = _horizon(0, steps=64)
    ok, ref, _ = plant.roll(u * TU, 64, fseg)
    assert ok
    errs = []
    for ps, r in ((8, 2), (8, 4), (16, 8)):
        plant, fseg, prob = _horizon(r, steps=ps)
        st = prob.simulate(u, fseg)[::2 * r]
        errs.append(np.max(np.abs(st[:, :4] - ref[:, :4])))
    assert errs[2] < 5e-4, errs
    assert errs[0] > 3 * errs[1] > 9 * errs[2], errs


def test_the_plant_follows_the_plan():
    """The plan is its torques' own motion (the collocation's unique feasible motion under
    them, to IPOPT's tolerance), and the plant re-integrated under those torques from the
    same state stays on it over the first update interval (a quarter of the horizon) within
    1e-3 (m, rad): the two discretizations' difference at these steps, which
    :func:`test_collocation_converges_to_the_plant` measures at 1.6e-3 over the whole
    horizon. Over the whole horizon the plan is open-loop unstable, so only its applied
    part is held to it."""
    plant, fseg, prob = _horizon(4)
    r = prob.solve(plant, fseg, np.zeros(N))
    assert r.status == 0, r.ipopt
    assert np.all(np.abs(r.x) <= 4.0)
    assert np.max(np.abs(r.x)) > 1.0  # the plan does act
    own = prob.simulate(r.x, fseg)
    assert np.max(np.abs(own - r.states)) < 1e-5
    ok, ys, _ = plant.roll(r.x * TU, PS, fseg)
    st = r.states[::8]
    k = N // 4 + 1
    assert ok and np.max(np.abs(ys[:k, :4] - st[:k, :4])) < 1e-3


@pytest.mark.parametrize("peek, causal", [(False, True), (True, False)])
def test_collocation_is_causal(monkeypatch, peek, causal):
    """The sea altered after ``t0 + H`` leaves the torques before ``t0`` bit-identical
    (tests/test_hull_mpc.py's check on the collocation planner)."""
    monkeypatch.setitem(th.OPTS, "planner", "collocation")
    th.test_torques_before_t0_ignore_the_sea_after_t0_plus_h(monkeypatch, peek, causal)


def test_collocation_ar_is_causal(monkeypatch):
    """The AR forecast: the sea altered after ``t0 - u`` leaves the torques before ``t0``
    bit-identical."""
    monkeypatch.setitem(th.OPTS, "planner", "collocation")
    th.test_ar_torques_before_t0_ignore_the_sea_after_t0(monkeypatch, "ar", True)


def test_capped_solves_are_reported():
    """IPOPT stopped by its iteration cap: the solve's status is 1 (capped, applied, not
    failed, as L-BFGS-B's), and the run counts every update as a solve."""
    plant, fseg, prob = _horizon(2)
    capped = HullCollocation(plant, N, PS, TU, 4.0, intervals=2, max_iter=2)
    r = capped.solve(plant, fseg, np.zeros(N))
    assert r.status == 1 and not r.success and r.nit == 2
    assert bc._check_solve(r, np.zeros(N))[1] == 0
    res = hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **dict(th.OPTS, max_iter=2,
                                                         planner="collocation"))
    assert res.solves > 0 and res.failed_solves == 0


def test_a_capped_plan_the_plant_cannot_resolve_is_not_applied(monkeypatch):
    """A solve stopped at its cap whose planned motion turns the generator faster than the
    plant's step resolves (``control.RESOLVED`` rad a step) is a failed solve: the previous
    plan continued is applied and is the next start (such capped iterates, far from
    feasible, drove a Hs 0.5 m bin's pendulum past that speed). A capped plan within it is
    applied as it is."""
    plant, fseg, _ = _horizon(2)
    prob = HullCollocation(plant, N, PS, TU, 4.0, intervals=2, max_iter=40)
    first = prob.solve(plant, fseg, np.zeros(N))
    assert first.status in (0, 1) and not prob.unfollowable(first.states)
    lo = prob.nx + prob.na
    want = np.clip(np.concatenate((prob.prev[lo + 1:lo + N], prob.prev[lo + N - 1:lo + N])),
                   -4.0, 4.0)
    orig = prob.solve_from
    spin = {"on": True}

    def capped(*a, **k):
        r = orig(*a, **k)
        st = r.states.copy()
        if spin["on"]:
            st[1:, 7] += 2.0 * bc.RESOLVED / plant.h
        r.states, r.status, r.success = st, 1, False
        return r

    monkeypatch.setattr(prob, "solve_from", capped)
    prob.shift = 1
    r = prob.solve(plant, fseg, first.x)
    assert r.status == 2 and not r.success and not prob.unfollowable(r.states)
    assert np.array_equal(r.x, want)
    assert np.array_equal(np.clip(prob.prev[lo:lo + N], -4.0, 4.0), want)
    assert bc._check_solve(r, first.x)[1] == 1
    spin["on"] = False
    r = prob.solve(plant, fseg, want)
    assert r.status == 1 and bc._check_solve(r, want)[1] == 0


def test_a_capped_plan_whose_torques_the_model_does_not_follow_is_not_applied(monkeypatch):
    """A capped iterate within the speed bound whose first torque the plant's model does not
    follow (rolled under it, the generator leaves the planned angle by 0.39 rad where a
    converged plan stays within 1e-6) is a failed solve: the previous plan continued is
    applied (such an iterate turned a Hs 0.5 m bin's pendulum past the plant's step). The
    same iterate with its own torques is applied."""
    plant, fseg, _ = _horizon(2)
    prob = HullCollocation(plant, N, PS, TU, 4.0, intervals=2, max_iter=40)
    first = prob.solve(plant, fseg, np.zeros(N))
    prob.shift = 1
    assert first.status in (0, 1) and not prob.drifts(first, fseg)
    lo = prob.nx + prob.na
    want = np.clip(np.concatenate((prob.prev[lo + 1:lo + N], prob.prev[lo + N - 1:lo + N])),
                   -4.0, 4.0)
    orig = prob.solve_from
    push = {"by": 1.0}

    def capped(*a, **k):
        r = orig(*a, **k)
        r.x = r.x.copy()
        r.x[0] += push["by"]
        r.status, r.success = 1, False
        return r

    monkeypatch.setattr(prob, "solve_from", capped)
    r = prob.solve(plant, fseg, first.x)
    assert r.status == 2 and not r.success and np.array_equal(r.x, want)
    assert bc._check_solve(r, first.x)[1] == 1
    push["by"] = 0.0
    r = prob.solve(plant, fseg, want)
    assert r.status == 1 and not prob.drifts(r, fseg) and bc._check_solve(r, want)[1] == 0


def test_bad_planner_is_one_line():
    """An unknown planner, or plant steps the collocation's intervals cannot hold."""
    with pytest.raises(hc.ParameterError, match="planner: expected"):
        hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **dict(th.OPTS, planner="newton"))
    with pytest.raises(hc.ParameterError, match="plant_steps"):
        hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **dict(th.OPTS, plant_steps=5,
                                                      planner="collocation"))


def test_the_default_terminal_weight_is_the_measured_one():
    """Without ``terminal_weight`` the collocation planner weighs the energy left at the
    horizon's end by ``COLLOCATION_TERMINAL_WEIGHT`` (0.5, measured: docs/hull.md): the run
    is the one with 0.5 given, to the bit, and not the one with 1 (the L-BFGS-B planner's
    default)."""
    opts = dict(th.OPTS, max_iter=3, planner="collocation")
    runs = [hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **opts, terminal_weight=w).series["torque"]
            for w in (None, 0.5, 1.0)]
    assert hc.COLLOCATION_TERMINAL_WEIGHT == 0.5
    assert np.array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])


@pytest.mark.slow
def test_the_command_runs_the_collocation_planner(tmp_path, capsys):
    """``parapend buoy --dofs surge,heave,pitch --controller mpc --planner collocation``:
    the run's planner is named, its reference is the plain command's record optimum, and the
    plant's energy balance closes."""
    import json

    from hull_timedomain import synthetic_hull_netcdf

    from parapend.cli import main

    path = synthetic_hull_netcdf(tmp_path / "hull.nc")
    sea = ["--dofs", "surge,heave,pitch", "--hydro", path, "--hs", "1", "--tp", "5",
           "--repeat-period", "10", "--seed", "0"]
    assert main(["buoy", *sea, "--json"]) == 0
    opt = json.loads(capsys.readouterr().out)
    rc = main(["buoy", *sea, "--controller", "mpc", "--planner", "collocation", "--json"])
    r = json.loads(capsys.readouterr().out)
    assert rc == (0 if r["success"] else 3)
    start = hc.start_mode(opt["winding"], opt["mean_angle_deg"], opt["swing_amplitude_deg"])
    assert r["planner"] == f"hull-collocation-{start}"
    assert r["optimum_power_w"] == opt["power_w"]
    assert r["energy_balance_residual"] < 1e-3
    assert r["solves"] > 0 and r["update_time_p99_s"] is not None


def test_the_compiled_solver_needs_no_casadi(monkeypatch):
    """The collocation planner on its compiled solver: with CasADi made unimportable the
    run is the one with CasADi there, to the bit (no IPOPT in it): the hull's default
    planner needs no extra; asked for IPOPT without CasADi, one line naming the extra."""
    import sys

    from parapend.hydro import _hull_collocation as hcol

    opts = {k: v for k, v in th.OPTS.items() if k != "planner"} | {"max_iter": 5}
    assert (hcol.SOLVER, hc.PLANNER) == ("compiled", "collocation")
    with_casadi = hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **opts)
    monkeypatch.setitem(sys.modules, "casadi", None)
    without = hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **opts)
    assert without.solves > 0 and without.failed_solves == 0
    assert np.array_equal(with_casadi.series["torque"], without.series["torque"])
    monkeypatch.setattr(hcol, "SOLVER", "ipopt")
    with pytest.raises(hc.ParameterError, match=r"parapend\[collocation\]"):
        hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **opts)


@pytest.mark.parametrize("solver, cap", [("compiled", 40), ("ipopt", 100)])
def test_the_default_iteration_cap_is_the_solvers(monkeypatch, solver, cap):
    """Without ``max_iter`` a horizon solve is capped at ``COMPILED_ITER`` (40, measured:
    docs/hull.md) with the compiled solver and ``COLLOCATION_ITER`` (100) with IPOPT."""
    from parapend.hydro import _hull_collocation as hcol

    seen = []

    def plan(prob, y0, fseg, u0, max_iter):
        seen.append((prob.solver_name, max_iter))
        raise StopIteration

    monkeypatch.setattr(hcol, "SOLVER", solver)
    monkeypatch.setattr(hc, "_plan", plan)
    opts = {k: v for k, v in th.OPTS.items() if k not in ("max_iter", "planner")}
    with pytest.raises(StopIteration):
        hc.hull_mpc(th.HULL, th.PEND, th.WAVE, **opts, planner="collocation")
    assert seen == [(solver, cap)]
    assert (hc.COMPILED_ITER, hc.COLLOCATION_ITER) == (40, 100)
