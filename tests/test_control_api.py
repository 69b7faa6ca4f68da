"""The Python API of ``horizon`` and ``track`` (both controllers) under bad values: each is a
one-line :class:`~parapend.errors.ParameterError` that names the parameter as the command
line does (#33), never a bare ``TypeError``/``ValueError``/``IndexError``; and the options
the signature allows are accepted as keywords."""

import math

import numpy as np
import pytest

import parapend
from parapend.errors import ParameterError


@pytest.mark.parametrize("kw, match", [
    ({"horizons": None}, "horizons: expected a comma list of numbers"),
    ({"horizons": ["x"]}, "horizons: expected a comma list of numbers"),
    ({"horizons": [[1, 2]]}, "horizons: expected a comma list of numbers"),
    ({"horizons": True}, "horizons: expected a comma list of numbers"),
    ({"horizons": b"1"}, "horizons: expected a comma list of numbers"),
    ({"horizons": "a"}, "horizons: expected a comma list of numbers"),
    ({"horizons": [1.0, math.nan]}, "horizons: expected a finite number"),
    ({"forecasts": None}, "forecasts: expected names from perfect, ar"),
    ({"forecasts": 3}, "forecasts: expected names from perfect, ar"),
    ({"forecasts": ["perfect", 3]}, "forecasts: expected names"),
    ({"baselines": None}, "baselines: expected names from tracker, extremum"),
    ({"records": "x"}, "records: expected an integer"),
    ({"update_interval": None}, "update-interval: expected a real number"),
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
