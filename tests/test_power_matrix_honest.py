"""``power-matrix`` honest: no impossible number is a success, a
bin without power (``no_power``) is at rest and counted at 0 W, the headline power with an
efficiency is the electrical one (``mechanical_power`` beside it), the buoy's body is solved
in the matrix's water, and the mode and the completeness of the annual energy reach the
text, the JSON and the NetCDF.

Independent sources: the bounds each device states (the gamma -> 0 limit, the radiation
bound, electrical <= mechanical), the closed form ``AEP = 8766 h sum max(P, 0) f``, the
single-point API (``parapend.sea`` through the take-off, ``parapend.buoy``), and for the
water the BEM's linearity in ``rho`` (the radiation bound and the flux both scale as
``rho``). The solver is replaced by a stub where only the bookkeeping is tested.
"""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.performance.solve import BOUND_TOL, verdict

KW = {"hs": "1,2", "te": "6,7", "realizations": 2, "waves": 3, "workers": 1}


def _stub(table, efficiency=False):
    """solve_bin from ``table[i][j] = (power, status)`` (the limit 10 W; with
    ``efficiency`` an electrical power of 0.8 P where P > 0, 1.25 P where P < 0)."""
    def solve_bin(spec, i, j, r):
        p, status = table[i][j]
        out = {"power": p, "limit_power": 10.0, "uniform_power": 0.5, "status": status}
        if efficiency:
            out["electrical_power"] = 0.8 * p if p > 0 else 1.25 * p
        return out
    return solve_bin


@pytest.fixture
def stub(monkeypatch):
    import parapend.performance.solve as solve

    def use(table, efficiency=False):
        monkeypatch.setattr(solve, "solve_bin", _stub(table, efficiency))
    return use


# -- no impossible number is a success ---------------------------------------------------

@pytest.mark.parametrize("vals, status", [
    ({"power": 5.0, "limit_power": 10.0}, "converged"),
    ({"power": 10.0 * (1 + 0.5 * BOUND_TOL), "limit_power": 10.0}, "converged"),
    ({"power": 10.0 * (1 + 2 * BOUND_TOL), "limit_power": 10.0}, "above_bound"),
    ({"power": 500.0, "radiation_bound_power": 400.0}, "above_bound"),
    ({"power": -5.0, "limit_power": 1.0}, "converged"),  # a loss is possible, a rest bin
    ({"power": 2.0, "electrical_power": 2.5, "limit_power": 10.0}, "above_bound"),
    ({"power": 2.0, "electrical_power": 1.6, "limit_power": 10.0}, "converged"),
    ({"power": math.nan, "limit_power": 10.0}, "nonfinite"),
    ({"power": 1.0, "radiation_bound_power": math.inf}, "nonfinite"),
    ({"power": 1.0, "electrical_power": math.nan, "limit_power": 10.0}, "nonfinite"),
    ({"power": math.nan, "radiation_bound_power": 1.0, "status": "no_power"}, "nonfinite"),
    ({"power": math.nan, "limit_power": 1.0, "status": "stalled"}, "stalled"),
])
def test_an_impossible_number_is_never_a_success(vals, status):
    vals = {"status": "converged", **vals}
    assert verdict(vals)["status"] == status


def test_a_bin_above_its_bound_is_stored_as_such_and_not_counted(stub, tmp_path):
    """The (1, 1) bin's 12 W exceeds its 10 W limit: status above_bound, out of the
    statistics, and the AEP says it has no power there (incomplete, with bounds)."""
    stub([[(1.0, "converged"), (2.0, "converged")], [(3.0, "converged"), (12.0, "converged")]])
    (tmp_path / "s.csv").write_text("hs,te,frequency\n1,6,0.25\n1,7,0.25\n2,6,0.25\n2,7,0.25\n")
    r = parapend.power_matrix(**KW, scatter=str(tmp_path / "s.csv"))
    ds = r.to_dataset()
    from parapend.maps.spec import _CODE

    assert (ds["status"].values[1, 1] == _CODE["above_bound"]).all()
    assert r.failed_solves == 2
    assert r.statistics["power"]["count"] == [[2, 2], [2, 0]]
    assert r.operating_mode[1][1] is None and r.power_matrix[1][1] is None
    a = r.annual_energy["power"]
    assert not a["complete"] and r.annual_energy_mwh is None
    assert a["wh"] == pytest.approx(8766.0 * 0.25 * (1 + 2 + 3), rel=1e-15)
    # the bin above its bound at that bound (its gamma -> 0 limit, 10 W), not at the
    # largest finished bin's power (3 W), which bounds nothing
    assert a["wh_bounds"][1] == pytest.approx(8766.0 * 0.25 * (1 + 2 + 3 + 10), rel=1e-15)


# -- no power is a bin at rest ---------------------------------------------------------------

def test_no_power_is_a_bin_at_rest_counted_at_zero(stub, tmp_path):
    """A solve whose every motion loses (status no_power, as the buoy's) is the device at
    rest: 0 W in the matrix, mode rest, counted in a complete AEP (it was a bin without a
    result, and the AEP incomplete). A negative converged optimum rests as well."""
    stub([[(2.0, "converged"), (-0.5, "no_power")], [(-1.0, "converged"), (4.0, "converged")]])
    (tmp_path / "s.csv").write_text("hs,te,count\n1,6,1\n1,7,1\n2,6,1\n2,7,1\n")
    r = parapend.power_matrix(**KW, scatter=str(tmp_path / "s.csv"))
    assert r.operating_mode == [["rotation", "rest"], ["rest", "rotation"]]
    assert r.power_matrix == [[2.0, 0.0], [0.0, 4.0]]
    assert r.failed_solves == 0
    assert r.statistics["power"]["mean"][0][1] == -0.5  # the optimum as solved
    a = r.annual_energy["power"]
    assert a["complete"] and r.annual_energy_complete is True
    # 8766 h sum P f over the bins it counted, all four
    pm, f = np.array(r.power_matrix), np.array(r.frequency)
    assert a["counted_frequency"] == 1.0 and a["rest_frequency"] == 0.5
    assert a["wh"] == pytest.approx(8766.0 * float(np.sum(pm * f)), rel=1e-15)
    assert r.annual_energy_mwh == pytest.approx(a["wh"] / 1e6, rel=1e-15)
    # no capture width is negative, and the matrix's lies between its min and max
    ds = r.to_dataset()
    for s in ("matrix", "min", "max"):
        assert (ds[f"capture_width_{s}"].values >= 0).all()
    cw = ds["capture_width_matrix"].values
    assert (ds["capture_width_min"].values <= cw).all()
    assert (cw <= ds["capture_width_max"].values).all()


def test_text_json_and_netcdf_carry_the_mode_and_the_completeness(stub, tmp_path, capsys):
    stub([[(2.0, "converged"), (-0.5, "no_power")], [(1.0, "converged"), (4.0, "converged")]])
    (tmp_path / "s.csv").write_text("hs,te,count\n1,6,1\n1,7,1\n2,6,1\n2,7,1\n")
    (tmp_path / "t.csv").write_text("hs,te\n1,6\n9,9\n")
    base = ["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "1", "--waves",
            "3", "--workers", "1"]
    nc = tmp_path / "m.nc"
    assert main([*base, "--scatter", str(tmp_path / "s.csv"), "--netcdf", str(nc)]) == 0
    text = capsys.readouterr().out
    assert "operating mode of the bins: 3 rotation; 1 rest" in text
    assert "complete: every sea state of the site lies in a bin with a result" in text
    assert "mean annual energy (8766 h/yr): optimum 15.34 kWh/yr" in text  # 1.75 W
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        assert ds.attrs["annual_energy_complete"] == 1
        assert ds.attrs["hours_per_year"] == 8766.0
        assert ds["operating_mode"].values.tolist() == [[1, 0], [1, 1]]
        assert ds["operating_mode"].attrs["flag_meanings"] == "no_result rest rotation"
    nc2 = tmp_path / "t.nc"
    assert main([*base, "--timeseries", str(tmp_path / "t.csv"), "--netcdf", str(nc2),
                 "--json"]) == 3  # incomplete: the annual energy is no resolved answer
    out = json.loads(capsys.readouterr().out)
    assert out["annual_energy_complete"] is False and out["hours_per_year"] == 8766.0
    assert out["operating_mode"] == [["rotation", "rest"], ["rotation", "rotation"]]
    with xr.open_dataset(nc2) as ds:
        assert ds.attrs["annual_energy_complete"] == 0
        assert ds.attrs["annual_energy_uncounted_frequency"] == 0.5
        # a sea state outside every bin: no upper bound (NaN in the file)
        lo, hi = ds.attrs["annual_energy_mwh_bounds"]
        assert lo == pytest.approx(8766.0 * 0.5 * 2.0 / 1e6, rel=1e-15) and math.isnan(hi)


# -- the efficiency: the headline is electrical --------------------------------------------

def test_with_an_efficiency_the_headline_power_is_electrical(stub, tmp_path, capsys):
    """power (the matrix, capture width and AEP) is the electrical power; the motion's
    mechanical power is mechanical_power, in the Dataset, the JSON and the text."""
    stub([[(2.0, "converged"), (-1.0, "converged")], [(3.0, "converged"), (5.0, "converged")]],
         efficiency=True)
    (tmp_path / "s.csv").write_text("hs,te,count\n1,6,1\n1,7,1\n2,6,1\n2,7,1\n")
    r = parapend.power_matrix(**KW, efficiency=0.8, scatter=str(tmp_path / "s.csv"))
    st = r.statistics
    assert st["power"]["mean"] == [[1.6, -1.25], [pytest.approx(2.4), 4.0]]
    assert st["mechanical_power"]["mean"] == [[2.0, -1.0], [3.0, 5.0]]
    assert st["electrical_power"]["mean"] == st["power"]["mean"]
    assert r.power_matrix == [[1.6, 0.0], [pytest.approx(2.4), 4.0]]
    a = r.annual_energy
    assert a["power"]["wh"] == pytest.approx(8766.0 * 0.25 * (1.6 + 2.4 + 4.0), rel=1e-14)
    assert a["mechanical_power"]["wh"] == pytest.approx(8766.0 * 0.25 * 10.0, rel=1e-14)
    ds = r.to_dataset()
    assert "electrical" in ds["power"].attrs["long_name"]
    assert ds["mechanical_power"].attrs["units"] == "W"
    assert main(["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "1",
                 "--waves", "3", "--workers", "1", "--efficiency", "0.8", "--scatter",
                 str(tmp_path / "s.csv")]) == 0
    text = capsys.readouterr().out
    assert "mean electrical power (the take-off's output" in text
    assert "mean annual energy (8766 h/yr): electrical 17.53 kWh/yr" in text  # 2 W
    assert "mechanical 21.92 kWh/yr" in text and ", electrical" not in text.split("yr): ")[1]


def test_the_prescribed_devices_electrical_bin_is_sea_through_the_take_off():
    """Against the single-point API: the bin's power is parapend.sea's optimum on the same
    record through the take-off (generating x eta, motoring / eta), its mechanical_power
    sea's power."""
    from parapend.performance.resource import repeat_period
    from parapend.performance.solve import electrical_power

    r = parapend.power_matrix(hs="1,2", tp="6,7", realizations=1, waves=3, workers=1,
                              efficiency=0.7)
    s = parapend.sea(hs=2.0, tp=7.0, repeat_period=repeat_period(3, 7.0), seed=0)
    assert r.statistics["mechanical_power"]["mean"][1][1] == pytest.approx(s.power_w,
                                                                           rel=1e-12)
    e = electrical_power(s, 0.7)
    assert r.statistics["power"]["mean"][1][1] == pytest.approx(e, rel=1e-12)
    assert r.power_matrix[1][1] == pytest.approx(max(e, 0.0), rel=1e-12)
    assert e <= s.power_w


# -- out of memory ---------------------------------------------------------------------------

def test_out_of_memory_names_this_commands_options(monkeypatch, capsys):
    import parapend.maps.run as mr

    def boom(*a, **kw):
        raise MemoryError

    monkeypatch.setattr(mr, "run_spec", boom)  # the engine, as the command calls it
    assert main(["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "1",
                 "--waves", "3", "--workers", "1"]) == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert "out of memory" in err and "--realizations" in err and "--waves" in err
    assert "--points" not in err


# -- the buoy in the matrix's water --------------------------------------------------------

def test_the_buoys_body_is_solved_in_the_matrixs_water(monkeypatch):
    """--density and --depth reach the body's BEM (it was solved at 1025 kg/m^3 in deep
    water whatever they said, the flux at theirs); at a finite depth on the body's own grid
    from its last point below the bins' band (Capytaine's finite-depth Green function is
    NaN at the grid's 100 s wave)."""
    from parapend.hydro import bem
    from parapend.performance import buoy_device

    seen = {}

    def cylinder(r, d, **kw):
        seen.update(kw, radius=r, draft=d)
        raise ParameterError("stop: seen")

    monkeypatch.setattr(bem, "cylinder", cylinder)
    monkeypatch.setattr(buoy_device, "_HYDRO", {})
    with pytest.raises(ParameterError, match="stop: seen"):
        parapend.power_matrix(device="buoy", hs="0.5,1", tp="2.5,3", realizations=1,
                              waves=4, density=1000.0, depth=20.0)
    assert seen["rho"] == 1000.0 and seen["water_depth"] == 20.0
    full = bem.body_frequencies(0.5 / bem.GEOMETRY_PANELS, g=9.81, water_depth=20.0)
    grid = seen["omega"]
    assert np.array_equal(grid, full[full.size - grid.size:])  # the body's own points
    assert grid[0] > full[0]
    # deeper than two wavelengths of the grid's lowest frequency is deep water (Capytaine's
    # finite-depth coefficients were NaN at 1e300 m): the body's deep-water problem
    for depth in (1e4, 1e300):
        seen.clear()
        with pytest.raises(ParameterError, match="stop: seen"):
            parapend.power_matrix(device="buoy", hs="0.5,1", tp="2.5,3", realizations=1,
                                  waves=4, density=1000.0, depth=depth)
        assert seen["water_depth"] == math.inf and seen["omega"] == "body"
        assert seen["rho"] == 1000.0


def test_a_hydro_datasets_water_is_used_and_contradictions_refused(monkeypatch, tmp_path):
    """With --hydro the dataset's rho and depth make the flux; --density or --depth that
    differ from them are refused in one line, equal ones accepted."""
    from parapend.performance import buoy_device

    f = tmp_path / "body.nc"
    f.write_bytes(b"not read: the loader is replaced")
    h = SimpleNamespace(rho=1000.0, g=9.81, water_depth=30.0)
    monkeypatch.setattr(buoy_device, "body_hydro", lambda spec: (h, None))
    monkeypatch.setattr(buoy_device, "prepare", lambda spec: None)
    monkeypatch.setattr(buoy_device, "band", lambda spec: (1.0, 8.0))
    kw = {"device": "buoy", "hydro": str(f), "hs": "0.5,1", "tp": "2.5,3",
          "realizations": 1, "waves": 4}
    for extra, needle in (({"density": 1025.5}, "density: the dataset .* rho = 1000 "),
                          ({"depth": 40.0}, "depth: the dataset .* in 30 m of water, got 40"),
                          ({"depth": 1.0}, "depth: expected at least Hm0 / 0.78")):
        with pytest.raises(ParameterError, match=needle):
            parapend.power_matrix(**kw, **extra)
    h.water_depth = 1.0  # a dataset in water too shallow for the largest bin's waves
    with pytest.raises(ParameterError, match="depth: expected at least Hm0 / 0.78 = 1.282"):
        parapend.power_matrix(**kw)
    h.water_depth = math.inf
    with pytest.raises(ParameterError, match="depth: the dataset .* in deep water, got 30"):
        parapend.power_matrix(**kw, depth=30.0)

    import parapend.maps.run as mr

    class Ran(Exception):
        pass

    def ran(spec, *a, **k):
        raise Ran

    monkeypatch.setattr(mr, "run_spec", ran)
    h.water_depth = 30.0
    with pytest.raises(Ran):  # the dataset's own values given again: accepted
        parapend.power_matrix(**kw, density=1000.0, depth=30.0)


@pytest.mark.slow
def test_the_buoys_bound_and_flux_scale_with_the_waters_density():
    """The BEM is linear in rho: A, B and F scale with it, so the radiation bound
    |F a|^2 / (8 B) does, and so does the flux rho g sum S c_g df. Solved at 1025 and at
    1000 kg/m^3 (deep water), bound and flux are in the ratio 1000/1025 to the BEM's
    rounding, the record being the same."""
    kw = {"device": "buoy", "hs": "0.1,0.2", "tp": "2.6,3.0", "realizations": 1,
          "waves": 4, "harmonics": 24, "workers": 1}
    a = parapend.power_matrix(**kw).to_dataset()
    b = parapend.power_matrix(**kw, density=1000.0).to_dataset()
    ratio = 1000.0 / 1025.0
    np.testing.assert_allclose(b["wave_energy_flux_matrix"].values,
                               ratio * a["wave_energy_flux_matrix"].values, rtol=1e-12)
    np.testing.assert_allclose(b["radiation_bound_power_mean"].values,
                               ratio * a["radiation_bound_power_mean"].values, rtol=1e-6)
    assert (b["status"].values == 0).all() and (a["status"].values == 0).all()


@pytest.mark.slow
def test_a_deep_finite_depth_is_the_deep_water_answer():
    """A second method: at 50 m (under two wavelengths of the BEM's lowest frequency, so
    Capytaine's finite-depth Green function) the coupled power, the radiation bound and the
    flux of Tp 2.6-3 s waves (wavelengths 10-14 m, k h above 20) are deep water's (the
    infinite-depth Green function) to the BEM's discretization, 1e-3."""
    kw = {"device": "buoy", "hs": "0.1,0.2", "tp": "2.6,3.0", "realizations": 1,
          "waves": 4, "workers": 1}
    a = parapend.power_matrix(**kw).to_dataset()
    b = parapend.power_matrix(**kw, depth=50.0).to_dataset()
    for name in ("power_mean", "radiation_bound_power_mean", "wave_energy_flux_matrix"):
        np.testing.assert_allclose(b[name].values, a[name].values, rtol=1e-3)
    assert (b["status"].values == 0).all()
