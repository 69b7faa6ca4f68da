"""One result protocol for every public function (DESIGN.md section 4): each
result has ``to_dict`` (= ``--json``), ``to_dataset`` (units and long_name on every
variable and coordinate, the command and version in the attributes), ``plot`` (a matplotlib
figure), ``save`` by extension (.json, .csv with a row of units, .nc, a figure) and a short
repr; the files read back to what the result holds."""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import parapend

ROOT = Path(__file__).resolve().parents[1]


def _sweep(tmp):
    store = str(tmp / "m.zarr")
    parapend.sweep(omega="1.7:1.8:2", delta="-0.3,-0.2", harmonics=4, store=store, workers=1)
    return parapend.map(store=store, plot=str(tmp / "m.png"))


FAST = {
    "optimize": lambda tmp: parapend.optimize(harmonics=8),
    "optimize-si": lambda tmp: parapend.optimize(harmonics=8, length=1.0, mass=10.0,
                                                 frequency=0.9, amplitude=0.09),
    "optimize-pto": lambda tmp: parapend.optimize(harmonics=8, gamma=0.03, torque_limit=2.5),
    "optimize-all": lambda tmp: parapend.optimize(harmonics=8, gamma=0.05, method="all"),
    "threshold": lambda tmp: parapend.threshold(harmonics=8),
    "damping-sweep": lambda tmp: parapend.damping_sweep(points=3, harmonics=4, length=2.0,
                                                        mass=3.0),
    "harmonics": lambda tmp: parapend.harmonics(n_from=2, n_to=4),
    "pto-curve": lambda tmp: parapend.pto_curve(points=2),
    "simulate": lambda tmp: parapend.simulate(periods=3, length=2.0, mass=3.0),
    "basins": lambda tmp: parapend.basins(resolution=8, periods=20),
    "track": lambda tmp: parapend.track(periods=20, harmonics=8, length=1.0, mass=10.0),
    "track-runs": lambda tmp: parapend.track(periods=20, harmonics=8, runs=2),
    "sea": lambda tmp: parapend.sea(repeat_period=96, cutoff=2),
    "horizon": lambda tmp: parapend.horizon(repeat_period=48.0, forecasts="none",
                                            baselines="extremum", records=1),
    "sweep-map": _sweep,
    # the sweep's own result: one axis (a curve, not a heat map), in SI
    "sweep": lambda tmp: parapend.sweep(omega="1.7,1.8", harmonics=4, workers=1, length=1.0,
                                        mass=10.0),
}
SLOW = {
    "rotations": lambda tmp: parapend.rotations(),
    "buoy": lambda tmp: parapend.buoy(harmonics=8),
    "buoy-sweep": lambda tmp: parapend.buoy(wave_period="1.8,2.2", harmonics=8),
    "buoy-mpc": lambda tmp: parapend.buoy(controller="mpc", harmonics=8, repeat_period=20.0),
    "track-mpc": lambda tmp: parapend.track(periods=20, controller="mpc", torque_limit=1.0,
                                            gamma=0.01, length=1.0, mass=10.0),
    "power-matrix": lambda tmp: parapend.power_matrix(hs="1,2", tp="6,7", realizations=1,
                                                      waves=10, workers=1),
    "figure": lambda tmp: parapend.figure("1", plot=str(tmp / "f.png")),
    # the hull (the barge's BEM, cached after the first): one wave, and a sweep
    "hull": lambda tmp: parapend.buoy(dofs="surge,heave,pitch", harmonics=8),
    "hull-sweep": lambda tmp: parapend.buoy(dofs="surge,heave,pitch", harmonics=8,
                                            wave_period="5,7", winding=1),
}


def _check(result, tmp: Path):
    import matplotlib.figure

    # the JSON object, and the .json file that holds it
    d = result.to_dict()
    text = json.dumps(d, allow_nan=False)
    assert json.loads(text) == d
    saved = result.save(tmp / "r.json")
    assert json.loads(Path(saved).read_text()) == d
    # the Dataset: units and a long name on every variable and coordinate
    ds = result.to_dataset()
    for name in ds.variables:
        attrs = ds[name].attrs
        assert isinstance(attrs.get("units"), str) and attrs["units"], (name, attrs)
        assert isinstance(attrs.get("long_name"), str) and attrs["long_name"], (name, attrs)
    assert ds.attrs["command"] and ds.attrs["parapend_version"] == parapend.__version__
    # every number of the JSON object is in the Dataset, as a 0-d variable or an attribute
    for k, v in d.items():
        if isinstance(v, (int, float)) and not isinstance(v, bool) and k in ds.data_vars \
                and ds[k].ndim == 0:
            assert float(ds[k].values) == pytest.approx(v, rel=0, abs=0), k
    # NetCDF round trip
    result.save(tmp / "r.nc")
    with xr.open_dataset(tmp / "r.nc") as back:
        for name, var in ds.data_vars.items():
            if var.dtype.kind in "fiu":
                np.testing.assert_array_equal(back[name].values, var.values, err_msg=name)
                assert back[name].attrs["units"] == var.attrs["units"]
    # CSV: one table (names, then units, then the values), where the result has one
    numeric = any(v.dtype.kind in "biuf" for v in ds.data_vars.values())
    if not numeric:
        with pytest.raises(parapend.ParameterError, match="path: this result holds no numbers"):
            result.save(tmp / "r.csv")
    elif len(ds.dims) <= 1:
        result.save(tmp / "r.csv")
        rows = list(csv.reader((tmp / "r.csv").read_text().splitlines()))
        names, units = rows[0], rows[1]
        assert len(names) == len(units) and names
        for i, n in enumerate(names):
            assert units[i] == ds[n].attrs["units"]
            col = np.array([float(r[i]) for r in rows[2:]])
            np.testing.assert_array_equal(col, np.atleast_1d(ds[n].values.astype(float)),
                                          err_msg=n)
    elif result.command in ("basins", "power-matrix"):
        # a grid's table: one row per grid point (per bin), the grid's coordinates first
        result.save(tmp / "r.csv")
        rows = list(csv.reader((tmp / "r.csv").read_text().splitlines()))
        first = ["dphi", "phi"] if result.command == "basins" else ["hm0"]
        assert rows[0][:len(first)] == first and len(rows) > 2
    else:
        with pytest.raises(parapend.ParameterError, match="path: a CSV file holds one table"):
            result.save(tmp / "r.csv")
    with pytest.raises(parapend.ParameterError, match=r"path: expected a file name ending"):
        result.save(tmp / "r.txt")
    # the figure
    fig = result.plot()
    assert isinstance(fig, matplotlib.figure.Figure) and fig.axes
    result.save(tmp / "r.png")
    assert (tmp / "r.png").read_bytes()[:4] == b"\x89PNG"
    # a short repr, with the result's name
    r = repr(result)
    assert r.endswith(")") and "Result(" in r and len(r) < 400, r


@pytest.mark.parametrize("name", list(FAST))
def test_every_result_follows_the_protocol(name, tmp_path):
    _check(FAST[name](tmp_path), tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SLOW))
def test_every_result_follows_the_protocol_slow(name, tmp_path):
    _check(SLOW[name](tmp_path), tmp_path)


def test_si_results_are_si_in_every_file(tmp_path):
    """Given the pendulum in SI, the saved curves are in SI: seconds, N m, W, rad/s, and the
    numbers are the non-dimensional ones times the scales (an independent conversion)."""
    r = parapend.optimize(harmonics=8, length=1.0, mass=10.0, frequency=0.9, amplitude=0.09)
    u = r.physical_units
    s = r.samples()
    ds = r.to_dataset()
    assert set(ds.dims) == {"time_s"}
    assert {"torque_nm", "instantaneous_power_w", "theta_dot_rad_per_s"} <= set(ds.data_vars)
    # the headline mean and the curve have a name each: power_w (0-d), instantaneous_power_w
    assert ds["power_w"].ndim == 0 and float(ds["power_w"]) == r.power_w
    assert "torque" not in ds.data_vars and "time" not in ds.coords
    g, length, m = 9.81, 1.0, 10.0
    t0 = math.sqrt(length / g)
    np.testing.assert_allclose(ds["time_s"].values, s["time"] * t0, rtol=1e-14)
    np.testing.assert_allclose(ds["torque_nm"].values, s["torque"] * m * g * length,
                               rtol=1e-14)
    np.testing.assert_allclose(ds["instantaneous_power_w"].values,
                               s["instantaneous_power"] * m * g * length / t0,
                               rtol=1e-14)
    # the mean of the saved power is the headline power in watts (one period, uniform grid)
    assert float(ds["instantaneous_power_w"].values.mean()) == pytest.approx(r.power_w,
                                                                             rel=1e-6)
    assert u.power == pytest.approx(m * g * length / t0, rel=1e-14)
    assert ds["instantaneous_power_w"].attrs["units"] == "W"
    assert ds["time_s"].attrs["units"] == "s"
    # omega in rad/s beside the non-dimensional one, as a Capytaine or WecOptTool user reads it
    assert r.omega_rad_per_s == pytest.approx(2 * math.pi * 0.9, rel=1e-14)
    assert ds["omega_rad_per_s"].attrs["units"] == "rad/s"
    c = parapend.optimize(harmonics=8, length=1.0, mass=10.0, frequency=0.9, amplitude=0.09,
                          damping_coefficient=0.3)
    assert c.damping_coefficient == pytest.approx(0.3, rel=1e-14)
    tr = parapend.track(periods=20, harmonics=8, length=1.0, mass=10.0)
    tds = tr.to_dataset()
    assert set(tds.dims) == {"time_s"} and tds["torque_nm"].attrs["units"] == "N m"
    np.testing.assert_allclose(tds["torque_nm"].values, tr.run.torque * m * g * length,
                               rtol=1e-14)
    th = parapend.threshold(length=1.0, mass=10.0, frequency=0.9, amplitude=0.09,
                            harmonics=8)
    tds = th.to_dataset()
    assert tds["damping_threshold_coefficient"].attrs["units"] == "N m s/rad"


_PRIVATE = re.compile(r"(?<![\w.])(?:r|rec|res|result|opt|push|ds|run|out|mapped|a|b|f|m)"
                      r"\._[a-z]\w*")


def test_nothing_a_user_or_the_cli_needs_is_behind_an_underscore():
    """The docs, the tutorials and the command line reach results through public names
    (``r._run``, ``rec._dataset`` and the like are gone)."""
    files = [*ROOT.joinpath("docs").rglob("*.md"), ROOT / "README.md",
             *ROOT.joinpath("src", "parapend", "cli").glob("*.py")]
    found = []
    for f in files:
        for i, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
            if _PRIVATE.search(line) and "_negative_number_matcher" not in line:
                found.append(f"{f.relative_to(ROOT)}:{i}: {line.strip()}")
    assert not found, "\n".join(found)


def test_every_torque_limit_has_its_si_form():
    """horizon takes the limit in N m as well as in m g l: the same runs (m g l = 98.1 N m for
    the default 1 m, 10 kg pendulum at g = 9.81), and not both at once."""
    kw = dict(repeat_period=48.0, forecasts="none", baselines="extremum", records=1)
    a = parapend.horizon(torque_limit=1.0, **kw)
    b = parapend.horizon(torque_limit_nm=10.0 * 9.81 * 1.0, **kw)
    assert b.torque_limit == pytest.approx(1.0, rel=1e-14)
    np.testing.assert_allclose(b.baseline_power, a.baseline_power, rtol=1e-9)
    with pytest.raises(parapend.ParameterError, match="torque-limit-nm: give either"):
        parapend.horizon(torque_limit=1.0, torque_limit_nm=5.0, **kw)
