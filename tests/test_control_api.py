"""The Python API of ``horizon`` and ``track`` (both controllers) under bad values: each is a
one-line :class:`~parapend.errors.ParameterError` that names the parameter as the command
line does, never a bare ``TypeError``/``ValueError``/``IndexError``; and the options
the signature allows are accepted as keywords."""

import math

import numpy as np
import pytest

import parapend
from parapend.errors import ParameterError


@pytest.mark.parametrize("kw, match", [
    ({"horizons": ["x"]}, "horizons: expected a comma list of numbers"),
    ({"horizons": "none"}, "horizons: expected a comma list of numbers"),
    ({"baselines": 3}, "baselines: expected names from tracker, extremum"),
    ({"update_interval": "x"}, "update-interval: expected a real number"),
    ({"horizons": [[1, 2]]}, "horizons: expected a comma list of numbers"),
    ({"horizons": True}, "horizons: expected a comma list of numbers"),
    ({"horizons": b"1"}, "horizons: expected a comma list of numbers"),
    ({"horizons": "a"}, "horizons: expected a comma list of numbers"),
    ({"horizons": [1.0, math.nan]}, "horizons: expected a finite number"),
    ({"forecasts": None}, "forecasts: expected names from perfect, ar"),
    ({"forecasts": 3}, "forecasts: expected names from perfect, ar"),
    ({"forecasts": ["perfect", 3]}, "forecasts: expected names"),
    ({"records": "x"}, "records: expected an integer"),
    ({"torque_limit": "x"}, "torque-limit: expected a real number"),
    ({"torque_limit_nm": "x"}, "torque-limit-nm: expected a real number"),
    ({"torque_limit_nm": -1.0}, "torque-limit-nm: expected a number > 0"),
    ({"efficiency": [0.9, 0.8, 0.7]}, "efficiency"),
    ({"progress": 3}, "progress: expected a callable"),
])
def test_horizon_bad_values_are_parameter_errors(kw, match):
    with pytest.raises(ParameterError, match=match) as exc:
        parapend.horizon(**{"records": 1, **kw})
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("kw, match", [
    ({"torque_limit": "x"}, "torque-limit: expected a real number"),
    ({"torque_limit": [1.0]}, "torque-limit: expected a real number"),
    ({"torque_limit": -1.0}, "torque-limit"),
    ({"theta0": "x"}, "theta0: expected a real number"),
    ({"theta0": None}, "theta0: expected a real number"),
    ({"theta0": math.nan}, "theta0: expected a finite number"),
    ({"theta_dot0": "x"}, "theta-dot0: expected a real number"),
    ({"irregular": "yes"}, "irregular: expected True or False"),
    ({"runs": "x"}, "runs: expected an integer"),
    ({"horizon": None}, "horizon: expected a real number"),
    ({"forecast": ["ar"]}, "forecast: expected perfect or ar"),
    ({"speed_limit": "x"}, "speed-limit: expected a real number"),
    ({"periods": None}, "periods: expected an integer"),
    ({"torque_limit_nm": "x", "length": 1.0, "mass": 1.0},
     "torque-limit-nm: expected a real number"),
])
def test_track_mpc_bad_values_are_parameter_errors(kw, match):
    with pytest.raises(ParameterError, match=match):
        parapend.track(controller="mpc", **kw)


@pytest.mark.parametrize("kw, match", [
    ({"theta0": "x"}, "theta0: expected a real number"),
    ({"theta_dot0": None}, "theta-dot0: expected a real number"),
    ({"irregular": "no"}, "irregular: expected True or False"),
    ({"torque_limit_nm": "x", "length": 1.0, "mass": 1.0},
     "torque-limit-nm: expected a real number"),
])
def test_track_lqr_bad_values_are_parameter_errors(kw, match):
    with pytest.raises(ParameterError, match=match):
        parapend.track(**kw)


def test_horizon_takes_sequences_and_arrays_of_horizons():
    """A list or an array of numbers is a valid ``horizons`` (the signature's sequence), as
    is a NumPy bool for the flags; refused only past validation, on the update interval."""
    for hz in ([0.5, 2], np.array([0.5, 2.0]), (1,)):
        with pytest.raises(ParameterError, match="update-interval"):
            parapend.horizon(horizons=hz, records=1, update_interval=5.0)


def test_track_mpc_announces_long_work_and_reports_progress(monkeypatch, caplog):
    """Before the work, an estimate on the ``parapend.control`` logger (the command line
    prints it on stderr) when it is over ``ANNOUNCE_SECONDS`` (lowered here); during it,
    ``progress(done, total)`` in torque samples, nondecreasing, ending at the total."""
    import logging

    from parapend.control import mpc

    monkeypatch.setattr(mpc, "ANNOUNCE_SECONDS", 0.0)
    calls = []
    with caplog.at_level(logging.INFO, logger="parapend.control"):
        r = parapend.track(controller="mpc", periods=20, horizon=0.5, update_interval=0.25,
                           progress=lambda d, t: calls.append((d, t)))
    assert r.success
    msgs = [rec.getMessage() for rec in caplog.records if rec.name == "parapend.control"]
    assert len(msgs) == 1 and "20 periods = about 80 updates" in msgs[0]
    assert calls[-1] == (20 * 64, 20 * 64)
    done = [d for d, _ in calls]
    assert done == sorted(done) and {t for _, t in calls} == {20 * 64}
    with pytest.raises(ParameterError, match="progress: expected a callable"):
        parapend.track(controller="mpc", progress="bar")


def test_update_seconds_grows_with_the_horizon_the_limit_and_the_forecast():
    from parapend.control.mpc import update_seconds

    base = update_seconds(1.0)
    assert 0 < base < update_seconds(2.0) < update_seconds(2.0, 1.0)
    assert update_seconds(2.0, 1.0) < update_seconds(2.0, 1.0, "ar")


def test_horizon_progress_counts_every_run_in_samples(monkeypatch):
    """``horizon``'s progress: in torque samples (64 a peak period), each run counting its
    own, passed through the receding-horizon runs as they go; nondecreasing to the total."""
    from parapend.control import mpc

    class Res:
        success, status = True, "ok"
        mean_electrical_power = harvested_electrical_power = 0.1
        stored_energy_change, failed_solves = 0.0, 0
        update_times = np.array([1.0, 1e-3])

    def stub(q, *, horizon, t_end, dt, progress, **kw):
        n = int(math.floor(t_end / dt + 1e-9))
        progress(n // 2, n)
        progress(n, n)
        r = Res()
        r.horizon = horizon
        return r

    monkeypatch.setattr(mpc, "mpc_run", stub)
    calls = []
    parapend.horizon(repeat_period=48.0, horizons="0.5,2", forecasts="perfect",
                     baselines="none", warm_up=2.0,
                     progress=lambda d, t: calls.append((d, t)))
    rec = 48 / 8 * 64  # the record (Tp = 8 s) in samples
    total = rec + 2 * (rec + 2 * 64)
    assert {t for _, t in calls} == {total}
    done = [d for d, _ in calls]
    assert done == sorted(done) and done[-1] == total
    assert rec + (rec + 128) / 2 in done  # halfway through the first receding-horizon run
