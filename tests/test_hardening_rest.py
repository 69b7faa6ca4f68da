"""The rest of the audit's list: a coefficient that is not a number named in one line, the
data-range error that says one period once and names --cutoff for a sea, and ``buoy
--save`` in every format a result writes."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro.bem import Hydro

PERIOD = 1.3
PEND = ["--mass", "20", "--length", "0.3", "--damping-coefficient", "0.5", "--harmonics", "8"]


def _hydro():
    w = np.linspace(1.0, 5.0, 9)
    return Hydro(w, np.full(9, 100.0), np.full(9, 50.0), np.full(9, 1000.0 + 0j), 8000.0,
                 400.0)


@pytest.mark.parametrize("field", [0, 1, 2, 3])
def test_a_coefficient_that_is_not_a_number_is_named(field):
    args = [np.linspace(1.0, 2.0, 3), np.ones(3), np.ones(3), np.ones(3), 1.0, 1.0]
    args[field] = "x"
    name = ("omega", "added_mass", "radiation_damping", "excitation")[field]
    with pytest.raises(ParameterError, match=f"^hydro: expected {name} as an array of"):
        Hydro(*args)


def test_the_data_range_error_says_one_period_once():
    h = _hydro()
    w = 6.0  # above the data's 5 rad/s
    with pytest.raises(ParameterError) as err:
        h.check_covers(w, w)
    text = str(err.value)
    t = f"{2 * math.pi / w:.4g} s"
    assert text.startswith(f"wave-period: {t} lies outside") and " to " + t not in text
    assert f"{2 * math.pi / 5.0:.4g} s to {2 * math.pi / 1.0:.4g} s" in text


@pytest.mark.parametrize("name", ["tp", "record"])
def test_a_sea_outside_the_data_names_cutoff(name):
    with pytest.raises(ParameterError, match=rf"^{name}: the sea's components from .* "
                                             r"--cutoff .*a smaller --cutoff$"):
        _hydro().check_covers(2.0, 12.0, name=name)


def test_the_cli_names_cutoff_for_a_short_sea(capsys):
    assert main(["buoy", "--hs", "0.1", "--tp", "1.2", "--cutoff", "6"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--cutoff" in err and "rad/s" not in err


@pytest.mark.parametrize("suffix", [".json", ".csv", ".png"])
def test_buoy_save_writes_every_format(sphere_nc, tmp_path, capsys, suffix):
    path = tmp_path / f"motion{suffix}"
    argv = ["buoy", "--hydro", sphere_nc, "--wave-period", str(PERIOD), *PEND, "--json",
            "--save", str(path)]
    assert main(argv) == 0
    shown = json.loads(capsys.readouterr().out)
    data = path.read_bytes()
    if suffix == ".json":
        assert json.loads(data)["power_w"] == shown["power_w"]
    elif suffix == ".csv":
        head, units, first = data.decode().splitlines()[:3]
        assert head.split(",")[0] == "time_s" and units.split(",")[0] == "s"
        assert len(first.split(",")) == len(head.split(","))
    else:
        assert data[:4] == b"\x89PNG"


def test_buoy_save_refuses_an_unknown_format(capsys, tmp_path):
    assert main(["buoy", "--save", str(tmp_path / "motion.xyz")]) == 2
    assert "--save" in capsys.readouterr().err


# --- sizes refused before the work; estimates printed without a terminal -----------------
def test_a_dataset_of_too_many_frequencies_is_refused_by_the_api():
    from parapend import limits
    from parapend.hydro.bem import HullHydro

    n = limits.BUOY_MAX_DATASET_FREQUENCIES + 1
    w = np.linspace(1.0, 5.0, n)
    with pytest.raises(ParameterError, match=f"^hydro: expected at most {n - 1} frequencies, "
                                             f"got {n} "):
        Hydro(w, np.ones(n), np.ones(n), np.ones(n, complex), 8000.0, 400.0)
    with pytest.raises(ParameterError, match=f"got {n} "):
        HullHydro(omega=w, added_mass=np.zeros((n, 3, 3)), radiation_damping=np.zeros(
            (n, 3, 3)), excitation=np.zeros((n, 3), complex), hydrostatic_stiffness=np.eye(3),
            mass=1.0, pitch_inertia=None)


def test_a_dataset_file_of_too_many_frequencies_is_one_line(tmp_path, capsys, monkeypatch):
    """A dataset of a million frequencies (the audit's size, under the file cap when it is
    compressed) is refused by its omega coordinate's length, before its values are merged
    or any solve starts."""
    from capytaine.io.xarray import separate_complex_values

    n = 10**6
    ds = _hydro().to_dataset()
    big = ds.reindex(omega=np.linspace(1.0, 5.0, n), method="nearest")
    path = tmp_path / "many.nc"
    enc = {v: {"zlib": True} for v in separate_complex_values(big).data_vars}
    separate_complex_values(big).to_netcdf(path, encoding=enc)

    def merged(_):
        raise AssertionError("merged before the count was checked")

    monkeypatch.setattr("capytaine.io.xarray.merge_complex_values", merged)
    assert main(["buoy", "--hydro", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.splitlines() == [err] and f"got {n} " in err and "frequencies" in err


def _stop(*args, **kwargs):
    raise ParameterError("stopped before the work (test)")


def test_the_sweep_estimate_is_printed_when_stderr_is_not_a_terminal(capsys, monkeypatch,
                                                                      tmp_path):
    """A million-point map (about 2 ms a point at N = 24, one process: half an hour) is
    announced on stderr even piped; pytest's captured stderr is not a terminal."""
    from parapend.maps import run

    monkeypatch.setattr(run, "run_spec", _stop)
    argv = ["sweep", "--omega", "1:2:1000000", "--workers", "1", "--store",
            str(tmp_path / "m.zarr")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    seconds = 10**6 * run.POINT_SECONDS
    assert "sweep: 1000000 points: roughly " in err
    assert f"roughly {round(seconds / 60)} minutes" in err
    # a rerun over a store holding half of it announces the half left
    monkeypatch.setattr(run, "stored_points", lambda spec, store, overwrite: spec.points // 2)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "sweep: 1000000 points (500000 of them in the store): roughly " in err
    assert f"roughly {round(seconds / 120)} minutes" in err


def test_the_persistence_estimate_is_printed_when_stderr_is_not_a_terminal(capsys, monkeypatch,
                                                                           tmp_path):
    from parapend.maps import run

    monkeypatch.setattr(run, "run_spec", _stop)
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    argv = ["persistence", "--mass", "1", "--length", "0.3", "--damping-coefficient", "2e-4",
            "--generator-damping", "5e-4", "--hs", "0.005:0.04:8", "--tp", "0.2:0.6:9",
            "--duration", "300", "--realizations", "2000", "--store", str(tmp_path / "p.zarr")]
    assert main(argv) == 2
    assert "persistence: 72 sea states x 2000 realizations: roughly " in capsys.readouterr().err


# --- a sea state's steepness: refused past breaking, warned past 1/20 --------------------
def test_sea_steepness_is_hs_over_the_peak_wavelength():
    from parapend.seas import sea_steepness

    # deep water: lambda_p = g Tp^2 / (2 pi); Tp = 8 s is 99.92 m at g = 9.81
    assert sea_steepness(2.0, 8.0) == pytest.approx(2.0 / (9.81 * 64 / (2 * math.pi)),
                                                    rel=1e-15)
    assert 9.81 * 64 / (2 * math.pi) == pytest.approx(99.92, abs=0.01)


@pytest.mark.parametrize("argv", [
    ["sea", "--hs", "3", "--tp", "3"],  # the prescribed-heave pendulum
    ["buoy", "--hs", "20", "--tp", "2.5"],  # the audit's M --hs 20
    ["buoy", "--dofs", "surge,heave,pitch", "--hs", "3", "--tp", "3"],  # before the BEM
    ["horizon", "--hs", "3", "--tp", "3"],
])
def test_a_sea_past_breaking_is_refused_in_one_line(argv, capsys, monkeypatch):
    """``Hs / lambda_p`` above 1/7, the regular wave's breaking limit, is refused before
    any record or BEM (the hull's barge is never solved: its BEM raises here)."""
    from parapend.hydro import bem

    def no_bem(*a, **k):
        raise AssertionError("the BEM ran before the sea was checked")

    monkeypatch.setattr(bem, "_solve", no_bem)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    hs, tp = float(argv[argv.index("--hs") + 1]), float(argv[argv.index("--tp") + 1])
    steep = hs / (9.81 * tp * tp / (2 * math.pi))
    assert steep > 1 / 7
    assert err.splitlines() == [err] and "error: hs: " in err and "past breaking (1/7)" in err
    assert f"Hs / lambda_p = {steep:.3g}" in err
    assert f"at most {tp * tp * 9.81 / (14 * math.pi):.4g} m" in err


def test_a_steep_sea_is_warned_in_the_result():
    from parapend.hydro.result import _sea_validity

    # 1/20 < Hs / lambda_p < 1/7: a validity warning; gentler: none; a measured record: none
    steep = 0.5 / (9.81 * 2.5**2 / (2 * math.pi))
    assert 1 / 20 < steep < 1 / 7
    (text,) = _sea_validity({"kind": "irregular", "hs": 0.5, "tp": 2.5})
    assert text.startswith("linear theory: ") and f"= {steep:.3g} exceeds 0.05" in text
    assert _sea_validity({"kind": "irregular", "hs": 0.2, "tp": 2.5}) == []
    assert _sea_validity({"kind": "irregular", "record": "eta.csv"}) == []
    assert _sea_validity({"kind": "regular", "height_m": 1.0, "period_s": 2.0}) == []


def test_the_buoy_in_a_steep_sea_warns(sphere_nc):
    import parapend

    r = parapend.buoy(hydro=sphere_nc, hs=0.3, tp=1.9, repeat_period=8 * 1.9, mass=20.0,
                      length=0.3, damping_coefficient=0.5, cutoff=2.0)
    steep = 0.3 / (9.81 * 1.9**2 / (2 * math.pi))
    assert 1 / 20 < steep < 1 / 7
    assert [w for w in r.validity_warnings if "Hs / lambda_p" in w] == [
        f"linear theory: the sea's steepness Hs / lambda_p = {steep:.3g} exceeds 0.05 "
        "(1/20; breaking at 1/7): its steepest waves' nonlinearity is left out"]
