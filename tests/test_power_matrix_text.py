"""The text report of ``parapend power-matrix``: a unit on every value, and the prefix of
each (W, kW, MW; Wh, kWh, MWh, GWh per year) chosen by its magnitude."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from parapend.performance.figures import _per_year, text_report, with_unit


@pytest.mark.parametrize("wh, text", [
    (41_000.0, "41 kWh/yr"), (41.0, "41 Wh/yr"), (41e6, "41 MWh/yr"), (4.1e10, "41 GWh/yr"),
    (0.0, "0 Wh/yr"), (18_846.9, "18.85 kWh/yr"), (999_960.0, "1 MWh/yr"),
    (math.nan, "n/a")])
def test_annual_energy_takes_the_prefix_of_its_magnitude(wh, text):
    assert _per_year(wh) == text


@pytest.mark.parametrize("w, text", [
    (1.609, "1.609 W"), (0.05, "50 mW"), (1234.6, "1.235 kW"), (-1234.6, "-1.235 kW"),
    (2.5e6, "2.5 MW"), (999.96, "1 kW"), (0.0, "0 W"), (math.inf, "n/a")])
def test_a_power_takes_the_prefix_of_its_magnitude(w, text):
    assert with_unit(w, "W") == text


def test_the_report_says_a_unit_on_every_value():
    """41 kWh a year reads as kWh (it printed "0.041 MWh/yr"); the matrix's cells carry W,
    its rows m and its columns s. The numbers are the inputs', scaled by the prefix."""
    p = np.array([[41_000.0 / 8766, 1234.6], [math.nan, 0.05]])
    ds = xr.Dataset({"power_mean": (("hm0", "te"), p)},
                    coords={"hm0": [1.0, 2.0], "te": [7.0, 8.0]})
    annual = {"power": {"wh": 41_000.0, "mwh": 0.041, "capacity_factor": 0.215,
                        "bins_without_power": [{"hm0": 2.0, "te": 7.0}],
                        "missing_frequency": 0.1},
              "limit_power": {"wh": 2.5e6, "mwh": 2.5}}
    out = {"device": "prescribed-heave", "realizations": 1, "waves": 8.0, "seeds": [0],
           "te_over_tp": 0.9, "computed_bins": 4, "resumed_bins": 0, "seconds": 1.0,
           "executor": "serial", "store": None, "failed_solves": 0, "annual_energy": annual,
           "netcdf": None, "zarr": None, "csv": None}
    text = text_report(ds, out, [])
    assert "mean annual energy (8766 h/yr): optimum 41 kWh/yr, limit 2.5 MWh/yr" in text
    assert "capacity factor 0.215 (21.5 % of the rated power's energy)" in text
    assert "(Hm0 2 m, te 7 s)" in text
    table = text.split("columns te:\n")[1].split("\n\n")[0].splitlines()
    assert table[0].split() == ["Hm0", "\\", "te", "7", "s", "8", "s"]
    assert table[2].split() == ["1", "m", "4.677", "W", "1.235", "kW"]
    assert table[3].split() == ["2", "m", "n/a", "50", "mW"]
