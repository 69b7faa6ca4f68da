"""Long work under ``--time-limit`` (:mod:`parapend.deadline`).

Without a time limit, work estimated above the cap is refused in one line (exit 2) naming
the option to change, the largest value that fits and ``--time-limit``; with one, the work
stops at its next unit once the deadline has passed and the result says ``time_limit``,
``success`` False and how much was done. A deadline already past (``time_limit=1e-9``, or
``deadline=0.0``) stops every loop after its first unit, so no test depends on a clock: the
part that was done is then compared with the same part of a full run (the same code on
the same input: equal to round-off), and the rest must be NaN, marked, and left out of
every sum.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import parapend
from parapend import limits
from parapend.cli import main
from parapend.deadline import check_time_limit, duration, refuse_untimed
from parapend.errors import ParameterError

# --- refusals: one line, exit 2, the option and --time-limit named -----------------------


def _refused(argv, capsys) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


@pytest.mark.parametrize("argv, option, fits", [
    # the four audit cases (each ran past 2 minutes, or for hours)
    (["buoy", "--optimize-design", "mass,length,inertia,damping-coefficient"],
     "optimize-design:", "choose at most 3 of them"),
    (["horizon", "--records", "20", "--repeat-period", "3200"], "repeat-period:",
     "--repeat-period at most 271.8 s (one record)"),
    (["power-matrix", "--hs", "0.5:5:100", "--te", "4:13:100"], "hs:", "--store"),
    (["track", "--controller", "mpc", "--periods", "2000"], "periods:",
     "--periods at most 416"),
    # neighbours: the same work a decade smaller, still over the cap
    (["horizon", "--records", "2", "--repeat-period", "3200"], "repeat-period:",
     "--repeat-period at most 271.8 s (one record)"),
    (["horizon", "--records", "2", "--repeat-period", "320"], "repeat-period:",
     "--repeat-period at most 271.8 s (one record)"),
    (["horizon", "--records", "3", "--repeat-period", "800"], "repeat-period:",
     "--repeat-period at most 271.8 s (one record)"),
    (["horizon", "--records", "3", "--repeat-period", "160"], "records:",
     "--records at most 1"),
    # the curve's old default record (100 waves, estimated at 6 minutes), and with an
    # efficiency and a torque limit on a 20-wave record at five horizons (about 143 s)
    (["horizon", "--repeat-period", "800"], "repeat-period:",
     "--repeat-period at most 271.8 s (one record)"),
    (["horizon", "--hs", "1.5", "--tp", "7", "--torque-limit", "1", "--efficiency", "0.9",
      "--horizons", "0.25,0.5,1,2,4"], "repeat-period:",
     "--repeat-period at most 113 s (one record)"),
    # the records' optima and baselines count too (20 x 400 waves: roughly 40 minutes)
    (["horizon", "--records", "20", "--repeat-period", "3200", "--forecasts", "none"],
     "records:", "--records at most 1"),
    (["power-matrix", "--hs", "1:3:3", "--te", "6:10:3", "--realizations", "100"],
     "realizations:", "--realizations at most"),
    (["buoy", "--wave-period", "1.2:3:200"], "wave-period:", "at most 94 periods"),
])
def test_long_work_is_refused_in_one_line(argv, option, fits, capsys):
    err = _refused(argv, capsys)
    assert f"error: {option}" in err and fits in err
    assert "--time-limit SECONDS" in err


def test_the_largest_value_named_fits():
    # track: 416 periods at the estimate's 9 ms an update fit the 120 s, 417 do not
    from parapend.control.mpc import update_seconds

    each = update_seconds(2.0) * 32  # 32 updates a period at the default 1/32
    assert 416 * each <= limits.MAX_UNTIMED_SECONDS < 417 * each


class _Started(Exception):
    """Raised where the work would start: the estimate let it through."""


@pytest.mark.parametrize("kw", [
    {},  # the default curve: one 20-wave record, 4 horizons, estimated at 71 s
    {"hs": 1.5, "tp": 7, "torque_limit": 1, "efficiency": 0.9, "horizons": "0.5,1,2"},
    {"repeat_period": 160, "horizons": "0.25,0.5,1,2,4", "records": 3,
     "forecasts": "perfect", "baselines": "none", "warm_up": 4},
])
def test_horizon_documented_curves_run_untimed(kw, monkeypatch):
    # the documented curves pass the 2-minute estimate (stopped where the first record's
    # optimum would start: the curve itself takes a minute); the default record is 20 Tp
    import parapend.irregular

    seen = {}

    def started(**kwargs):
        seen.update(kwargs)
        raise _Started

    monkeypatch.setattr(parapend.irregular, "sea", started)
    with pytest.raises(_Started):
        parapend.horizon(**kw)
    tp = kw.get("tp", 8.0)
    assert seen["repeat_period"] == pytest.approx(kw.get("repeat_period", 20 * tp))


@pytest.mark.parametrize("argv, match", [
    (["buoy", "--time-limit", "5"], "time-limit: bounds long work only"),
    (["track", "--time-limit", "5"], "time-limit: bounds long work only"),
    (["power-matrix", "--time-limit", "0"], "time-limit: expected a number > 0"),
    (["horizon", "--time-limit", "1e9"], "time-limit: expected seconds in (0, 604800]"),
    (["buoy", "--dofs", "surge,heave,pitch", "--time-limit", "5"],
     "time-limit: bounds long work only: with --dofs surge,heave,pitch a period sweep"),
])
def test_time_limit_input_is_checked(argv, match, capsys):
    assert match in _refused(argv, capsys)


def test_the_helpers():
    assert check_time_limit(None) is None and check_time_limit(2) == 2.0
    with pytest.raises(ParameterError, match="time-limit"):
        check_time_limit(math.inf)
    assert duration(45) == "45 s" and duration(600) == "10 minutes"
    # beside the 120 s cap a refused 143 s must not read "2 minutes"
    assert duration(143) == "143 s" and duration(299) == "299 s"
    assert duration(12 * 3600) == "12 hours" and duration(3 * 86400) == "3 days"
    cap = limits.MAX_UNTIMED_SECONDS
    refuse_untimed("x", "work", cap, "fix")  # at the cap: runs
    refuse_untimed("x", "work", 1e9, "fix", time_limit=10.0)  # a time limit: runs
    with pytest.raises(ParameterError, match=r"^x: work is estimated at roughly 12 hours"):
        refuse_untimed("x", "work", 12 * 3600, "fix")


# --- the design search ---------------------------------------------------------------------
class _Pend:
    def __init__(self, mass, length, inertia, damping_coefficient=0.0):
        self.mass, self.length, self.inertia = mass, length, inertia
        self.damping_coefficient = damping_coefficient


def _replace(p, **kw):
    return _Pend(**{"mass": p.mass, "length": p.length, "inertia": p.inertia,
                    "damping_coefficient": p.damping_coefficient, **kw})


class _Sol:
    def __init__(self, power):
        self.power, self.success = power, True


def test_design_search_stops_after_its_first_solve(monkeypatch):
    import dataclasses

    from parapend.hydro import design

    monkeypatch.setattr(dataclasses, "replace", lambda p, **kw: _replace(p, **kw))
    calls = []

    def solve(p):
        calls.append(p.mass)
        return _Sol(10 - (p.mass - 3.3) ** 2)

    full = design.optimize_design(solve, _Pend(2.0, 0.5, 0.5), ["mass"], {"mass": (1.0, 5.0)})
    assert full.status == "ok" and full.evaluations > 7
    calls.clear()
    part = design.optimize_design(solve, _Pend(2.0, 0.5, 0.5), ["mass"],
                                  {"mass": (1.0, 5.0)}, deadline=0.0)
    # one inner solve (the grid's first point, the lower bound), then the time limit
    assert calls == [1.0] and part.evaluations == 1 and part.total == full.total
    assert part.status == "time_limit" and "1 of at most" in part.message
    assert part.best["mass_kg"] == 1.0
    assert part.power_w == pytest.approx(10 - (1.0 - 3.3) ** 2, rel=1e-15)


# --- the buoy: a period sweep and the receding-horizon run (no BEM) ------------------------
PEND = {"mass": 20.0, "length": 0.3, "damping_coefficient": 0.5, "harmonics": 8}


def test_buoy_period_sweep_partial(sphere_nc, tmp_path, capsys):
    import xarray as xr

    part = parapend.buoy(hydro=sphere_nc, wave_period="1.1:1.5:3", time_limit=1e-9, **PEND)
    one = parapend.buoy(hydro=sphere_nc, wave_period=1.1, **PEND)
    assert not part.success and part.status[1:] == ["time_limit", "time_limit"]
    assert part.power_w[0] == pytest.approx(one.power_w, rel=1e-12)
    assert np.isnan(part.power_w[1:]).all()
    assert any("1 of 3 periods solved" in w for w in part.warnings)
    nc = tmp_path / "sweep.nc"
    argv = ["buoy", "--hydro", sphere_nc, "--wave-period", "1.1:1.5:3", "--mass", "20",
            "--length", "0.3", "--damping-coefficient", "0.5", "--harmonics", "8",
            "--time-limit", "1e-9", "--save", str(nc)]
    assert main(argv) == 0
    assert "time limit reached: 1 of 3 periods solved" in capsys.readouterr().out
    with xr.open_dataset(nc) as ds:
        assert list(ds["status"].values[1:]) == ["time_limit", "time_limit"]
        assert "1 of 3 periods solved" in ds.attrs["warnings"]


def test_buoy_design_partial_through_the_command(sphere_nc, capsys):
    argv = ["buoy", "--hydro", sphere_nc, "--wave-period", "1.3", "--mass", "20",
            "--length", "0.3", "--damping-coefficient", "0.5", "--harmonics", "8",
            "--optimize-design", "length", "--time-limit", "1e-9", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "time_limit" and out["success"] is False
    # the search stops at its first design that harvests power (on the grid's first line)
    assert out["design"]["status"] == "time_limit"
    assert 1 <= out["design"]["evaluations"] < out["design"]["total"]
    # the design reported is the one evaluated, solved in full: a plain solve agrees
    best = out["design"]["best"]
    plain = parapend.buoy(hydro=sphere_nc, wave_period=1.3, mass=20.0, length=best["length_m"],
                          inertia=best["inertia_kg_m2"], damping_coefficient=0.5, harmonics=8)
    assert out["power_w"] == pytest.approx(plain.power_w, rel=1e-10)


def _buoy_mpc(**kw):
    from buoy_synthetic import synthetic

    from parapend.hydro import control as bc
    from parapend.hydro.coupled import Pendulum, Wave

    amps = np.zeros(12, complex)
    amps[3], amps[4], amps[5] = 0.25, 0.15j, 0.08
    wave = Wave(2 * math.pi / 10.0, amps)
    pend = Pendulum(20.0, 0.3, 20.0 * 0.09, 0.25)
    return bc.buoy_mpc(synthetic(), pend, wave, peak_period=2.5, horizon=0.5, warmup=2.0,
                       samples=32, memory=8.0, controller="one-way", **kw)


def test_buoy_mpc_partial_is_marked():
    part = _buoy_mpc(deadline=0.0)
    assert part.status == "time_limit" and not part.success
    assert part.solves == 1 and part.t_end_s < 12.0  # of the 5 + 10 s run
    assert "time limit reached after 1 updates" in part.message


@pytest.mark.slow
def test_buoy_mpc_partial_is_the_full_runs_beginning():
    full, part = _buoy_mpc(), _buoy_mpc(deadline=0.0)
    # the full one-way run loses energy on this record (marked loses_energy, not ok)
    assert full.status == "loses_energy" and part.t_end_s < full.t_end_s
    n = part.series["theta"].size
    assert np.allclose(part.series["theta"], full.series["theta"][:n], rtol=0, atol=1e-12)


# --- track --controller mpc and horizon ---------------------------------------------------
def test_track_mpc_partial_is_the_full_runs_beginning():
    full = parapend.track(controller="mpc", periods=20)
    part = parapend.track(controller="mpc", periods=20, time_limit=1e-9)
    assert full.success and part.status == "time_limit" and not part.success
    assert part.solves == 1 and "time limit reached at t = " in part.message
    th, ref = part._run.theta, full._run.theta
    assert 1 < th.size < ref.size
    assert np.allclose(th, ref[:th.size], rtol=0, atol=1e-12)
    # stopped before the averaging window (10 periods): no power is claimed
    assert math.isnan(part.mean_power)


def test_horizon_partial_keeps_what_it_finished():
    kw = dict(repeat_period=48.0, horizons="1", forecasts="perfect", baselines="extremum",
              records=2)
    part = parapend.horizon(time_limit=1e-9, **kw)
    assert part.status == "time_limit" and part.success is False
    assert "1 of 6 runs finished" in part.message
    # the first record's optimum is the sea command's; the rest NaN and marked
    sea = parapend.sea(repeat_period=48.0, seed=part.seeds[0])
    assert part.optimum_power[0] == pytest.approx(sea.power, rel=1e-12)
    assert math.isnan(part.optimum_power[1])
    assert part.mpc_status == [[["time_limit", "time_limit"]]]
    assert part.baseline_status == [["time_limit", "time_limit"]]


# --- the power matrix ----------------------------------------------------------------------
TINY = {"hs": "1,2", "te": "6,7", "realizations": 2, "waves": 4, "workers": 1}


@pytest.fixture(scope="module")
def full_matrix():
    from parapend.performance import power_matrix

    return power_matrix(**TINY)[0]


def _site(path):
    path.write_text("hs,te,frequency\n1,6,0.1\n1,7,0.2\n2,6,0.3\n2,7,0.4\n")
    return str(path)


def test_power_matrix_partial_bins_equal_the_full_runs(full_matrix, tmp_path):
    from parapend.performance import power_matrix
    from parapend.performance.annual import HOURS_PER_YEAR

    ds, annual, run, _ = power_matrix(**TINY, time_limit=1e-9,
                                      scatter=_site(tmp_path / "site.csv"))
    assert run.stopped and ds.attrs["status"] == "time_limit"
    assert ds.attrs["bins"] == 4 and ds.attrs["bins_finished"] == 1
    p, ref = ds["power_mean"].values, full_matrix["power_mean"].values
    done = np.isfinite(p)
    # the dearest bin goes first: the higher sea (Hs 2 m), then the longer record (the
    # records are all 4 waves here: the first period)
    assert done.sum() == 1 and done[1, 0]
    assert p[1, 0] == pytest.approx(ref[1, 0], rel=1e-12)
    assert (ds["power_count"].values[~done] == 0).all()
    # the AEP counts the finished bin only, and says it is incomplete
    a = annual["power"]
    assert not a["complete"] and a["uncounted_frequency"] == pytest.approx(0.7)
    assert a["wh"] == pytest.approx(HOURS_PER_YEAR * max(ref[1, 0], 0.0) * 0.3, rel=1e-12)
    assert ds.attrs["annual_energy_complete"] == 0


@pytest.mark.slow  # 4 s: two runs of a matrix through its store
def test_power_matrix_partial_store_resumes(tmp_path, capsys):
    from parapend.maps.store import open_sweep
    from parapend.performance import power_matrix

    small = {"hs": "1,2", "te": "6,7", "realizations": 1, "waves": 4, "workers": 1}
    store = tmp_path / "m.zarr"
    argv = ["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "1",
            "--waves", "4", "--workers", "1", "--store", str(store)]
    assert main([*argv, "--time-limit", "1e-9", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "time_limit" and out["success"] is False
    assert (out["bins_finished"], out["bins"], out["computed_bins"]) == (1, 4, 1)
    assert open_sweep(store)["done"].values.sum() == 1  # the unfinished bins: not done
    # a rerun computes the rest, and the matrix is the one a single run gives
    ds, _, run, _ = power_matrix(**small, store=str(store))
    assert (run.resumed_points, run.computed_points, run.stopped) == (1, 3, False)
    assert "status" not in ds.attrs
    ref = power_matrix(**small)[0]
    assert np.allclose(ds["power_mean"].values, ref["power_mean"].values, rtol=1e-12,
                       atol=0, equal_nan=True)


def test_power_matrix_partial_text_is_marked(capsys):
    argv = ["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "2", "--waves",
            "4", "--workers", "1", "--time-limit", "1e-9"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "status: time_limit: PARTIAL matrix, bins 1 of 4 finished" in out


@pytest.mark.slow
def test_power_matrix_partial_on_local_processes(full_matrix):
    """Two worker processes: the deadline passes once the first bin is written; the bins
    still running are abandoned (never marked done), and the finished ones equal a full
    run's."""
    from parapend import deadline
    from parapend.performance import power_matrix

    ds, _, run, _ = power_matrix(**{**TINY, "workers": 2}, time_limit=1e-9)
    assert run.stopped and ds.attrs["status"] == "time_limit"
    p, ref = ds["power_mean"].values, full_matrix["power_mean"].values
    done = np.isfinite(p)
    assert 1 <= done.sum() == ds.attrs["bins_finished"] < 4
    assert np.allclose(p[done], ref[done], rtol=1e-12, atol=0)
    assert deadline.expired(0.0) and not deadline.expired(None)
