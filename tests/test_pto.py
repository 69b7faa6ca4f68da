"""Physical units and the power take-off: torque limit, efficiency, profiles."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import parapend
from parapend import pto
from parapend.errors import ParameterError
from parapend.optimal.profile import pto_profile
from parapend.units import Units, from_options

# -- units -------------------------------------------------------------------------------


@pytest.mark.parametrize("length,mass,g,inertia", [(1.0, 10.0, 9.81, None),
                                                   (0.37, 2.5, 9.80665, None),
                                                   (2.0, 40.0, 9.81, 200.0)])
def test_units_round_trip(length, mass, g, inertia):
    u = Units(length, mass, g, inertia)
    for f, a, c in [(0.9, 0.09, 3.0), (0.13, 1.7, 0.0)]:
        assert u.frequency(u.omega(f)) == pytest.approx(f, rel=1e-15)
        assert u.amplitude(u.delta(a, f), f) == pytest.approx(a, rel=1e-15)
        assert u.damping_coefficient(u.gamma(c)) == pytest.approx(c, rel=1e-15, abs=1e-300)
    assert u.from_watts(u.to_watts(0.3)) == pytest.approx(0.3, rel=1e-15)
    assert u.from_newton_metres(u.to_newton_metres(5.0)) == pytest.approx(5.0, rel=1e-15)
    # power unit = torque unit / time unit; point mass: m g^1.5 l^0.5
    assert u.power == pytest.approx(u.torque / u.time, rel=1e-15)
    if inertia is None:
        assert u.power == pytest.approx(mass * g**1.5 * length**0.5, rel=1e-14)
        assert u.time == pytest.approx(math.sqrt(length / g), rel=1e-15)


def test_worked_example_hand_calculation():
    """docs/units.md: 1 m, 10 kg, base heave 0.09 m at 0.9 Hz."""
    u = Units(1.0, 10.0)
    assert u.power == pytest.approx(10 * 9.81**1.5, rel=1e-15)  # 307.258 W
    assert u.power == pytest.approx(307.2582, abs=1e-4)
    assert u.omega(0.9) == pytest.approx(2 * math.pi * 0.9 / math.sqrt(9.81), rel=1e-15)
    assert u.omega(0.9) == pytest.approx(1.80546, abs=1e-5)
    assert u.delta(0.09, 0.9) == pytest.approx(-0.293372, abs=1e-6)
    # the paper's case exactly (delta = -0.3, omega = 1.8) on this pendulum: 105.5 W
    r = parapend.optimize(harmonics=24)
    assert u.to_watts(r.power) == pytest.approx(105.53, abs=0.01)
    _, p = from_options(length=1.0, mass=10.0, frequency=0.9, amplitude=0.09)
    r2 = parapend.optimize(harmonics=24, **p)
    assert u.to_watts(r2.power) == pytest.approx(103.51, abs=0.01)


def test_units_bad_input():
    with pytest.raises(ParameterError, match="^length: expected a number > 0"):
        Units(0.0, 1.0)
    with pytest.raises(ParameterError, match="^mass"):
        from_options(length=1.0, frequency=1.0)
    with pytest.raises(ParameterError, match="^amplitude: needs --frequency"):
        from_options(length=1.0, mass=1.0, amplitude=0.1)


# -- derivatives, reductions ----------------------------------------------------------------


def test_reduces_to_core():
    """eta = 1 and a torque limit above the ideal peak give the ideal optimum to 1e-6."""
    ideal = parapend.optimize(gamma=0.03, harmonics=24)
    r = pto.optimize_pto(gamma=0.03, harmonics=24, efficiency=1.0)
    assert r.electrical_power == pytest.approx(ideal.power, abs=1e-6)
    assert r.power == pytest.approx(ideal.power, abs=1e-6)
    r = pto.optimize_pto(gamma=0.03, harmonics=24, torque_limit=1.5 * ideal.peak_torque)
    assert r.power == pytest.approx(ideal.power, abs=1e-6)
    assert r.status == "converged"


def test_torque_limit_feasible_and_monotone():
    ideal = parapend.optimize(gamma=0.03, harmonics=24)
    powers = []
    for tmax in (3.0, 2.0):
        r = pto.optimize_pto(gamma=0.03, harmonics=24, torque_limit=tmax)
        assert r.status == "converged"
        # the motion's own dense evaluation satisfies the limit
        s = parapend.api.motion_samples(r, points=20000)
        assert np.max(np.abs(s["torque"])) <= tmax * (1 + 1e-9)
        assert r.peak_torque <= tmax * (1 + 1e-9)
        powers.append(r.power)
    assert ideal.power >= powers[0] >= powers[1] > ideal.uniform_power * 0.9


def test_profile_energy_balance():
    """harvested - motoring energy per cycle = P * period; peak torque matches the result."""
    r = parapend.optimize(gamma=0.03, harmonics=24)
    exc = r._excitation
    prof = pto_profile(r.motion, exc, r.gamma, points=4096)
    period = exc.period
    assert prof["harvested_energy"] - prof["motoring_energy"] == pytest.approx(
        r.power * period, abs=1e-9)
    assert prof["peak_torque"] == pytest.approx(r.peak_torque, rel=1e-9)
    assert prof["motoring_energy"] > 0  # the ideal optimum motors part of each cycle
    assert np.mean(prof["power"]) == pytest.approx(r.power, abs=1e-10)


def test_efficiency_avoids_motoring():
    ideal = pto.optimize_pto(gamma=0.03, harmonics=24)
    r = pto.optimize_pto(gamma=0.03, harmonics=24, efficiency=0.7)
    assert r.status == "converged"
    assert r.motoring_energy < 1e-3 * ideal.motoring_energy
    # the electrical optimum beats the ideal motion run through the lossy machine
    p = pto_profile(ideal.motion, ideal._excitation, 0.03)["power"]
    assert r.electrical_power > np.mean(np.where(p > 0, 0.7 * p, p / 0.7))


def test_pto_bad_input():
    with pytest.raises(ParameterError, match=r"^torque-limit: expected a number in \[1e-06"):
        pto.optimize_pto(torque_limit=0.0)
    with pytest.raises(ParameterError,
                       match=r"^efficiency-motoring: expected a number in \(0, 1\]"):
        pto.optimize_pto(efficiency_motoring=1.5)
    with pytest.raises(ParameterError, match="^harmonics"):
        pto.optimize_pto(efficiency=0.9, harmonics=500)
    with pytest.raises(ParameterError, match="^vary"):
        pto.pto_curve("mass")


# -- independent formulation: CasADi/IPOPT direct collocation ----------------------------------

CASES = [(0.03, {"torque_limit": 2.5}), (0.05, {"efficiency": (0.7, 0.7)})]
SLOW_CASES = [(g, {"torque_limit": t}) for g in (0.03, 0.05) for t in (3.0, 2.5, 2.0)] + [
    (g, {"efficiency": (e, e)}) for g in (0.03, 0.05) for e in (0.9, 0.7)]


def _cross_check(gamma, kw):
    pytest.importorskip("casadi")
    from casadi_pto import collocate

    exc = parapend.harmonic(-0.3, 1.8)
    eff = kw.get("efficiency")
    r = pto.optimize_pto(gamma=gamma, harmonics=24, torque_limit=kw.get("torque_limit"),
                         efficiency=None if eff is None else eff[0],
                         efficiency_motoring=None if eff is None else eff[1])
    c = collocate(exc, gamma, intervals=150, **kw)
    assert c["status"] == "Solve_Succeeded"
    assert r.success
    # refined (change < 1e-6 at the last doubling) and collocation K = 150 both within
    # ~1e-5 of their limits here
    assert r.electrical_power == pytest.approx(c["electrical_power"], abs=1e-4)


@pytest.mark.slow  # about 2-6 s: the default set stays under 5 minutes
@pytest.mark.parametrize("gamma,kw", CASES)
def test_casadi_cross_check(gamma, kw):
    _cross_check(gamma, kw)


@pytest.mark.slow
@pytest.mark.parametrize("gamma,kw", SLOW_CASES)
def test_casadi_cross_check_all(gamma, kw):
    _cross_check(gamma, kw)


# -- command line ------------------------------------------------------------------------------


def _run(capsys, *args):
    from parapend.cli import main

    code = main(list(args))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_units_json(capsys):
    code, out, _ = _run(capsys, "optimize", "--length", "1", "--mass", "10", "--frequency",
                        "0.9", "--amplitude", "0.09", "--json")
    import json

    d = json.loads(out)
    assert code == 0
    assert d["omega"] == pytest.approx(1.80546, abs=1e-5)
    assert d["power_w"] == pytest.approx(103.51, abs=0.01)
    for k in ("uniform_power_w", "limit_power_w", "peak_torque_nm"):
        assert d[k] > 0


def test_cli_pto_save(capsys, tmp_path):
    f = tmp_path / "m.csv"
    code, out, _ = _run(capsys, "optimize", "--gamma", "0.05", "--efficiency", "0.9",
                        "--save", str(f))
    assert code == 0 and "electrical power" in out
    head = f.read_text().splitlines()[0]
    assert head == ("time,phase,theta,theta_dot,torque,instantaneous_power,"
                    "instantaneous_electrical_power")


@pytest.mark.parametrize("args,name", [
    (("--torque-limit", "-1"), "torque-limit"),
    (("--efficiency", "0"), "efficiency"),
    (("--efficiency-generating", "1.2"), "efficiency-generating"),
    (("--torque-limit-nm", "5"), "torque-limit-nm"),
    (("--frequency", "1"), "length, mass"),
    (("--length", "1", "--mass", "1", "--frequency", "1", "--omega", "2"), "frequency"),
    (("--length", "-1", "--mass", "1"), "length"),
])
def test_cli_bad_input(capsys, args, name):
    code, out, err = _run(capsys, "optimize", *args)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and f"error: {name}:" in err


def test_cli_pto_curve_efficiency(capsys):
    import json

    code, out, _ = _run(capsys, "pto-curve", "--vary", "efficiency", "--points", "2",
                        "--gamma", "0.05", "--json")
    d = json.loads(out)
    assert code == 0
    p = d["electrical_power"]
    assert d["value"] == [1.0, 0.5]
    assert p[0] == pytest.approx(d["unconstrained_power"], abs=1e-6)
    assert p[1] < p[0]


def test_cli_explicit_default_beside_physical_option(capsys):
    """--omega 1.8 (the default's value, typed) contradicts --frequency; omitted it does not."""
    args = ["optimize", "--length", "1", "--mass", "10", "--frequency", "0.9", "--amplitude",
            "0.09"]
    code, _, err = _run(capsys, *args, "--omega", "1.8")
    assert code == 2 and "frequency: give either --frequency or --omega" in err
    code, _, err = _run(capsys, *args, "--gamma", "0", "--damping-coefficient", "1")
    assert code == 2 and "damping-coefficient: give either" in err
    code, out, _ = _run(capsys, *args, "--damping-coefficient", "1")
    assert code == 0 and "power" in out


def test_copper_loss_alone_and_with_a_slack_limit_agree():
    """A copper loss alone goes to the collocation, with a limit above its peak to the
    Hermite method: two discretizations, one optimum (the loss keeps the peak torque
    below 2)."""
    r = pto.optimize_pto(gamma=0.03, copper_loss=0.01)
    h = pto.optimize_pto(gamma=0.03, copper_loss=0.01, torque_limit=2.0)
    assert (r.method, h.method) == ("collocation", "hermite")
    assert r.status == h.status == "converged"
    assert r.peak_torque < 2.0
    assert h.electrical_power == pytest.approx(r.electrical_power, rel=1e-7)
    assert h.electrical_power < h.power  # the loss is subtracted


def test_winding_two_by_both_time_domain_methods():
    """K = 2 turns per forcing period under a torque limit: the Hermite interior point and
    the collocation (lossless: the same problem) are independent discretizations and
    solvers, and they agree after refinement (at gamma = 0.01 with one harmonic a two-turn
    rotation costs power: status no_power, the smallest loss)."""
    a = pto.optimize_pto(gamma=0.01, torque_limit=3.0, winding=2)
    ideal = parapend.optimize(gamma=0.01, winding=2)
    b, _, extra = pto._collocation(ideal._excitation, 0.01, ideal, 3.0, 0.0, None, None)
    assert (a.method, extra["method"]) == ("hermite", "collocation")
    assert a.status == "no_power" and b.status == "converged" and b.electrical_power <= 0
    assert a.winding == 2
    assert a.power == pytest.approx(b.power, abs=1e-6)
    assert a.peak_torque <= 3.0 * (1 + 1e-9) and b.peak_torque <= 3.0 * (1 + 1e-9)


def test_lossless_efficiency_with_a_torque_limit_is_the_torque_limited_optimum(capsys):
    """Efficiency 1 both ways with a torque limit is the torque-limited problem: the same
    method and the same answer as without an efficiency (it went to the collocation, whose
    first mesh stalled off the dynamics at 1.7 times the unlimited optimum, "infeasible").
    Along the efficiency curve the electrical power does not fall as eta rises, and no
    mechanical power exceeds the unlimited optimum."""
    args = {"length": 1.0, "mass": 10.0, "frequency": 0.9, "amplitude": 0.09,
            "damping_coefficient": 0.5}
    unlimited = parapend.optimize(**args)
    limited = parapend.optimize(torque_limit_nm=20.0, **args)
    one = parapend.optimize(torque_limit_nm=20.0, efficiency=1.0, **args)
    assert limited.status == one.status == "converged"
    assert one.method == limited.method == "hermite"
    assert one.power == pytest.approx(limited.power, rel=1e-8)
    assert one.electrical_power == pytest.approx(limited.power, rel=1e-8)
    assert one.efficiency_generating == one.efficiency_motoring == 1.0
    code, out, _ = _run(capsys, "optimize", "--length", "1", "--mass", "10", "--frequency",
                        "0.9", "--amplitude", "0.09", "--damping-coefficient", "0.5",
                        "--torque-limit-nm", "20", "--efficiency", "1", "--json")
    assert code == 0
    assert json.loads(out)["power_w"] == pytest.approx(limited.power_w, rel=1e-8)
    curve = parapend.pto_curve(vary="efficiency", torque_limit_nm=20.0, points=3, **args)
    assert list(curve["status"].values) == ["converged"] * 3
    assert float(curve["power_w"][0]) == pytest.approx(limited.power_w, rel=1e-8)
    ele = curve["electrical_power"].values[::-1]  # eta rising
    assert np.all(np.diff(ele) >= -1e-12)
    assert np.all(curve["power"].values <= unlimited.power * (1 + 1e-9))
    # the collocation agrees on the same problem (an independent discretization), from
    # the first mesh that stalled: a finer mesh is tried before "infeasible"
    b, _, _ = pto._collocation(unlimited._excitation, unlimited.gamma, unlimited,
                               limited.torque_limit, 0.0, None, None)
    assert b.status == "converged"
    assert b.power == pytest.approx(limited.power, rel=1e-5)


def test_efficiency_with_a_small_limit_is_the_constant_brake():
    """Through an efficiency the collocation alone stalled at a 1 N m limit and reported
    "infeasible", while 0.5 N m was feasible: the constant brake is tried as in the
    Hermite path. Its power is the closed-form bound T_max omega of every monotone
    rotation, and it only generates: electrical = eta_g P (``power`` is the electrical
    power through an efficiency, ``mechanical_power`` the mechanical one)."""
    args = {"length": 1.0, "mass": 10.0, "frequency": 0.9, "amplitude": 0.09,
            "damping_coefficient": 0.5}
    r = parapend.optimize(torque_limit_nm=1.0, efficiency=0.9, **args)
    assert r.status == "converged" and r.method == "constant-brake"
    assert r.mechanical_power == pytest.approx(r.torque_limit * r.omega, rel=1e-9)
    assert r.power == r.electrical_power == pytest.approx(0.9 * r.mechanical_power,
                                                          rel=1e-12)
    assert r.power_w == pytest.approx(0.9 * r.mechanical_power_w, rel=1e-12)
    assert r.motoring_energy == pytest.approx(0.0, abs=1e-12)
    assert r.peak_torque <= r.torque_limit * (1 + 1e-9)
