"""The hull (``parapend buoy --dofs surge,heave,pitch``): a headline is an answer or says it
is not (rest when no motion beats 0 W; none, with its reason and exit status 3, past the
radiation bound or unconverged), impossible inputs refused in one line before the BEM,
datasets held to the options' limits, the bound's cut at the data's noise beside the
capture-width limit, and the search's local maxima reported."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr
from hull_timedomain import synthetic_hull_netcdf

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro.bem import HullHydro, _stated_noise, load_hull
from parapend.hydro.result import capture_width_limit, headline_reason
from parapend.hydro.waves import energy_flux

H = ["buoy", "--dofs", "surge,heave,pitch"]
PERIOD = 2 * math.pi / 1.2
ON = ["--mass", "4000", "--length", "1", "--inertia", "5000", "--pivot-height", "1.5",
      "--pivot-offset", "1", "--wave-period", repr(PERIOD)]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return synthetic_hull_netcdf(tmp_path_factory.mktemp("hull") / "hull.nc")


def _refused(capsys, args, *words):
    """One line on stderr, exit 2, naming ``words``."""
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


def _no_bem(monkeypatch):
    """Any BEM run fails the test: a refusal must come before it."""
    from parapend.hydro import bem

    def boom(*a, **k):
        raise AssertionError("the BEM ran")
    monkeypatch.setattr(bem, "_solve_hull", boom)


# -- refusals before the BEM ------------------------------------------------------------------
def test_a_pendulum_at_the_floating_mass_is_refused_before_the_bem(capsys, monkeypatch):
    """The default barge floats rho L B D = 1025 x 10 x 4 x 1 = 41000 kg, the pendulum
    included: 41000 kg is refused (it was solved, 2.4e10 W), 40999 passes the check."""
    _no_bem(monkeypatch)
    err = _refused(capsys, [*H, "--mass", "41000"], "mass:", "41000")
    assert "floating mass" in err
    _refused(capsys, [*H, "--mass", "60000"], "mass:")
    from parapend.hydro.api import _check_fits
    from parapend.hydro.coupled import Pendulum

    geometry = {"body": "barge", "length_m": 10.0, "beam_m": 4.0, "draft_m": 1.0,
                "half_length_m": 5.0}
    _check_fits(Pendulum(mass=40999.0, length=1.0, inertia=40999.0), (0.0, 0.5), geometry)


def test_a_pendulum_longer_than_the_hull_is_refused(capsys, monkeypatch):
    """A 100 m pendulum in a 10 m barge (it was solved at 179.5 degrees of pitch): refused,
    naming the most that fits (half the length less the pivot's offset)."""
    _no_bem(monkeypatch)
    err = _refused(capsys, [*H, "--length", "100"], "length:", "5 m")
    assert "100" in err
    _refused(capsys, [*H, "--length", "4.5", "--pivot-offset", "1"], "length:", "4 m")


@pytest.mark.parametrize("height, period", [(30.0, 4.0), (4.0, 4.0)])
def test_waves_past_breaking_are_refused_before_the_bem(capsys, monkeypatch, height, period):
    """H / lambda above 1/7 (lambda = g T^2 / (2 pi)): 30 m in 4 s is 1.2, 4 m in 4 s 0.16."""
    _no_bem(monkeypatch)
    lam = 9.81 * period**2 / (2 * math.pi)
    err = _refused(capsys, [*H, "--wave-height", f"{height:g}", "--wave-period",
                            f"{period:g}"], "wave-height:", "breaking")
    assert f"{height / lam:.3g}" in err
    assert f"{lam / 7:.4g}" in err  # the largest height that does not break


def test_a_thin_barge_is_refused_by_its_estimate(capsys, monkeypatch):
    """--barge-beam 0.01: panels of radius B / 12 over a 10 x 1 m side, millions of them
    (it ran for minutes); refused naming the smallest beam that fits."""
    from parapend import limits
    from parapend.hydro.api import barge_panels

    _no_bem(monkeypatch)
    err = _refused(capsys, [*H, "--barge-beam", "0.01"], "barge-beam:", "panels")
    least = float(err.rsplit("at least ", 1)[1].split()[0])
    assert barge_panels(10.0, least, 1.0) <= limits.HULL_MAX_BEM_PANELS * 1.01
    assert barge_panels(10.0, 0.99 * least, 1.0) > limits.HULL_MAX_BEM_PANELS
    # the default barge's estimate is near its mesh (412 panels and a lid of 120)
    assert 400 < barge_panels(10.0, 4.0, 1.0) < 640


def test_the_cylinder_hull_s_defaults_hold_the_default_pendulum():
    """``--body cylinder`` (and sphere) with no other option: its own defaults (radius 2 m,
    draft 1 m) hold the default pivot (0.5 m, under the deck) and the 1 m pendulum; the
    heaving buoy's 0.5 m cylinder refused its own pivot height."""
    from parapend.defaults import HULL
    from parapend.hydro.api import _check_fits, _hull_body, _hull_pendulum, _hull_pivot

    for body in ("cylinder", "sphere"):
        _, geometry = _hull_body({"body": body})
        assert geometry["radius_m"] == HULL["radius"]
        pivot = _hull_pivot({}, geometry)
        _check_fits(_hull_pendulum({}), pivot, geometry)


# -- datasets held to the options' limits ---------------------------------------------------
def _edited(dataset, tmp_path, edit, name="bad.nc"):
    ds = xr.load_dataset(dataset)
    edit(ds)
    path = tmp_path / name
    ds.to_netcdf(path)
    return str(path)


def _set_pitch_inertia(value):
    def edit(ds):
        m = ds["inertia_matrix"].values.copy()
        m[2, 2] = value
        ds["inertia_matrix"].values = m
    return edit


def _indefinite_added_mass(ds):
    a = ds["added_mass"].values.copy()
    a[:, 1, 1] = -3.0 * float(ds["inertia_matrix"].values[1, 1])
    ds["added_mass"].values = a


def _moved_centre(ds):
    ds.coords["rotation_center"] = xr.DataArray([0.0, 0.0, -0.5], dims=["space_coordinate"])


@pytest.mark.parametrize("edit, words", [
    (lambda ds: ds.__setitem__("rho", 1e-300), ("rho",)),
    (lambda ds: ds.__setitem__("g", 1e300), ("g in",)),
    (_set_pitch_inertia(1e300), ("inertia",)),
    (_set_pitch_inertia(1e13), ("pitch inertia",)),
    (_indefinite_added_mass, ("added_mass", "positive definite")),
    (_moved_centre, ("rotation_center", "0, 0, -0.5")),
])
def test_datasets_outside_the_options_limits_are_refused(dataset, tmp_path, capsys, edit,
                                                         words):
    """rho 1e-300 (a capture width of 8.6e301 m, success), g 1e300, a pitch inertia of
    1e300 or 1e13 (the option refuses above 1e12), an added-mass matrix that makes the body's
    inertia indefinite (574 W, success) and a rotation centre other than O (ignored): one
    line naming the field, exit 2."""
    path = _edited(dataset, tmp_path, edit)
    _refused(capsys, [*H, "--hydro", path, *ON], "hydro:", *words)
    with pytest.raises(ParameterError):
        load_hull(path)


def test_the_rotation_centre_at_o_is_taken(dataset, tmp_path):
    """A dataset with rotation_center (0, 0, 0), Capytaine's record of it: read as before."""
    path = _edited(dataset, tmp_path, lambda ds: ds.coords.__setitem__(
        "rotation_center", xr.DataArray([0.0, 0.0, 0.0], dims=["space_coordinate"])), "o.nc")
    a, b = load_hull(path), load_hull(dataset)
    np.testing.assert_array_equal(a.radiation_damping, b.radiation_damping)


# -- bounds ------------------------------------------------------------------------------------
def test_the_capture_width_limit_is_three_wavelengths_over_two_pi():
    """Deep water, one harmonic: ``J 3 lambda / (2 pi)`` with ``lambda = g T^2 / (2 pi)``
    and ``J = rho g^2 H^2 T / (32 pi)`` (closed forms); two harmonics add."""
    rho, g, height, period = 1025.0, 9.81, 1.0, 6.0
    w = 2 * math.pi / period
    j = rho * g**2 * height**2 * period / (32 * math.pi)
    lam = g * period**2 / (2 * math.pi)
    got = capture_width_limit(w, [height / 2], rho, g, math.inf)
    assert got == pytest.approx(j * 3 * lam / (2 * math.pi), rel=1e-12)
    two = capture_width_limit(w, [height / 2, 0.1], rho, g, math.inf)
    assert two == pytest.approx(got + capture_width_limit(2 * w, [0.1], rho, g, math.inf),
                                rel=1e-12)
    assert energy_flux(w, [height / 2], rho, g) == pytest.approx(j, rel=1e-12)


def test_the_data_s_noise_is_measured_and_stated():
    """B's asymmetry (relative to its largest entry) is its noise; so is the size of a
    negative eigenvalue set to 0, which the note now states; a cached dataset's notes give it
    back."""
    w = np.array([0.5, 1.0])
    b = np.array([np.diag([1.0, 2.0, 3.0])] * 2)
    b[1, 0, 2], b[1, 2, 0] = 0.03, 0.0  # asymmetry 0.03 / 3 = 0.01
    b[0, 2, 2] = 3.0
    b[0, 0, 0] = -0.006  # a negative eigenvalue, 0.002 of the largest
    kw = dict(omega=w, added_mass=np.array([np.eye(3)] * 2), excitation=np.ones((2, 3)),
              hydrostatic_stiffness=np.diag([0.0, 1.0, 1.0]), mass=10.0)
    h = HullHydro(radiation_damping=b, **kw)
    assert h.damping_noise == pytest.approx(0.01, rel=1e-12)
    note = [n for n in h.notes if "positive semidefinite" in n][0]
    assert "largest correction 0.006" in note and "0.002 of its largest" in note
    assert max(_stated_noise(h.notes)) == pytest.approx(0.002, rel=1e-3)
    again = HullHydro(radiation_damping=h.radiation_damping, notes=(
        "hydro: radiation_damping of the BEM symmetrised (relative asymmetry 0.0093, a "
        "measure of its discretisation error)",), **kw)
    assert again.damping_noise == pytest.approx(0.0093)


def test_the_bound_s_cut_is_the_data_s_noise(dataset):
    """A near-null direction of B at the noise's level is cut: B = diag(1, 1, eps) with the
    force along it; at eps below the noise the bound keeps the two resolved directions only
    (``|F_1|^2 + |F_2|^2) / 8``), at the fixed 1e-8 cut it would add ``|F_3|^2 / (8 eps)``."""
    from parapend.hydro.hull import BOUND_RCOND, bound_error, radiation_bound

    class Case:
        hull_harmonics = 1
        B = np.array([np.zeros((3, 3)), np.diag([1.0, 1.0, 1e-4])])

        def wave_force(self):
            return np.array([np.zeros(3), [1.0, 2.0, 1.0]], dtype=complex)

    fixed, cut0 = radiation_bound(Case(), BOUND_RCOND)
    noisy, cut1 = radiation_bound(Case(), 1e-3)
    assert (cut0, cut1) == (0, 1)
    assert fixed == pytest.approx((1 + 4 + 1e4) / 8, rel=1e-12)
    assert noisy == pytest.approx((1 + 4) / 8, rel=1e-12)
    # its error: each kept term moved by noise x sigma_max over its sigma (here 1e-3 each)
    assert bound_error(Case(), 1e-3) == pytest.approx(1e-3 * (1 + 4) / 8, rel=1e-12)
    assert bound_error(Case(), 0.5) == pytest.approx(0.5 * (1 + 4) / 8, rel=1e-12)


# -- a headline is an answer or says why not --------------------------------------------------
def _mode(name, power, ok=True, status="converged"):
    return {"mode": name, "power_w": power, "success": ok, "status": status}


def test_headline_reason_rules():
    """Rest answers when a mode converged and none beats 0 W; none converged: no answer
    (0 W only a lower bound); an unconverged best, or a power above the bound beyond 0.1 %,
    no answer; a converged power within the bound, the answer."""
    rot, swing = _mode("rotation", -1277.0), _mode("swinging", 50.0)
    assert headline_reason([rot], rot, 0.0, 1e5, True) is None
    failed = _mode("rotation", math.nan, False, "no motion found")
    assert "lower bound" in headline_reason([failed], failed, 0.0, 1e5, True)
    assert headline_reason([rot, swing], swing, 50.0, 1e5, False) is None
    assert headline_reason([swing], swing, 1e5 * 1.0009, 1e5, False) is None
    over = headline_reason([swing], swing, 2.4e10, 2.14e5, False)
    assert "radiation bound" in over and f"{2.4e10 / 2.14e5:.4g}" in over
    bad = _mode("swinging", 4.85e7, False, "no start converged (best: aliased)")
    assert "did not converge" in headline_reason([bad], bad, 4.85e7, 2.14e5, False)


def test_exit_status_3_and_a_null_headline(monkeypatch, capsys):
    """The CLI prints a result without a resolved answer (power none, the reason) and exits
    with status 3; JSON: power_w null, headline_reason a string."""
    from parapend.cli import buoy as cli_buoy
    from parapend.hydro.result import BuoyResult

    r = BuoyResult(power_w=None, headline_reason="the rotation's 2.4e10 W is 1.1e5 times the "
                   "radiation bound", dofs=["surge", "heave", "pitch"], mode="rotation",
                   modes=[], success=False, status="rotation: converged")

    class A:
        save = plot = None
        json = True
    out = cli_buoy._hull_output(r, A())
    from parapend.cli._common import EXIT_UNRESOLVED, Unresolved

    assert isinstance(out, Unresolved) and EXIT_UNRESOLVED == 3
    assert out.out["power_w"] is None and "radiation bound" in out.out["headline_reason"]


@pytest.mark.slow
def test_rest_is_the_answer_when_no_motion_beats_it(dataset, capsys):
    """A single winding that only costs (a damping of 1e5 N m s/rad, the pendulum driven
    round once a wave): the rotation's power is negative, rest (0 W) is the answer, success,
    exit 0 (it was named best at a negative power)."""
    args = [*H, "--hydro", dataset, *ON, "--winding", "1", "--damping-coefficient", "1e5",
            "--json"]
    assert main(args) == 0
    d = json.loads(capsys.readouterr().out)
    rot = [m for m in d["modes"] if m["mode"] == "rotation"][0]
    assert rot["power_w"] < 0
    assert (d["mode"], d["power_w"], d["success"], d["headline_reason"]) == (
        "rest", 0.0, True, None)


@pytest.mark.slow
def test_the_search_s_maxima_and_the_bounds_beside_the_answer(dataset):
    """The synthetic hull's swinging answer: its local maxima (count and powers, the best
    the answer's within its refinement), the answer within the radiation bound, the bound
    and the capture-width limit reported, its noise-aware cut stated."""
    r = parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, mass=4000.0, length=1.0,
                      inertia=5000.0, pivot_height=1.5, pivot_offset=1.0,
                      wave_period=PERIOD, winding=0)
    assert r.maxima == len(r.maxima_powers_w) >= 1
    assert r.maxima_powers_w == sorted(r.maxima_powers_w, reverse=True)
    assert r.maxima_powers_w[0] == pytest.approx(r.power_w, rel=1e-3)
    assert 0 < r.power_w <= r.radiation_bound_w
    flux_limit = capture_width_limit(2 * math.pi / PERIOD, [0.5], 1025.0, 9.81, math.inf)
    assert r.capture_width_limit_w == pytest.approx(flux_limit, rel=1e-12)
    assert r.bound_rcond >= 1e-8


@pytest.mark.slow
@pytest.mark.parametrize("args, code, mode", [
    (["--winding", "5"], 0, "rest"),
    (["--damping-coefficient", "0", "--winding", "0"], 3, "swinging"),
    (["--torque-limit", "1"], 3, "rest"),
])
def test_the_barge_s_reproductions(capsys, args, code, mode):
    """The default barge: ``--winding 5`` (a rotation at -1277 W was named best over rest):
    rest, 0 W, success; ``--damping-coefficient 0 --winding 0`` (4.85e7 W, 226 times the
    bound) and ``--torque-limit 1`` (best "rotation", power NaN): no resolved answer, the
    power null with its reason, exit status 3."""
    assert main([*H, *args, "--json"]) == code
    d = json.loads(capsys.readouterr().out)
    assert d["mode"] == mode
    if code == 0:
        assert (d["power_w"], d["success"], d["headline_reason"]) == (0.0, True, None)
        assert all(m["power_w"] <= 0 for m in d["modes"])
    else:
        assert d["power_w"] is None and d["success"] is False
        assert d["headline_reason"] and d["bound_fraction"] is None


def test_a_time_limit_for_one_hull_wave_is_refused(capsys, monkeypatch):
    """One wave's work is bounded by its harmonics: --time-limit needs a period sweep."""
    _no_bem(monkeypatch)
    _refused(capsys, [*H, "--time-limit", "10"], "time-limit:", "period sweep")


@pytest.mark.slow
def test_a_hull_sweep_stops_at_its_time_limit(dataset):
    """A period sweep under a time limit already past after its first period: the first
    period solved (the same power as alone), the others NaN with the status time_limit, no
    success, a note saying so."""
    kw = dict(dofs="surge,heave,pitch", hydro=dataset, mass=4000.0, length=1.0,
              inertia=5000.0, pivot_height=1.5, pivot_offset=1.0, winding=1)
    r = parapend.buoy(**kw, wave_period="5,5.5,6", time_limit=0.01)
    alone = parapend.buoy(**kw, wave_period=5.0)
    assert r.power_w[0] == pytest.approx(alone.power_w, rel=1e-12)
    assert np.isnan(r.power_w[1:]).all()
    assert r.status[1:] == ["time_limit", "time_limit"] and r.success is False
    assert any("time limit reached: 1 of 3" in w for w in r.warnings)


def test_the_ends_check_of_a_dataset_uses_its_hydrostatics():
    """With --hydro the hull's draft and half-length come from its hydrostatics as a
    wall-sided box: a box L x B x D floating at D has C33 = rho g L B, C55 ~ rho g B L^3 / 12
    and M = rho L B D, so they give back D and L / 2."""
    from parapend.hydro.result import _ends

    rho, g, length, beam, draft = 1025.0, 9.81, 10.0, 4.0, 1.0

    class Box:
        mass = rho * length * beam * draft
        hydrostatic_stiffness = np.diag([0.0, rho * g * length * beam,
                                         rho * g * beam * length**3 / 12])
    Box.g = g
    d, half, how = _ends(Box(), None)
    assert d == pytest.approx(draft, rel=1e-12) and half == pytest.approx(length / 2, rel=1e-12)
    assert "estimate" in how
    assert _ends(Box(), {"draft_m": 2.0, "half_length_m": 3.0}) == (2.0, 3.0, "")


@pytest.mark.slow
def test_the_barge_in_a_steep_wave():
    """The barge at H 5 m, T 5 s (steepness 0.128: below breaking, above 1/20): an answer
    within the radiation bound (a user's barge was named best at 1.59e10 W), with the
    steepness warned about."""
    r = parapend.buoy(dofs="surge,heave,pitch", wave_height=5.0, wave_period=5.0)
    assert r.headline_reason is None and r.success
    assert 0 <= r.power_w <= r.radiation_bound_w * (1 + 1e-3)
    lam = 9.81 * 25 / (2 * math.pi)
    assert any(f"{5 / lam:.3g}" in w and "1/20" in w for w in r.validity_warnings)


def test_periods_outside_the_barge_s_grid_are_refused_before_the_bem(capsys, monkeypatch):
    """The barge's own grid (panel radius min(L, B) / 12 = 1/3 m) resolves waves down to
    12 panel radii, 4 m (deep water: T = sqrt(2 pi 4 / g) = 1.601 s): a 1 s wave is refused
    before the BEM, naming the range."""
    from parapend.hydro.bem import body_frequencies

    _no_bem(monkeypatch)
    top = float(body_frequencies(4.0 / 12)[-1])
    assert 2 * math.pi / top == pytest.approx(math.sqrt(2 * math.pi * 4.0 / 9.81), rel=1e-6)
    err = _refused(capsys, [*H, "--wave-period", "1", "--wave-height", "0.1"],
                   "wave-period:", f"{2 * math.pi / top:.4g} s to 100 s")
    assert "1 s lies" in err


@pytest.mark.slow
def test_a_result_without_an_answer_is_written_in_every_format(tmp_path):
    """The unresolved answer (the swinging search aliased at c = 0) is saved as NetCDF,
    JSON, CSV and a figure, its power none there too."""
    r = parapend.buoy(dofs="surge,heave,pitch", damping_coefficient=0.0, winding=0)
    assert r.power_w is None and r.headline_reason
    for ext in ("nc", "json", "csv", "png"):
        r.save(tmp_path / f"x.{ext}")
    assert json.loads((tmp_path / "x.json").read_text())["power_w"] is None


def test_a_sweep_with_an_unresolved_period_exits_3(capsys):
    """A period sweep carries each period's headline_reason beside its status; one period
    without a resolved answer makes the command exit with status 3, as that period alone
    does; a sweep where every period is resolved exits 0."""
    from parapend.cli import buoy as cli_buoy
    from parapend.cli._common import Unresolved
    from parapend.hydro.result import BuoyResult, BuoySweepResult

    common = dict(dofs=["surge", "heave", "pitch"], mode="rotation", modes=[],
                  pendulum={"mass_kg": 2000.0, "length_m": 1.0, "inertia_kg_m2": 2000.0,
                            "damping_coefficient": 50.0}, body={"description": "a barge"},
                  pivot={"pivot_height_m": 0.5, "pivot_offset_m": 0.0})
    ok = BuoyResult(power_w=50.0, headline_reason=None, success=True,
                    status="rotation: converged", **common)
    bad = BuoyResult(power_w=None, headline_reason="the rotation's 2.4e10 W is 1.1e5 times "
                     "the radiation bound", success=False, status="rotation: converged",
                     warnings=["no resolved answer: the rotation's 2.4e10 W ..."], **common)

    class A:
        save = plot = None
        json = True
    mixed = BuoySweepResult.from_results([5.0, 6.0], [ok, bad], 1.0)
    out = cli_buoy._hull_output(mixed, A())
    assert isinstance(out, Unresolved)
    assert out.out["headline_reason"] == [None, bad.headline_reason]
    assert out.out["status"] == [ok.status, bad.status] and out.out["success"] is False
    assert out.out["power_w"] == [50.0, None]
    both = BuoySweepResult.from_results([5.0, 6.0], [ok, ok], 1.0)
    assert not isinstance(cli_buoy._hull_output(both, A()), Unresolved)
    A.json = False
    text = cli_buoy._hull_output(mixed, A()).out
    assert "power: none at T = 6 s, no resolved answer" in text


@pytest.mark.slow
def test_the_barge_s_unresolved_period_in_a_sweep_exits_3(capsys):
    """The default barge undamped and swinging (4.85e7 W, 226 times the bound at 6 s: no
    resolved answer alone, exit 3) in a sweep over 6 and 7 s: exit 3 too (it was 0), the
    6 s period's reason the same as alone."""
    args = [*H, "--damping-coefficient", "0", "--winding", "0", "--json"]
    assert main(args) == 3
    alone = json.loads(capsys.readouterr().out)
    assert main([*args, "--wave-period", "6,7"]) == 3
    d = json.loads(capsys.readouterr().out)
    assert d["headline_reason"][0] == alone["headline_reason"]
    assert len(d["status"]) == len(d["headline_reason"]) == 2 and d["success"] is False


def test_a_power_above_the_capture_width_limit_is_no_answer():
    from parapend.hydro.result import bound_note

    swing = {"mode": "swinging", "success": True, "status": "converged"}
    # within both: the answer; above the limit (but within a bound inflated by B's noise)
    assert headline_reason([swing], swing, 5e4, 2.1e5, False, limit=1.58e5) is None
    why = headline_reason([swing], swing, 2e5, 2.1e5, False, limit=1.58e5)
    assert "capture-width limit 1.58e+05 W" in why and f"{2e5 / 1.58e5:.4g} times" in why
    # the bound's own warning: above the limit by more than its error only
    assert bound_note(1.5e5, 2e3, 1.58e5) is None
    assert bound_note(1.59e5, 2e3, 1.58e5) is None
    note = bound_note(4.49e6, 0.04, 1.58e5)
    assert note.startswith("radiation bound: 4.49e+06 W is 28.4 times the capture-width")


@pytest.mark.slow
def test_the_default_barge_s_bounds_bound():
    """The default barge (412 panels, the noise cut): the power within the radiation bound,
    the bound within the capture-width limit ``J 3 lambda / (2 pi)`` (a theorem for exact
    coefficients: 155 kW under 158 kW at 6 s, 718 kW under 731 kW at 10 s), no warning;
    the same coefficients written as a dataset (their noise no longer stated, the cut
    1e-8) give a bound 1.4 and 3.5 times the limit: warned, and the answer unchanged."""
    from parapend.hydro import bem

    h = bem.barge(10.0, 4.0, 1.0, omega="body")
    for period in (6.0, 10.0):
        r = parapend.buoy(dofs="surge,heave,pitch", wave_period=period)
        assert r.headline_reason is None and 0 < r.power_w <= r.radiation_bound_w
        assert r.radiation_bound_w <= r.capture_width_limit_w + r.bound_error_w
        assert not any("times the capture-width limit" in w for w in r.warnings)
        d = parapend.buoy(dofs="surge,heave,pitch", wave_period=period, hydro=h.to_dataset())
        assert d.bound_rcond == 1e-8 and d.radiation_bound_w > 1.3 * d.capture_width_limit_w
        assert any(w.startswith("radiation bound: ") and "capture-width limit" in w
                   for w in d.warnings)
        assert d.power_w == pytest.approx(r.power_w, rel=1e-6) and d.headline_reason is None
