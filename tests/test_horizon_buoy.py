"""``parapend horizon --device buoy`` (hydro/horizon.py): the buoy's causal controller against
the forecast horizon.

The numbers are checked against independent paths: a point of the curve is
:func:`parapend.hydro.control.buoy_mpc` run directly on the body and record that
``parapend.buoy`` builds; the optimum is ``parapend.buoy``'s on the same record; the
fractions are their quotient; the storage correction is the harvested power plus the
stored energy's change over the repeat. The buoy runs use the coarse Capytaine sphere of
tests/test_buoy_cli.py (``--hydro``) and records of four peak periods; they take several
seconds and are slow tests. The input checks (one line, exit 2) and the keys run no buoy.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.control.horizon import HorizonResult
from parapend.errors import ParameterError
from parapend.hydro.horizon import BUOY_HORIZON, BuoyHorizonResult

#: the small sphere's sea and pendulum (its dataset covers 1..8 rad/s)
SEA = {"hs": 0.3, "tp": 2.5, "repeat_period": 10.0, "seed": 3}
PEND = {"mass": 20.0, "length": 0.3, "damping_coefficient": 0.5}
ARGV = ["--hs", "0.3", "--tp", "2.5", "--repeat-period", "10", "--seed", "3", "--mass", "20",
        "--length", "0.3", "--damping-coefficient", "0.5"]


@pytest.fixture(scope="module")
def curve(sphere_nc):
    return parapend.horizon(device="buoy", hydro=sphere_nc, horizons="0.5,1",
                            forecasts="perfect", warm_up=1.0, **SEA, **PEND)


@pytest.fixture(scope="module")
def optimum(sphere_nc):
    """``parapend buoy`` on the same record: the coupled optimum, its body and its wave."""
    return parapend.buoy(hydro=sphere_nc, **SEA, **PEND)


# --- the numbers against independent paths (buoy runs: slow) --------------------------------
@pytest.mark.slow
def test_a_point_of_the_curve_is_buoy_mpc_run_directly(curve, optimum):
    """The curve's run at horizon 1, perfect forecast, is buoy_mpc called by hand with the same
    arguments on the body and the record parapend.buoy built (its own input path): the
    same power, harvested power and stored energy, to the bit (the run is deterministic)."""
    from parapend.hydro.control import buoy_mpc
    from parapend.hydro.coupled import Pendulum

    pend = Pendulum(mass=20.0, length=0.3, inertia=20.0 * 0.09, damping_coefficient=0.5)
    r = buoy_mpc(optimum._hydro, pend, optimum._wave, peak_period=2.5, horizon=1.0,
                 update_interval=0.125, warmup=1.0, repeats=1, forecast="perfect")
    j = curve.horizons.index(1.0)
    assert r.success and curve.mpc_status[0][j][0] == r.status
    assert curve.mpc_power_w[0][j][0] == r.electrical_power_w
    assert curve.mpc_harvested_power_w[0][j][0] == r.harvested_electrical_power_w
    assert curve.mpc_stored_energy_change_j[0][j][0] == r.stored_energy_change_j
    assert curve.mpc_failed_solves[0][j][0] == r.failed_solves
    assert curve.planner == r.planner


@pytest.mark.slow
def test_fractions_are_the_power_over_parapend_buoy_s_optimum(curve, optimum):
    assert optimum.success
    assert curve.optimum_power_w == [optimum.power_w]
    frac = np.asarray(curve.mpc_power_w)[:, :, 0] / optimum.power_w
    assert np.array_equal(np.asarray(curve.mpc_fraction)[:, :, 0], frac)
    # one record: its mean, least and largest are its own
    for name in ("mpc_fraction_mean", "mpc_fraction_min", "mpc_fraction_max"):
        assert np.array_equal(np.asarray(getattr(curve, name)), frac)


@pytest.mark.slow
def test_the_power_is_storage_corrected_over_one_repeat(curve):
    """No efficiency: power = harvested + dE / T_r, the window one repeat of the record."""
    p = np.asarray(curve.mpc_power_w)
    h = np.asarray(curve.mpc_harvested_power_w)
    de = np.asarray(curve.mpc_stored_energy_change_j)
    assert np.all(np.isfinite(p))
    assert np.allclose(p, h + de / SEA["repeat_period"], rtol=1e-9, atol=1e-9 * np.abs(h).max())


@pytest.mark.slow
def test_the_timings_and_the_realtime_verdict(curve):
    med, p99 = np.asarray(curve.mpc_update_time_median), np.asarray(curve.mpc_update_time_p99)
    mx, first = np.asarray(curve.mpc_update_time_max), np.asarray(curve.mpc_update_time_first)
    assert np.all(np.isfinite(first)) and np.all(first > 0)
    assert np.all(0 < med) and np.all(med <= p99) and np.all(p99 <= mx)
    # the update interval in seconds: 1/8 of the peak period, on whole torque samples
    assert curve.update_interval_s == pytest.approx(2.5 / 8, rel=0.05)
    assert curve.realtime_fits == bool(p99.max() <= curve.update_interval_s)
    assert curve.seeds == [SEA["seed"]] and curve.status == "done" and curve.success


@pytest.mark.slow
def test_the_ar_forecast_beside_the_perfect_one_and_records_pooled(sphere_nc, monkeypatch):
    """Two forecasts and two records: the AR run on the second record (seed + 1) is buoy_mpc
    with the AR forecast on parapend.buoy's record of that seed, its optimum parapend.buoy's,
    and the mean fraction the mean over the records. The update times are every run's own
    (captured here), pooled: the first record's first update apart, the rest together."""
    import parapend.hydro.control as hc

    runs = []
    real = hc.buoy_mpc

    @functools.wraps(real)
    def spy(*args, **kw):
        runs.append((kw["forecast"], real(*args, **kw)))
        return runs[-1][1]

    monkeypatch.setattr(hc, "buoy_mpc", spy)
    r = parapend.horizon(device="buoy", hydro=sphere_nc, horizons="0.5",
                         forecasts="ar,perfect", records=2, warm_up=1.0, **SEA, **PEND)
    monkeypatch.setattr(hc, "buoy_mpc", real)
    assert [f for f, _ in runs] == ["ar", "ar", "perfect", "perfect"]
    for i in range(2):
        a, b = runs[2 * i][1], runs[2 * i + 1][1]
        assert r.mpc_power_w[i][0] == [a.electrical_power_w, b.electrical_power_w]
        pooled = np.concatenate((a._update_times[1:], b._update_times))
        assert r.mpc_update_time_first[i][0] == a._update_times[0] == a.update_time_first_s
        assert r.mpc_update_time_median[i][0] == float(np.median(pooled))
        assert r.mpc_update_time_p99[i][0] == float(np.percentile(pooled, 99))
        assert r.mpc_update_time_max[i][0] == float(np.max(pooled))
    assert r.forecasts == ["ar", "perfect"] and r.seeds == [3, 4]
    from parapend.hydro.control import buoy_mpc
    from parapend.hydro.coupled import Pendulum

    opt = parapend.buoy(hydro=sphere_nc, **{**SEA, "seed": 4}, **PEND)
    assert r.optimum_power_w[1] == opt.power_w
    pend = Pendulum(mass=20.0, length=0.3, inertia=20.0 * 0.09, damping_coefficient=0.5)
    d = buoy_mpc(opt._hydro, pend, opt._wave, peak_period=2.5, horizon=0.5, warmup=1.0,
                 forecast="ar")
    assert r.mpc_power_w[0][0][1] == d.electrical_power_w
    mean = np.mean([r.mpc_fraction[0][0][k] for k in range(2)])
    assert r.mpc_fraction_mean[0][0] == pytest.approx(mean, rel=1e-12)


@pytest.mark.slow
def test_cli_text_json_plot_and_save(sphere_nc, tmp_path, capsys):
    png, nc = tmp_path / "h.png", tmp_path / "h.nc"
    argv = ["horizon", "--device", "buoy", "--hydro", sphere_nc, *ARGV, "--horizons", "0.5",
            "--forecasts", "perfect", "--warm-up", "1"]
    assert main([*argv, "--plot", str(png), "--save", str(nc)]) == 0
    out = capsys.readouterr().out
    assert "horizon, buoy" in out and "seed 3" in out and "p99" in out
    assert png.stat().st_size > 0
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        assert ds["mpc_power_w"].dims == ("forecast", "horizon", "record")
        power = float(ds["mpc_power_w"].values[0, 0, 0])
    assert main([*argv, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["device"] == "buoy" and d["seeds"] == [3]
    assert d["mpc_power_w"][0][0][0] == power  # the run is deterministic


@pytest.mark.slow
def test_a_time_limit_gives_a_partial_curve(sphere_nc):
    r = parapend.horizon(device="buoy", hydro=sphere_nc, horizons="0.5",
                         forecasts="perfect", warm_up=1.0, time_limit=1e-3, **SEA, **PEND)
    assert r.status == "time_limit" and not r.success
    assert r.mpc_status == [[["time_limit"]]] and math.isnan(r.mpc_power_w[0][0][0])


# --- keys, defaults and input checks (no buoy run) ------------------------------------------
def test_the_keys_are_the_pendulum_curve_s_where_the_quantity_is_the_same():
    buoy = {f.name for f in dataclasses.fields(BuoyHorizonResult)}
    pend = {f.name for f in dataclasses.fields(HorizonResult)}
    shared = {"horizons", "forecasts", "seeds", "mpc_power_w", "optimum_power_w",
              "mpc_fraction", "mpc_fraction_mean", "mpc_fraction_min", "mpc_fraction_max",
              "mpc_status", "mpc_stored_energy_change_j", "mpc_failed_solves",
              "mpc_failed_kept_previous", "mpc_horizon_used", "mpc_update_time_first",
              "mpc_update_time_median", "mpc_update_time_p99", "mpc_update_time_max",
              "update_interval", "update_interval_s", "realtime_fits", "warm_up", "record",
              "success", "status", "message", "convention"}
    assert shared <= buoy and shared <= pend
    # a buoy quantity in SI has its unit in its name; none of the pendulum's
    # non-dimensional names
    assert not buoy & {"mpc_power", "optimum_power", "gamma", "units"}


def test_the_default_device_is_the_pendulum_and_the_buoy_s_defaults_are_its_own():
    import inspect

    params = inspect.signature(parapend.horizon).parameters
    assert params["device"].default == "pendulum"
    for name in ("horizons", "update_interval", "warm_up", "baselines", "length", "mass"):
        assert params[name].default is None  # resolved by device
    assert BUOY_HORIZON["update_interval"] == 0.125 and BUOY_HORIZON["warm_up"] == 4.0


def test_the_pendulum_curve_keeps_its_defaults_and_keys():
    """Without ``device`` the curve is the pendulum's: HORIZON's horizons, update interval,
    warm-up and baselines, sea's 1 m, 10 kg pendulum, and no key of the buoy's."""
    from parapend.defaults import HORIZON
    from parapend.defaults import SEA as SEA_DEFAULTS

    r = parapend.horizon(forecasts="none", baselines="extremum", repeat_period=16.0)
    assert isinstance(r, HorizonResult)
    assert r.horizons == [float(h) for h in HORIZON["horizons"].split(",")]
    assert r.update_interval == HORIZON["update_interval"] and r.warm_up == HORIZON["warm_up"]
    assert r.units["length_m"] == SEA_DEFAULTS["length"]
    assert r.units["mass_kg"] == SEA_DEFAULTS["mass"]
    d = r.to_dict()
    assert "device" not in d and "planner" not in d
    assert parapend.horizon(forecasts="none", repeat_period=16.0).baselines == [
        "tracker", "extremum"]


def _one_line(argv, name, capsys):
    assert main(["horizon", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and name in err[0], err


@pytest.mark.parametrize("argv, name", [
    (["--device", "buoy", "--gamma", "0.01"], "gamma"),
    (["--device", "buoy", "--gravity", "9.8"], "gravity"),
    (["--device", "buoy", "--baselines", "tracker"], "baselines"),
    (["--device", "buoy", "--baselines", "none"], "baselines"),
    (["--device", "buoy", "--speed-limit", "2"], "speed-limit"),
    (["--body", "sphere"], "body"),
    (["--radius", "0.4"], "radius"),
    (["--planner", "plan"], "planner"),
    (["--controller", "plan"], "--planner"),          # the former name, named the new one
    (["--device", "buoy", "--controller", "coupled"], "--planner"),
    (["--hydro", "x.nc"], "hydro"),
    (["--device", "buoy", "--forecasts", "none"], "forecasts"),
    (["--device", "buoy", "--forecasts", "tracker"], "forecasts"),
    (["--device", "buoy", "--planner", "plan", "--efficiency", "0.9"], "efficiency"),
    (["--device", "buoy", "--planner", "lbfgsb"], "planner"),     # the hull's planner
    (["--device", "buoy", "--dofs", "surge,heave,pitch", "--planner", "plan"], "planner"),
    (["--device", "buoy", "--torque-limit", "1", "--torque-limit-nm", "100"],
     "torque-limit-nm"),
    (["--device", "buoy", "--torque-limit", "-1"], "torque-limit"),
    (["--device", "buoy", "--horizons", "0.5", "--update-interval", "1"], "update-interval"),
    (["--device", "buoy", "--mass", "-3"], "mass"),
    (["--device", "buoy", "--records", "0"], "records"),
    (["--device", "buoy", "--warm-up", "-1"], "warm-up"),
    # the estimate, before any BEM: twenty records, or one record of 400 waves
    (["--device", "buoy", "--records", "20"], "records"),
    (["--device", "buoy", "--repeat-period", "1000"], "repeat-period"),
    # the hull's (collocation) planner on long horizons: their warm-up alone is past the 2
    # minutes, whatever the record: fewer horizons, not a repeat period of 0 s
    (["--device", "buoy", "--dofs", "surge,heave,pitch", "--horizons", "2,4,6,8,10"],
     "horizons"),
    # the hull's controller's own ranges, before the estimate (the heaving buoy's are wider)
    (["--device", "buoy", "--dofs", "surge,heave,pitch", "--horizons", "12"], "horizons"),
    (["--device", "buoy", "--dofs", "surge,heave,pitch", "--update-interval", "0.02"],
     "update-interval"),
])
def test_bad_input_is_one_line_exit_2(argv, name, capsys):
    _one_line(argv, name, capsys)


def test_the_refusal_names_what_fits():
    with pytest.raises(ParameterError, match=r"records: .* use --records at most \d+"):
        parapend.horizon(device="buoy", records=20)
    with pytest.raises(ParameterError, match=r"device: expected pendulum or buoy"):
        parapend.horizon(device="tank")
