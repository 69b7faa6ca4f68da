"""A hull's sea state over seeded realizations and the power matrix's statistics.

``parapend buoy --dofs surge,heave,pitch --hs --tp --realizations R``: each realization is the
record ``buoy`` solves alone with that seed (the solve replaced by a stand-in that is a
function of the record: the plumbing, fast; the real solver, slow), the interval is
``scipy.stats.t``'s computed here independently; the power matrix's bins' intervals, the
annual energy's interval (paired over the common seeds) and the generator's rating per bin
and over the site, against sums done here; the bearing load against a finite difference of
the motion. The hull is the synthetic one of tests/test_power_matrix_hull.py."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats
from test_power_matrix_hull import BINS, HULL, PEND, _save

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro import api as hull_api
from parapend.hydro.result import BuoyResult
from parapend.performance import HOURS_PER_YEAR, power_matrix
from parapend.performance.spec import FAILURES

DOFS = "surge,heave,pitch"
#: the real solve (its checks kept by the stand-ins)
_REAL = hull_api.solve_record
#: the real solve (its checks kept by the stand-ins)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return _save(tmp_path_factory.mktemp("hull") / "hull.nc")


def _record_numbers(wave):
    """Numbers that depend on the record's amplitudes and phases (so on its seed)."""
    a = np.asarray(wave.amplitudes)
    k = np.arange(1, a.size + 1)
    e = float(np.sum(np.abs(a) ** 2))
    phase = float(np.sum(k * a.real) / np.sum(np.abs(a)))
    return e, phase


def _stand_in(real, fail=None):
    """``solve_record`` with the checks real and the solve replaced by a BuoyResult whose
    power, peak torque and bearing load are functions of the record; ``fail(wave)`` true: the
    record has no resolved answer."""

    def fake(problem, wave, info, *, check_only=False):
        if check_only:
            return real(problem, wave, info, check_only=True)
        e, ph = _record_numbers(wave)
        bad = fail is not None and fail(wave)
        p = 1e4 * e * (1.5 + math.tanh(ph))
        return BuoyResult(power_w=None if bad else p, mechanical_power_w=None if bad else p,
                          headline_reason=("the best mode (rotation) did not converge: "
                                           "not resolved: 256 harmonics still change the "
                                           "power by 79 W") if bad else None,
                          peak_torque_nm=2.0 * p, peak_pivot_force_n=3.0 * p + 1e4,
                          mode="rotation", success=not bad, modes=[],
                          radiation_bound_w=1e6 * e, one_way_power_w=0.5 * p,
                          status="rotation: converged", warnings=[],
                          surge_amplitude_m=0.1, heave_amplitude_m=0.2,
                          pitch_amplitude_deg=1.0, mean_heel_deg=0.0, harmonics=24,
                          hull_harmonics=26, maxima=1, maxima_powers_w=[p],
                          pendulum={"mass_kg": 4e3, "length_m": 1.0, "inertia_kg_m2": 5e3,
                                    "damping_coefficient": 50.0},
                          body={"description": "stand-in"},
                          pivot={"pivot_height_m": 1.5, "pivot_offset_m": 1.0},
                          dofs=["surge", "heave", "pitch"],
                          wave=dict(info, omega_rad_per_s=wave.omega))
    return fake


@pytest.fixture
def stand_in(monkeypatch):
    monkeypatch.setattr(hull_api, "solve_record", _stand_in(_REAL))


SEA = {"hs": 1.0, "tp": 6.0, "repeat_period": 12.0, "seed": 3}


def test_the_interval_is_students_t_over_records_each_buoy_alone(dataset, stand_in,
                                                                  tmp_path):
    """Each realization's power is what ``buoy`` alone says of the record with that seed;
    the mean and its 95 % interval are scipy.stats.t's over those powers."""
    r = parapend.buoy(dofs=DOFS, hydro=dataset, **SEA, realizations=4, **PEND)
    alone = [parapend.buoy(dofs=DOFS, hydro=dataset, **{**SEA, "seed": 3 + k}, **PEND)
             for k in range(4)]
    assert r.realization_seeds == [3, 4, 5, 6]
    assert r.realization_powers_w == [a.power_w for a in alone]
    assert r.realization_peak_torques_nm == [a.peak_torque_nm for a in alone]
    assert r.realization_peak_pivot_forces_n == [a.peak_pivot_force_n for a in alone]
    assert len(set(r.realization_powers_w)) == 4  # the seeds differ
    p = np.array(r.realization_powers_w)
    lo, hi = stats.t.interval(0.95, df=3, loc=p.mean(), scale=stats.sem(p))
    assert r.mean_power_w == pytest.approx(p.mean(), rel=1e-14)
    assert r.power_ci_w == pytest.approx([lo, hi], rel=1e-12)
    assert r.power_std_w == pytest.approx(np.std(p, ddof=1), rel=1e-12)
    assert r.power_w == alone[0].power_w and r.realizations_solved == 4
    d = r.to_dict()
    assert d["power_ci_w"] == pytest.approx([lo, hi], rel=1e-12)
    assert "Student t" in d["power_ci_method"]
    ds = r.to_dataset()
    assert ds["seed"].values.tolist() == [3, 4, 5, 6]
    assert np.array_equal(ds["realization_powers_w"].values, p)
    assert ds["power_ci_low_w"].attrs["units"] == "W"
    assert float(ds["power_ci_high_w"]) == pytest.approx(hi, rel=1e-12)
    rows = r.save(tmp_path / "r.csv").read_text().splitlines()
    assert rows[0].startswith("realization,realization_powers_w") and len(rows) == 2 + 4
    assert float(rows[3].split(",")[1]) == p[1]


def test_an_unresolved_record_is_left_out_and_named(dataset, monkeypatch):
    """A record without a resolved answer is null in the list, named with its reason, and
    the mean and interval are over the others."""
    from parapend.units import Units

    units = Units(PEND["length"], PEND["mass"], 9.81, PEND["inertia"])
    phases = {}
    for s in range(10, 16):
        w, _ = hull_api._irregular_wave(1.0, 6.0, "jonswap", 3.3, 12.0, s, 3.0, None, 0.1,
                                        units)
        phases[s] = _record_numbers(w)[1]
    cut = sorted(phases.values())[1]  # the lowest one fails
    monkeypatch.setattr(hull_api, "solve_record",
                        _stand_in(_REAL, fail=lambda w: _record_numbers(w)[1] < cut))
    r = parapend.buoy(dofs=DOFS, hydro=dataset, **{**SEA, "seed": 10}, realizations=6,
                      time_limit=3600, **PEND)
    bad = [i for i, p in enumerate(r.realization_powers_w) if math.isnan(p)]
    assert len(bad) == 1 and r.realizations_solved == 5
    assert "not resolved" in r.realization_reasons[bad[0]]
    good = np.array([p for p in r.realization_powers_w if not math.isnan(p)])
    lo, hi = stats.t.interval(0.95, df=4, loc=good.mean(), scale=stats.sem(good))
    assert r.power_ci_w == pytest.approx([lo, hi], rel=1e-12)
    assert any("left out of the mean" in w for w in r.warnings)
    assert r.to_dict()["realization_powers_w"][bad[0]] is None


def test_a_time_limit_gives_a_marked_partial_result(dataset, stand_in, monkeypatch):
    """Past the time limit no realization is begun: the ones finished, marked time_limit."""
    import parapend.deadline as dl

    monkeypatch.setattr(dl, "expired", lambda when: when is not None)
    r = parapend.buoy(dofs=DOFS, hydro=dataset, **SEA, realizations=50, time_limit=5,
                      **PEND)
    assert r.status == "time_limit" and r.success is False
    assert r.realization_seeds == [3] and r.power_ci_w is None
    assert any("PARTIAL" in w for w in r.warnings)


@pytest.mark.parametrize("kw, match", [
    ({"realizations": 0}, r"^realizations: expected"),
    ({"realizations": 2.5}, r"^realizations: "),
    ({"realizations": 1000}, r"^realizations: 1000 hull records .* --realizations at most"),
    # an efficiency's record priced at its own cost (minutes a peak period): one is past
    # the untimed cap
    ({"realizations": 1, "efficiency": 0.9}, r"^realizations: 1 hull records .* shorter"),
    ({"realizations": 1, "efficiency": "0.8,x"}, r"^efficiency: expected"),
    ({"realizations": 2, "dofs": "heave", "hydro": None}, r"^realizations: .*hull"),
    ({"realizations": 2, "hs": None, "tp": None, "repeat_period": None, "seed": None},
     r"^realizations: needs an irregular sea"),
])
def test_refusals_in_one_line(kw, match, dataset):
    opts = {"dofs": DOFS, "hydro": dataset, **SEA, **PEND, **kw}
    if opts["dofs"] == "heave":
        opts = {k: v for k, v in opts.items() if k not in ("pivot_height", "pivot_offset")}
    with pytest.raises(ParameterError, match=match):
        parapend.buoy(**opts)


def test_the_command_line(dataset, stand_in, capsys):
    """--realizations: the JSON's keys, the text's table and interval, exit 2 on bad input."""
    args = ["buoy", "--dofs", DOFS, "--hydro", dataset, "--hs", "1", "--tp", "6",
            "--repeat-period", "12", "--seed", "3", "--realizations", "3",
            *(x for k, v in PEND.items() for x in (f"--{k.replace('_', '-')}", repr(v)))]
    assert main([*args, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    p = np.array(out["realization_powers_w"])
    assert out["realization_seeds"] == [3, 4, 5]
    assert out["power_ci_w"] == pytest.approx(
        list(stats.t.interval(0.95, df=2, loc=p.mean(), scale=stats.sem(p))), rel=1e-12)
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "mean power over 3 of 3 realizations" in text and "Student t, 2 degrees" in text
    bad = list(args)
    bad[bad.index("--realizations") + 1] = "0"
    assert main(bad) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "realizations" in err[0]


# -- the power matrix ------------------------------------------------------------------------

@pytest.fixture(scope="module")
def scatter(tmp_path_factory):
    path = tmp_path_factory.mktemp("site") / "scatter.csv"
    rows = [(1, 5, 0.4), (1, 6, 0.3), (2, 5, 0.2), (2, 6, 0.1)]
    path.write_text("hs,tp,frequency\n" + "".join(f"{h},{t},{f}\n" for h, t, f in rows))
    return str(path), np.array([[0.4, 0.3], [0.2, 0.1]])


def test_the_matrix_bins_intervals_and_the_annual_energys(dataset, scatter, stand_in,
                                                          tmp_path):
    """Each bin's interval is scipy's t-interval of its stored powers; the annual energy's
    (paired: realization r has the same seed in every bin) is the t-interval of the annual
    energies of the realizations, summed here; the peaks per bin are the largest of the
    records' and the site's the largest of the bins'; all in the NetCDF too."""
    import xarray as xr

    path, f = scatter
    nc = str(tmp_path / "m.nc")
    ds, annual, _, _ = power_matrix(**BINS, realizations=3, hydro=dataset, scatter=path,
                                    workers=1, time_limit=3600, netcdf=nc, **HULL)
    p = ds["power"].values
    for i in range(2):
        for j in range(2):
            lo, hi = stats.t.interval(0.95, df=2, loc=p[i, j].mean(), scale=stats.sem(p[i, j]))
            assert ds["power_ci_low"].values[i, j] == pytest.approx(lo, rel=1e-12)
            assert ds["power_ci_high"].values[i, j] == pytest.approx(hi, rel=1e-12)
    per = [HOURS_PER_YEAR * float(np.sum(f * p[:, :, r])) / 1e6 for r in range(3)]
    lo, hi = stats.t.interval(0.95, df=2, loc=np.mean(per), scale=stats.sem(per))
    want = (max(lo, 0.0), hi)  # the annual energy is never negative
    a = annual["power"]
    assert a["mwh"] == pytest.approx(np.mean(per), rel=1e-12)
    assert a["mwh_ci"] == pytest.approx(list(want), rel=1e-10)
    assert a["ci_method"].startswith("paired")
    assert ds["peak_torque_max"].values == pytest.approx(2 * p.max(axis=-1), rel=1e-14)
    assert ds["peak_torque"].attrs["units"] == "N m"
    from parapend.commands import power_matrix as cmd

    rec = cmd(**BINS, realizations=3, hydro=dataset, scatter=path, workers=1,
              time_limit=3600, **HULL)
    out = rec.to_dict() if hasattr(rec, "to_dict") else rec
    assert out["site_peak_pivot_force_n"] == pytest.approx(3 * p.max() + 1e4, rel=1e-14)
    assert out["bin_failures"] == []
    back = xr.open_dataset(nc)
    try:
        assert np.allclose(back["power_ci_low"].values, ds["power_ci_low"].values)
        assert back.attrs["annual_energy_mwh_ci"] == pytest.approx(list(want), rel=1e-10)
        assert back["peak_pivot_force_max"].attrs["units"] == "N"
    finally:
        back.close()


def test_an_unresolved_bin_says_why_and_stays_out_of_the_aep(dataset, scatter, monkeypatch,
                                                             capsys):
    """A record without a resolved answer: its reason code per realization and per bin, the
    JSON's list and the text's line; a bin with none solved is out of the annual energy,
    whose completeness is the share of the year counted."""
    from parapend.performance.buoy_device import wave_of

    path, f = scatter
    # the records of the bin (Hm0 2 m, Tp 6 s) fail: its period and its energy single it out
    spec = parapend.performance.matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL)
    e = {(i, j): _record_numbers(wave_of(spec, i, j, 0)[0])[0] for i in range(2)
         for j in range(2)}
    cut = 0.5 * (e[(0, 1)] + e[(1, 1)])

    def fail(wave):
        return abs(2 * math.pi / wave.omega - 12.0) < 1e-6 and _record_numbers(wave)[0] > cut
    monkeypatch.setattr(hull_api, "solve_record", _stand_in(_REAL, fail=fail))
    args = ["power-matrix", "--device", "buoy", "--dofs", DOFS, "--hydro", dataset,
            "--hs", "1,2", "--tp", "5,6", "--waves", "2", "--seed", "3", "--realizations",
            "1", "--workers", "1", "--scatter", path, "--time-limit", "3600",
            *(x for k, v in PEND.items() for x in (f"--{k.replace('_', '-')}", repr(v)))]
    assert main([*args, "--json"]) == 3  # incomplete: no plain annual energy
    out = json.loads(capsys.readouterr().out)
    assert out["bin_failures"] == [{"hm0": 2.0, "tp": 6.0, "failed": 1, "realizations": 1,
                                    "reasons": ["harmonics unresolved"], "frequency": 0.1}]
    a = out["annual_energy"]["power"]
    assert a["complete"] is False
    assert a["counted_frequency"] == pytest.approx(0.9, rel=1e-12)
    assert out["peak_torque_nm"][1][1] is None
    main(args)
    text = capsys.readouterr().out
    assert "bin Hm0 2 m, tp 6 s: 1 of 1 records without a resolved answer (harmonics " \
           "unresolved)" in text
    assert "the bins counted hold 90 % of the year's hours" in text
    assert FAILURES[2] == "harmonics unresolved"


def test_a_bin_is_what_buoy_alone_answers_and_an_unresolved_one_is_retried(dataset,
                                                                           monkeypatch):
    """A record whose best mode is resolved while another mode did not converge is solved
    (buoy alone answers it: the matrix stored it as 'other' before); a record left
    unresolved is solved once more with more harmonics, and that answer kept."""
    from parapend.hydro.hull import HARMONICS_PER_TURN, waves_in
    from parapend.performance.buoy_device import wave_of
    from parapend.performance.hull_device import RETRY_HARMONICS

    spec = parapend.performance.matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL)
    low = _record_numbers(wave_of(spec, 0, 0, 0)[0])[0]  # Hm0 1 m, Tp 5 s
    calls = []

    def fake(problem, wave, info, *, check_only=False):
        if check_only:
            return _REAL(problem, wave, info, check_only=True)
        res = _stand_in(_REAL)(problem, wave, info)
        calls.append(problem["harmonics"])
        e, _ = _record_numbers(wave)
        if abs(2 * math.pi / wave.omega - 12.0) < 1e-6:  # Tp 6 s: swinging did not converge
            import dataclasses

            return dataclasses.replace(res, success=False,
                                       status="rotation: converged; swinging: stalled")
        if problem["harmonics"] is None and e > 2 * low:  # Tp 5 s, Hm0 2 m: unresolved first
            return _stand_in(_REAL, fail=lambda w: True)(problem, wave, info)
        return res
    monkeypatch.setattr(hull_api, "solve_record", fake)
    ds, _, _, _ = power_matrix(**BINS, realizations=1, hydro=dataset, workers=1,
                               time_limit=3600, **HULL)
    assert (ds["status"].values == 0).all() and (ds["failure"].values == 0).all()
    n = HARMONICS_PER_TURN * waves_in(wave_of(spec, 1, 0, 0)[0])
    more = int(math.ceil(RETRY_HARMONICS * n / 2)) * 2
    assert [c for c in calls if c is not None] == [more]
    for hs, tp, i, j, h in ((1.0, 6.0, 0, 1, None), (2.0, 6.0, 1, 1, None),
                            (1.0, 5.0, 0, 0, None), (2.0, 5.0, 1, 0, more)):
        alone = parapend.buoy(dofs=DOFS, hydro=dataset, hs=hs, tp=tp, repeat_period=2 * tp,
                              seed=3, harmonics=h, **PEND)
        assert alone.power_w == ds["power"].values[i, j, 0]


@pytest.mark.slow
def test_the_bearing_load_is_a_finite_difference_of_the_motion(dataset):
    """The peak bearing load is the largest ``|m c'' + m g e_z|``, ``c = p + l (sin phi, cos
    phi)`` the pendulum's centre, ``p = G xi`` the pivot: here ``c''`` by a central second
    difference of the motion's positions (independent of the result's analytic
    derivatives), on a grid of 4096 points of the period."""
    r = parapend.buoy(dofs=DOFS, hydro=dataset, wave_height=1.0, wave_period=6.0, winding=1,
                      **PEND)
    m, length = r.pendulum["mass_kg"], r.pendulum["length_m"]
    d, h = r.pivot["pivot_offset_m"], r.pivot["pivot_height_m"]
    period, g = 6.0, 9.81

    def centre(t):
        s = r.motion(t)
        x, z, beta = s["xi"]
        return np.stack((x + h * beta + length * np.sin(s["phi"]),
                         z - d * beta + length * np.cos(s["phi"])))
    t = period * np.arange(4096) / 4096
    dt = period * 1e-4
    acc = (centre(t + dt) - 2 * centre(t) + centre(t - dt)) / dt**2
    force = np.hypot(m * acc[0], m * acc[1] + m * g)
    assert force.max() == pytest.approx(r.peak_pivot_force_n, rel=1e-5)
    assert force.max() <= r.peak_pivot_force_n * (1 + 1e-6)  # the grid's largest at most
    assert r.peak_pivot_force_n > m * g  # the motion loads the bearing beyond the weight


@pytest.mark.slow
@pytest.mark.parametrize("height, period, winding", [(1.0, 6.0, 1), (1.5, 5.0, 1),
                                                     (1.0, 7.0, 0)])
def test_the_stated_discretization_error_covers_one_more_doubling(dataset, height, period,
                                                                  winding):
    """The stated error estimate (``error_estimate`` of the refinement's stages) is at least
    the change of the power when the answer's harmonics (of the pendulum and of the hull)
    are doubled once more and the maximum solved again from the answer."""
    from parapend.hydro.coupled import Wave
    from parapend.hydro.hull import GTOL, HullProblem, make_case
    from parapend.hydro.result import _solve_mode, error_estimate
    from parapend.optimal.fourier import _pad, newton_maximize

    p = hull_api.hull_problem(hydro=dataset, **PEND)
    wave = Wave.regular(height, period)
    mode = _solve_mode(p["hull"], p["pendulum"], wave, winding, None, p["pivot"],
                       p["pitch_inertia"], p["pto"])
    sol = mode["_solution"]
    assert mode["success"] and len(sol.refinement_history) >= 2
    stated = error_estimate(sol.refinement_history)
    assert stated == mode["discretization_error_estimate_w"]
    assert sol.refinement_history[-1][1] == sol.power
    n, nh = 2 * sol.case.harmonics, 2 * sol.case.hull_harmonics
    finer = make_case(p["hull"], p["pendulum"], wave, winding=winding, harmonics=n,
                      hull_harmonics=nh, pivot=p["pivot"], pitch_inertia=p["pitch_inertia"])
    r = newton_maximize(HullProblem(finer), _pad(sol.x, n), "check", gtol=GTOL)
    assert r.status == "converged"
    observed = abs(float(r.power) - sol.power)
    assert stated is not None and observed <= stated + 1e-9 * abs(sol.power)
