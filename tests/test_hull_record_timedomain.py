"""The hull in an irregular record, checked in the time domain by code that does not share the
package's hull kernel (tests/cummins_hull.py, tests/hull_timedomain.py):

- the record optimum's pendulum motion prescribed, Cummins' equation with the radiation
  memory integrated from rest over repeats of the record until periodic: the last repeat's
  hull motion and mean power are the frequency domain's;
- the record optimum's torque ``tau(t)`` given to the nonlinear pendulum and the hull
  (:func:`cummins_hull.reintegrate_hull`, DOP853, the memory a direct convolution), from the
  optimum's state: the motion stays on the optimum's and the mean power is its power;
- the heaving buoy's causal run (its saved held torques) re-integrated by the same code with
  surge and pitch held: the saved motion and energies; and the hull's causal run the same
  way (once its controller, ``parapend.hydro.hull_control``, is there).

On the causal synthetic hull of tests/hull_timedomain.py (no BEM); the record is the
package's own JONSWAP record (seeded).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from cummins_hull import (
    chunked,
    compare_motion,
    hull_data,
    matched_a_inf,
    memory_length,
    record_replay,
    reintegrate_hull,
)
from hull_timedomain import (
    RHO_V,
    interpolator,
    synthetic_hull,
    synthetic_hull_netcdf,
)

from parapend.errors import ParameterError
from parapend.hydro.bem import HullHydro
from parapend.hydro.coupled import Pendulum
from parapend.hydro.result import REPORT_HULL_FACTOR

SYN = synthetic_hull()
PEND = Pendulum(SYN["m"], SYN["l"], SYN["I"], SYN["c"])
PIVOT = SYN["pivot"]
HS, TP = 1.0, 5.0
#: the cheap record: two peak periods, the optimum's harmonics fixed (no refinement)
SHORT_WAVES, SHORT_HARMONICS = 2, 64


def _hull() -> HullHydro:
    return HullHydro(omega=SYN["omega_data"], added_mass=SYN["A"], radiation_damping=SYN["B"],
                     excitation=SYN["F"], hydrostatic_stiffness=SYN["C"], mass=RHO_V,
                     pitch_inertia=float(SYN["Mh"][2, 2]), description="synthetic hull")


def _record(waves):
    """The package's seeded JONSWAP record (Hs 1 m, Tp 5 s) repeating after ``waves`` peak
    periods, as ``buoy --hs --tp --repeat-period --seed 0`` builds it."""
    from parapend.hydro.declared import default_of
    from parapend.hydro.inputs import _irregular_wave
    from parapend.units import Units

    wave, _ = _irregular_wave(HS, TP, default_of("spectrum", None),
                              default_of("gamma_peak", None), waves * TP, 0,
                              default_of("cutoff", None), None, default_of("taper", None),
                              Units(PEND.length, PEND.mass, 9.81, PEND.inertia))
    return wave


@functools.cache
def _short_optimum(winding):
    """A record optimum (a local maximum of the coupled problem, by the package's Newton
    from one start: a swing at the record's peak harmonic, or the turn from upright; one
    start keeps it cheap) and its motion at any time
    (:class:`parapend.hydro.result.MotionAt`)."""
    from parapend.hydro.hull import HullProblem, make_case
    from parapend.hydro.result import MotionAt
    from parapend.optimal.fourier import newton_maximize

    wave = _record(SHORT_WAVES)
    case = make_case(_hull(), PEND, wave, winding=winding, harmonics=SHORT_HARMONICS,
                     pivot=PIVOT)
    problem = HullProblem(case)
    n = case.harmonics
    x0 = np.zeros(2 * n + 1)
    if winding == 0:
        x0[0], x0[int(np.argmax(np.abs(wave.amplitudes))) + 1] = math.pi, 0.5
    sol = newton_maximize(problem, x0, "start", gtol=1e-10, maxiter=200)
    assert sol.status == "converged" and sol.power > 0
    return case, sol.x, float(sol.power), MotionAt(problem, sol.x, problem.solve_hull(sol.x))


@pytest.fixture(scope="module")
def short_optimum():
    """The swinging record optimum of :func:`_short_optimum`."""
    return _short_optimum(0)


def _replay_check(omega, amplitudes, x, winding, power, motion, hull, pend, pivot, dt,
                  pitch_inertia=None):
    data = hull_data(hull, pend.mass, pitch_inertia)
    td = record_replay(data, pend, pivot, omega, amplitudes, x, winding, dt=dt)
    fd = chunked(motion)(td["t"])
    diff = compare_motion(td, fd["xi"].T, fd["xi_dot"].T)
    return td, diff, td["power"] / power - 1


#: per mode: the tolerances of the hull's motion and speeds against the optimum's (its own
#: truncation of the hull's harmonics at 65-66: measured 3e-4 and 7e-4 swinging, 3e-4 and
#: 4e-3 rotating at 64 harmonics of phi; 1.2e-2 in the rotation's surge speed at 48)
MOTION_TOL = {0: (1e-3, 2e-3), 2: (1e-3, 6e-3)}


@pytest.mark.parametrize("winding", [0, pytest.param(2, marks=pytest.mark.slow)])
def test_record_optimum_replayed_through_cummins(winding):
    """The optimum's phi prescribed (swinging, and turning twice per record), the hull from
    rest over repeats of the 10 s record (Newmark at 5 ms, the memory's A_inf matched at the
    record's peak): the last repeat is periodic and its mean power is the optimum's to
    1e-3 (measured 1.4e-4 swinging, 1.1e-4 rotating: the memory model's own error, the
    data's A(w) against A_inf and the memory's at the other harmonics, and Newmark's
    (w dt)^2 / 12). The hull's motion agrees to the optimum's own truncation of the hull's
    harmonics (``MOTION_TOL``)."""
    case, x, power, motion = _short_optimum(winding)
    td, diff, rel = _replay_check(case.omega, case.amplitudes, x, case.winding, power, motion,
                                  _hull(), PEND, PIVOT, dt=0.005)
    assert td["periodicity"] < 1e-5
    assert abs(rel) < 1e-3, rel
    assert np.all(diff["xi"] < MOTION_TOL[winding][0]), diff
    assert np.all(diff["xi_dot"] < MOTION_TOL[winding][1]), diff


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return synthetic_hull_netcdf(tmp_path_factory.mktemp("hull") / "hull.nc")


#: per body: the tolerances of the power, the hull's motion and its speeds. The embedded
#: barge's BEM data are causal only to their accuracy, and held above their top frequency
#: (3.4 rad/s): on its default 4-wave record (Hs 1.5 m, Tp 6 s) the replay measured the
#: power to 1.5e-4 but the motion to 3.8e-3 and the speeds to 2.6e-2 (surge), while against
#: the frequency domain with the time-domain model's own coefficients (the memory's A and B,
#: ``replay(...)["model_coefficients"]``, a dense solve of six minutes) to 2.5e-5 and
#: 1.2e-4: the difference is the data's, not the integration's
REPLAY_TOL = {"synthetic": (1e-3, 1e-3, 1e-3), "barge": (1e-3, 1e-2, 5e-2)}
#: the synthetic hull's 100-wave record: solved at the record's cut of the hull's harmonics
#: (``hull_harmonics = harmonics + max(1, K)``, here 2810, 35 rad/s) its hull motion missed
#: the replay's by 1.4e-3 (positions) and 3.3e-2 (speeds) of their largest, all of it at one
#: instant (t = 275.2 s, where the optimum throws the pendulum from near upright down past
#: hanging in 0.4 s, phi'' up to 93 rad/s^2): the hull's response to the pendulum's reaction
#: there (products such as ``sin(phi) phi''``, up to twice phi's harmonics) lies above that
#: cut. The answer's reported motion is therefore the hull re-solved at twice the cut
#: (``parapend.hydro.result.REPORT_HULL_FACTOR``), measured against the replay to 2.4e-4 and
#: 7.1e-4 (at 2.5 ms 2.3e-4 and 4.1e-4; with 120 s of memory instead of 33 s 2.7e-4 and
#: 8.8e-4): inside ``REPLAY_TOL``.


def _hull_resolved(r, pivot, pitch_inertia, factor=2):
    """The record optimum's hull motion (:class:`parapend.hydro.result.MotionAt`) solved
    again by the package at the same phi with ``factor`` times the record's hull harmonics
    (``factor=1``: the record's own, a check that this is the record's problem)."""
    from parapend.hydro.hull import ideal_problem, make_case
    from parapend.hydro.result import MotionAt

    cs = r.motion.case
    case = make_case(r.hydrodynamics, _pendulum_of(r), r.incident_wave, winding=cs.winding,
                     harmonics=cs.harmonics, hull_harmonics=factor * cs.hull_harmonics,
                     pivot=pivot, pitch_inertia=pitch_inertia)
    problem = ideal_problem(case)
    return MotionAt(problem, r.motion.x, problem.solve_hull(r.motion.x))


def _pendulum_of(r) -> Pendulum:
    """The result's pendulum as :class:`parapend.hydro.coupled.Pendulum`."""
    p = r.pendulum
    return Pendulum(p["mass_kg"], p["length_m"], p["inertia_kg_m2"], p["damping_coefficient"])


@pytest.mark.slow
@pytest.mark.parametrize("body, waves", [("synthetic", 4), ("synthetic", 100),
                                         ("barge", 100)])
def test_api_record_optimum_replayed_through_cummins(dataset, body, waves):
    """The record optimum of ``parapend.buoy(dofs="surge,heave,pitch", hs, tp,
    repeat_period=waves Tp, seed=0)`` (the best mode, refined), on the synthetic hull
    (Hs 1 m, Tp 5 s) or the embedded barge (its default sea, Hs 1.5 m, Tp 6 s), its phi
    prescribed to Cummins' equation from rest over repeats of the record: the hull's motion
    and the mean power over the last repeat (``REPLAY_TOL``; synthetic, 4 waves, measured:
    power 1.9e-4 swinging and 2.5e-4 rotating at 10 ms, 8.5e-5 and 9.5e-5 at 5 ms, motion
    below 4e-4; 100 waves: the comment above ``REPLAY_TOL``). The reported motion is the
    package's hull re-solved at the answer's phi with ``REPORT_HULL_FACTOR`` times the
    solve's hull harmonics. A record the solver refuses as too long is skipped, with the
    refusal as the reason."""
    import parapend

    if body == "synthetic":
        opts = dict(hydro=dataset, hs=HS, tp=TP, mass=PEND.mass, length=PEND.length,
                    inertia=PEND.inertia, damping_coefficient=PEND.damping_coefficient,
                    pivot_offset=PIVOT[0], pivot_height=PIVOT[1])
        if waves == 4:  # the best mode there (4863 W against the rotation's 4368 W): half
            opts["winding"] = 0  # the cost; the rotation is replayed above
    else:
        opts = dict(hs=1.5, tp=6.0)
    try:
        r = parapend.buoy(dofs="surge,heave,pitch", repeat_period=waves * opts["tp"], seed=0,
                          **opts)
    except ParameterError as e:
        pytest.skip(f"the record is refused: {e}")
    assert r.success and r.power_w is not None, r.status
    mot = r.motion
    wave = r.incident_wave
    pend = _pendulum_of(r)
    pivot = (r.pivot["pivot_offset_m"], r.pivot["pivot_height_m"])
    hull = r.hydrodynamics
    inertia = hull.pitch_inertia or mot.case.Mh[2, 2]
    td, diff, rel = _replay_check(wave.omega, wave.amplitudes, mot.x, mot.case.winding,
                                  r.power_w, mot, hull, pend, pivot, dt=0.005,
                                  pitch_inertia=inertia)
    if waves * opts["tp"] < 100:  # the repeat before the last holds the ramp in a long record
        assert td["periodicity"] < 1e-4
    tol = REPLAY_TOL[body]
    assert abs(rel) < tol[0], rel
    assert np.all(diff["xi"] < tol[1]), diff
    assert np.all(diff["xi_dot"] < tol[2]), diff
    # the reported motion is the package's hull at the answer's phi with twice the solve's
    # hull harmonics
    assert mot.case.hull_harmonics == REPORT_HULL_FACTOR * r.hull_harmonics
    if body == "synthetic":
        same = chunked(_hull_resolved(r, pivot, inertia, factor=1))(td["t"][::50])
        ref = chunked(mot)(td["t"][::50])
        assert np.max(np.abs(same["xi_dot"] - ref["xi_dot"])) < 1e-9 * np.max(
            np.abs(ref["xi_dot"]))


def _excitation(data, omega, amplitudes):
    """``F_exc(t) = Re sum_k F(k w) a_k exp(i k w t)`` (N, N, N m), the data interpolated
    as the spec says (:func:`hull_timedomain.interpolator`): (m,) -> (m, 3)."""
    coef = interpolator(data["omega"], data["A"], data["B"], data["F"], data["C"])
    amps = np.asarray(amplitudes, dtype=complex)
    fk = np.array([coef(k * omega)[2] for k in range(1, amps.size + 1)]) * amps[:, None]
    ks = np.arange(1, amps.size + 1)

    def force(t):
        return np.real(np.exp(1j * omega * np.outer(np.atleast_1d(t), ks)) @ fk)
    return force


@pytest.mark.parametrize("points", [16, 2048])
def test_motion_on_grid_is_the_trigonometric_sums(short_optimum, points):
    """The answer's motion on a grid of the period by inverse FFTs (``MotionAt.on_grid``,
    what the peaks and amplitudes read) is its direct trigonometric sums at those times to
    rounding (1e-12 of each quantity's size), also on fewer points than harmonics."""
    case, _, _, motion = short_optimum
    period = 2 * math.pi / case.omega
    direct = motion(period * np.arange(points) / points)
    fast = motion.on_grid(points)
    assert set(fast) == set(direct)
    for key, want in direct.items():
        assert np.shape(fast[key]) == np.shape(want)
        np.testing.assert_allclose(fast[key], want, rtol=0,
                                   atol=1e-12 * max(float(np.max(np.abs(want))), 1e-300))


@pytest.mark.slow  # 10 s
def test_record_optimum_torque_reintegrated(short_optimum):
    """The optimum's torque ``tau(t)`` (from (P) on its motion) re-integrated with the
    nonlinear pendulum and the hull, from the optimum's state and past (the memory's
    history the optimum's hull speed), over one repeat in 64 samples, the state reset to
    the optimum's every 4 (a swinging optimum far from hanging is open-loop unstable: a
    difference grows some 2.7 times a second). The plant both ways: the motion stays on the
    optimum's (measured 2e-5 rad, 6e-5 of the hull's motion, 1.3e-4 of its speeds) and the
    harvested energy over the repeat is the optimum's power to 1e-4 (measured 2e-5); what
    is left is the memory model's (its A_inf matched at the record's peak)."""
    case, x, power, motion = short_optimum
    data = hull_data(_hull(), PEND.mass)
    w = case.omega
    kp = int(np.argmax(np.abs(case.amplitudes))) + 1
    mem = memory_length(data["omega"], data["B"], tol=1e-4, longest=40.0)
    data["a_inf"] = matched_a_inf(data["omega"], data["A"], data["B"], kp * w, mem)
    data["memory"] = mem
    period = 2 * math.pi / w
    n = 64
    t = period * np.arange(n + 1) / n
    ref = motion(t)
    states = np.column_stack((ref["xi"].T, ref["phi"], ref["xi_dot"].T, ref["phi_dot"]))
    out = reintegrate_hull(data, PEND, PIVOT, _excitation(data, w, case.amplitudes), t,
                           lambda s: motion(s)["tau"], state0=states[0],
                           history=lambda s: motion(s)["xi_dot"].T, restart=(4, states))
    assert np.max(np.abs(out["phi"] - ref["phi"])) < 1e-4
    assert np.max(np.abs(out["phidot"] - ref["phi_dot"])) < 1e-4 * np.max(
        np.abs(ref["phi_dot"]))
    for key, fd in (("xi", ref["xi"]), ("xidot", ref["xi_dot"])):
        rel = np.max(np.abs(out[key] - fd.T), axis=0) / np.max(np.abs(fd), axis=1)
        assert np.all(rel < 3e-4), (key, rel)
    assert out["energy"][-1] / period == pytest.approx(power, rel=1e-4)


def test_held_torques_independent_of_the_sample_grid():
    """Held torques on the full hull (surge, heave, pitch; the pendulum swinging from 2 rad
    in the record's sea), integrated over 1.2 s on samples of 0.1 s and again on samples of
    0.05 s with each torque held twice as long: the same motion and the same harvested
    energy to the integrator's tolerance (measured 8e-10 of the heave speed, 1.6e-9 of the
    energy): the memory's weights and the past's bookkeeping do not depend on the grid.
    The memory is cut at 0.73 s, inside the run and between samples, so that its truncation
    is exercised (cut at 0.70 s instead, the heave speed moves by 2.5e-3)."""
    data = hull_data(_hull(), PEND.mass)
    wave = _record(SHORT_WAVES)
    data["a_inf"] = matched_a_inf(data["omega"], data["A"], data["B"], 1.2, 0.73)
    data["memory"] = 0.73
    force = _excitation(data, wave.omega, wave.amplitudes)
    tau = 800.0 * np.sin(0.9 * np.arange(12))
    y0 = np.array([0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0])
    runs = []
    for split in (1, 2):
        t = (0.1 / split) * np.arange(12 * split + 1)
        runs.append(reintegrate_hull(data, PEND, PIVOT, force, t, np.repeat(tau, split),
                                     state0=y0))
    a, b = runs
    scale = np.max(np.abs(a["xidot"]), axis=0)
    assert np.all(scale > 0) and np.max(np.abs(a["phi"] - 2.0)) > 0.05
    assert np.all(np.abs(a["xidot"][-1] - b["xidot"][-1]) < 1e-8 * scale)
    assert abs(a["phidot"][-1] - b["phidot"][-1]) < 1e-8 * np.max(np.abs(a["phidot"]))
    assert a["energy"][-1] == pytest.approx(b["energy"][-1], rel=1e-8)
    assert np.max(np.abs(a["energy"])) > 1.0


# --- the heaving buoy's causal run: its saved torques, surge and pitch held ----------------

@pytest.mark.slow  # the closed loop's run and its re-integration, 10 s (more compiling)
def test_buoy_causal_run_reintegrated_as_a_heave_only_hull():
    """The buoy's receding-horizon run (tests/test_buoy_causality.py's short closed loop)
    saves its held torques, heave and angle; :func:`reintegrate_hull` with surge and pitch
    held, the pivot at O and the buoy's heave data in the hull's heave entries (its total
    mass split as ``M_h + m``), the run's A_inf and memory, the free buoy's speed before
    ``t = 0``, the state re-measured at every update: the saved motion, the harvested
    energy, the stored energy's change and the storage-corrected power to 1e-4 of their
    sizes (measured 1.7e-6 m, 9e-6 m/s, 4e-6 rad, 2.4e-5 rad/s, 2e-4 J of 67 J
    harvested, 6e-4 J of 125 J stored, 8e-5 W of 11.4 W: the plant's own second-order
    step, as the buoy's own re-integration found)."""
    from buoy_synthetic import synthetic
    from test_buoy_causality import OPTS, PENDULUM, WAVE

    from parapend.hydro import control as bc

    buoy = synthetic()
    r = bc.buoy_mpc(buoy, PENDULUM, WAVE, **OPTS)
    assert r.success and r.catch_time_s is not None
    s = r.series
    n = s["torque"].size
    nw = buoy.omega.size
    b = np.zeros((nw, 3, 3))
    b[:, 1, 1] = buoy.radiation_damping
    a_inf = np.zeros((3, 3))
    a_inf[1, 1] = r.units["a_inf_kg"]
    mh = buoy.mass - PENDULUM.mass
    data = {"omega": buoy.omega, "B": b, "C": np.diag([0.0, buoy.hydrostatic_stiffness, 0.0]),
            "Mh": np.diag([mh, mh, 1.0]), "g": buoy.g, "a_inf": a_inf,
            "memory": r.units["memory_s"]}
    force = bc.record_force(buoy, WAVE)
    zk, wk = bc.free_motion(buoy, WAVE)

    def heave(v):
        out = np.zeros((np.size(v), 3))
        out[:, 1] = v
        return out
    states = np.array([[0, s["z"][k], 0, s["theta"][k], 0, s["z_dot"][k], 0,
                        s["theta_dot"][k]] for k in range(n + 1)])
    m = int(round(r.update_interval_s / r.dt_s))
    t = r.dt_s * np.arange(n + 1)
    out = reintegrate_hull(
        data, PENDULUM, (0.0, 0.0), lambda v: heave(force(v)), t, s["torque"],
        state0=states[0], dofs=(1,), restart=(m, states),
        history=lambda v: heave(np.real(np.exp(1j * np.multiply.outer(v, wk)) @ (1j * wk * zk))))
    for got, want in ((out["xi"][:, 1], s["z"]), (out["xidot"][:, 1], s["z_dot"]),
                      (out["phi"], s["theta"]), (out["phidot"], s["theta_dot"])):
        assert np.max(np.abs(got - want)) < 1e-4 * np.max(np.abs(want))
    a0 = int(round(r.average_from_s / r.dt_s))
    span = r.t_end_s - r.average_from_s
    work = out["energy"][-1] - out["energy"][a0]
    stored = out["stored"][-1] - out["stored"][a0]
    assert work == pytest.approx(r.harvested_energy_j, rel=1e-4)
    assert stored == pytest.approx(r.stored_energy_change_j, rel=1e-4)
    assert (work + stored) / span == pytest.approx(r.mean_power_w, rel=1e-4)


# --- the hull's causal run (its controller's module, once merged): its saved torques --------

def _a_inf_median(data):
    """``A_inf`` (3, 3): the median over the data's frequencies of the Kramers-Kronig
    estimates (:func:`hull_timedomain.a_infinity_estimates`), per entry: the plant's rule."""
    from hull_timedomain import a_infinity_estimates

    return np.median(a_infinity_estimates(data["omega"], data["A"], data["B"]), axis=0)


def _free_history(data, pend, pivot, omega, amplitudes):
    """The free hull's periodic speed (the pendulum's mass lumped at the pivot), the data
    interpolated as the spec says: ``t`` (m,) -> (m, 3), where a closed loop starts."""
    coef = interpolator(data["omega"], data["A"], data["B"], data["F"], data["C"])
    d, h = pivot
    gm = np.array([[1.0, 0.0, h], [0.0, 1.0, -d]])
    cp = np.array(data["C"], dtype=float)
    cp[2, 2] -= pend.mass * data["g"] * h
    mass = data["Mh"] + pend.mass * gm.T @ gm
    amps = np.asarray(amplitudes, dtype=complex)
    ks = np.arange(1, amps.size + 1)
    vk = np.empty((amps.size, 3), dtype=complex)
    for k in ks:
        a, b, f = coef(k * omega)
        z = -(k * omega) ** 2 * (mass + a) + 1j * k * omega * b + cp
        vk[k - 1] = 1j * k * omega * np.linalg.solve(z, f * amps[k - 1])

    def speed(t):
        return np.real(np.exp(1j * omega * np.outer(np.atleast_1d(t), ks)) @ vk)
    return speed


def _hull_discrepancy(hc, plant_steps):
    """A short closed loop of the hull (the synthetic hull, a 10 s record of two components,
    a warm-up of one peak period, one repeat, 16 torque samples a peak period) and its
    re-integration: the largest difference of the states relative to their sizes, and the
    differences of the harvested energy, of the stored energy's change (over the averaging
    window) and of the storage-corrected power relative to the gross work ``sum |tau_k
    (theta_k+1 - theta_k)|`` (and its mean)."""
    from parapend.hydro.coupled import Wave

    amps = np.zeros(4, complex)
    amps[1], amps[2] = 0.5, 0.25j
    wave = Wave(2 * math.pi / 10.0, amps)
    r = hc.hull_mpc(_hull(), PEND, wave, peak_period=5.0, pivot=PIVOT, horizon=0.5,
                    update_interval=0.125, warmup=1.0, samples=16, plant_steps=plant_steps,
                    memory=6.0, max_iter=15)
    assert r.series["torque"].size > 0 and r.catch_time_s is not None, r.status
    s = r.series
    n = s["torque"].size
    data = hull_data(_hull(), PEND.mass)
    data["a_inf"] = _a_inf_median(data)
    data["memory"] = r.units["memory_s"]
    data["window"] = r.units["memory_window"]
    names = ("x", "z", "beta", "phi", "x_dot", "z_dot", "beta_dot")
    states = np.column_stack([s[k] for k in names] + [s["theta_dot"] + s["beta_dot"]])
    m = int(round(r.update_interval_s / r.dt_s))
    t = r.dt_s * np.arange(n + 1)
    out = reintegrate_hull(data, PEND, PIVOT, _excitation(data, wave.omega, amps), t,
                           s["torque"], state0=states[0], restart=(m, states),
                           history=_free_history(data, PEND, PIVOT, wave.omega, amps))
    got = np.column_stack((out["xi"], out["phi"], out["xidot"], out["phidot"]))
    motion = float(np.max(np.max(np.abs(got - states), axis=0)
                          / np.max(np.abs(states), axis=0)))
    a0 = int(round(r.average_from_s / r.dt_s))
    span = r.t_end_s - r.average_from_s
    gross = float(np.sum(np.abs(out["work"][a0:])))
    work = out["energy"][-1] - out["energy"][a0]
    stored = out["stored"][-1] - out["stored"][a0]
    return (motion, abs(work - r.harvested_energy_j) / gross,
            abs(stored - r.stored_energy_change_j) / gross,
            abs((work + stored) / span - r.mean_power_w) / (gross / span))


@pytest.mark.slow  # two short closed loops and their re-integrations, 25 s
def test_hull_causal_run_reintegrated():
    """The hull's receding-horizon runs save their held torques and the states at the
    samples' ends; :func:`reintegrate_hull` from the run's first state, the free hull's
    speed before ``t = 0``, ``A_inf`` the median of the Kramers-Kronig estimates and the
    run's memory, the state re-measured at every update, gives the saved motion and
    energies to 1e-4: at 16 plant steps a sample (h = Tp / 256) measured 5.3e-5 of the
    states, the harvested energy, the stored energy's change and the storage-corrected
    power to 2e-6 of the gross work (the controller moves energy both ways: the net is
    about 1 % of the gross). The rest is the plant's own step (RK4 with a trapezoidal
    memory, second order): measured 8.3e-4, 2.0e-4, 5.3e-5, 1.1e-5 at 4, 8, 16, 32 steps;
    asserted falling at least 2.5 times from 16 to 32. Skipped until the hull's controller
    (``parapend.hydro.hull_control``) is there."""
    hc = pytest.importorskip("parapend.hydro.hull_control")
    m16, w16, e16, p16 = _hull_discrepancy(hc, 16)
    assert m16 < 1e-4
    assert w16 < 1e-4 and e16 < 1e-4 and p16 < 1e-4
    m32, *_ = _hull_discrepancy(hc, 32)
    assert m32 < m16 / 2.5
