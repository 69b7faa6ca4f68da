"""Hardening of ``power-matrix``: bad input, absurd sizes, unwritable outputs,
odd files and the annual energy's bookkeeping, each refused before any bin runs (one line,
exit 2, the API's ParameterError with the same text) or answered with a correct result.

Independent sources: the solver's own checks (``parapend sea`` refuses the same bins one
at a time), the closed form ``AEP = 8766 h sum max(P, 0) f`` on hand-made matrices, the
deep-water flux ``rho g^2 m_-1 / (4 pi)`` for an unbounded depth, and the store's ``done``
mask read back. The solver is replaced by a stub where only the bookkeeping is tested.
"""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.performance import matrix_spec
from parapend.performance.annual import (
    HOURS_PER_YEAR,
    annual_energy,
    bin_power,
    read_scatter,
    read_series,
)
from parapend.performance.check import MAX_BINS, check_bins, check_size
from parapend.performance.resource import energy_flux, record_spectrum, repeat_period

BASE = {"--hs": "1,2", "--te": "6,7", "--realizations": "1", "--waves": "3",
        "--workers": "1"}


def _argv(extra):
    opts = dict(BASE)
    opts.update(zip(extra[::2], extra[1::2]))
    return ["power-matrix", *(x for kv in opts.items() for x in kv)]


def _kwargs(extra):
    """The API's keywords of the same options."""
    kw = {"hs": "1,2", "te": "6,7", "realizations": 1, "waves": 3, "workers": 1}
    for k, v in zip(extra[::2], extra[1::2]):
        name = k[2:].replace("-", "_")
        try:
            v = float(v) if name not in ("hs", "te", "tp", "device", "scatter", "timeseries",
                                         "netcdf", "csv", "zarr", "store") else v
        except ValueError:
            pass
        if name in ("realizations", "workers", "harmonics", "winding") and isinstance(v, float):
            v = int(v)
        kw[name] = v
    return kw


@pytest.fixture
def no_solve(monkeypatch):
    """Fail the test if any bin would run (every case here is refused before the work)."""
    import parapend.maps.run as mr

    def refuse(*a, **k):
        raise AssertionError("the engine ran: the input was not checked before the work")

    monkeypatch.setattr(mr, "run_spec", refuse)


CASES = [
    # input errors that used to fail in every bin, exit 0 with an empty matrix
    (["--hs", "1e-7,2e-7"], "hs: expected bin centres of at least 1e-06 m"),
    (["--hs", "1e-8,2e-8"], "hs: expected bin centres of at least 1e-06 m"),
    (["--harmonics", "1"], "harmonics: expected at least 2 K = 2"),
    (["--gravity", "1e-3"], "hs, cutoff, gravity: the bin Hm0 1 m, te 6 s"),
    (["--gravity", "1e-4"], "gravity: expected a number in [0.001, 1000]"),
    # long work refused by a bin: the refusal alone, no estimate line before it
    (["--hs", "0.5:5:100", "--te", "4:13:100", "--gravity", "1e-3"],
     "hs, cutoff, gravity: the bin Hm0 0.5 m, te 4 s"),
    (["--device", "buoy", "--damping-coefficient", "1e300"], "damping-coefficient:"),
    (["--device", "buoy", "--damping-coefficient", "1e30"], "damping-coefficient:"),
    # silent wrong numbers
    (["--depth", "5e-324"], "depth: expected a water depth of at least 0.001 m"),
    (["--depth", "1e-300"], "depth: expected a water depth of at least 0.001 m"),
    (["--depth", "1e-299"], "depth: expected a water depth of at least 0.001 m"),
    (["--depth", "1"], "depth: expected at least Hm0 / 0.78 = 2.564 m"),
    (["--efficiency", "5e-324"], "efficiency: expected a number in [1e-06, 1]"),
    (["--efficiency", "1e-7"], "efficiency: expected a number in [1e-06, 1]"),
    # the buoy's body is solved in the matrix's water: a depth it does not float in, a
    # density no water has, waves that break, all before its BEM
    (["--device", "buoy", "--depth", "0.3", "--hs", "0.1,0.2"],
     "draft: expected less than the water depth 0.3 m, got 0.5"),
    (["--device", "buoy", "--body", "sphere", "--depth", "0.45", "--hs", "0.1,0.2"],
     "radius: expected less than the water depth 0.45 m, got 0.5"),
    (["--device", "buoy", "--depth", "1"], "depth: expected at least Hm0 / 0.78 = 2.564 m"),
    (["--device", "buoy", "--depth", "5e-324"], "depth: expected a water depth of at least"),
    (["--device", "buoy", "--density", "1e-300"], "density: expected a number in [500, 2000]"),
    # absurd sizes
    (["--hs", "0.5:5:1000", "--te", "4:13:1000"],
     "hs: at most 10000 bins in all, got 1000 Hm0 x 1000 te = 1000000; with 1000 te bins, "
     "--hs may have at most 10 bins"),
    (["--hs", "0.5:5:100", "--te", "4:13:1000"], "te: at most 10000 bins in all"),
    (["--hs", "0.5:5:100", "--te", "4:13:100", "--realizations", "1000"],
     "realizations: at most 1000000 solves (bins x realizations) in all, got 10000 bins x "
     "1000 = 10000000; with 10000 bins, --realizations may be at most 100"),
    # output paths checked before the work
    (["--netcdf", "/nonexistent/x.nc"], "netcdf: directory '/nonexistent' does not exist"),
    (["--csv", "/proc/x.csv"], "csv: cannot write '/proc/x.csv'"),
    (["--csv", "/nonexistent/x.csv"], "csv: directory '/nonexistent' does not exist"),
    (["--zarr", "FOREIGN"], "zarr: "),
    (["--netcdf", "DIR"], "is a directory"),
]


@pytest.mark.parametrize("extra, needle", CASES)
def test_refused_before_any_bin_in_one_line(extra, needle, tmp_path, capsys, no_solve):
    extra = [str(tmp_path / "foreign") if v == "FOREIGN" else
             str(tmp_path / "d.nc") if v == "DIR" else v for v in extra]
    (tmp_path / "foreign").mkdir()
    (tmp_path / "d.nc").mkdir()
    (tmp_path / "foreign" / "mine.txt").write_text("a user's file\n")
    code = main(_argv(extra))
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1, err
    assert needle in err, err
    # the API: ParameterError (a ValueError) with the same text
    with pytest.raises(ParameterError) as info:
        parapend.power_matrix(**_kwargs(extra))
    assert str(info.value) == err.strip().split("error: ", 1)[1]
    assert (tmp_path / "foreign" / "mine.txt").exists()


def test_the_neighbours_of_the_refused_run(monkeypatch):
    """One decade inside each refusal the spec is accepted and every bin checks: Hm0 at
    sea's floor, g = 0.01 (q of the largest bin below the cap), 2 harmonics."""
    for kw in ({"hs": "1e-6,2e-6"}, {"gravity": 1e-2}, {"harmonics": 2}):
        spec = matrix_spec(**{"hs": "1,2", "te": "6,7", "realizations": 2, "waves": 3, **kw})
        check_bins(spec)
        check_size(spec, workers=1)
    # the largest sizes that fit: 10 x 1000 bins, 10 000 bins x 100 realizations
    for kw in ({"hs": "0.5:5:10", "te": "4:13:1000"},
               {"hs": "0.5:5:100", "te": "4:13:100", "realizations": 100}):
        spec = matrix_spec(**{"realizations": 1, "waves": 3, **kw})
        assert check_size(spec, workers=1, available=2 << 30)["bins"] == 10_000


def test_every_refusal_is_what_sea_says_of_the_bin():
    """The bin named by the refusal is one that ``parapend sea`` refuses on its own."""
    from parapend.irregular import sea

    spec = matrix_spec(hs="1,2", te="6,7", realizations=1, waves=3, gravity=1e-3)
    with pytest.raises(ParameterError, match="the bin Hm0 1 m, te 6 s"):
        check_bins(spec)
    with pytest.raises(ParameterError, match=r"\|q\(t\)\| <= 1000"):
        sea(**spec.sea_kwargs(0, 0, 0))
    spec = matrix_spec(hs="1,2", te="6,7", realizations=1, waves=3, harmonics=1)
    with pytest.raises(ParameterError, match="harmonics: expected at least 2 K = 2"):
        sea(**spec.sea_kwargs(0, 0, 0))


def test_workers_are_at_most_the_bins(monkeypatch):
    """--workers 256 for 4 bins starts 4 processes (it started 57)."""
    import parapend.maps.run as mr

    seen = {}

    class Pool:
        def __init__(self, workers, start=True):
            seen["workers"] = workers
            raise KeyboardInterrupt  # stop here: nothing started

    monkeypatch.setattr(mr, "_LocalPool", Pool)
    monkeypatch.setattr(mr, "_forkserver_available", lambda: True)
    spec = matrix_spec(hs="1,2", te="6,7", realizations=1, waves=3)
    with pytest.raises(KeyboardInterrupt):
        mr.run_spec(spec, None, workers=256)
    assert seen["workers"] == 4


def test_memory_estimate_names_the_workers_that_fit():
    spec = matrix_spec(hs="0.5:5:10", te="4:13:10", realizations=1, waves=3)
    with pytest.raises(ParameterError, match=r"workers: 100 processes need about 29.3 GB "
                                             r"\(300 MB each\), 2 GB is available; "
                                             r"--workers may be at most 6$"):
        check_size(spec, workers=256, available=2 << 30)
    est = check_size(spec, workers=6, available=2 << 30)
    assert est["processes"] == 6 and est["bins"] == 100 and est["memory_bytes"] <= 2 << 30
    # the default is not refused: it starts as many processes as the memory holds
    est = check_size(spec, workers=None, available=2 << 30)
    assert est["processes"] == min(6, os.cpu_count() or 1)
    assert MAX_BINS == 10_000


def test_a_400_wave_record_is_never_over_400_waves():
    """waves * tp rounds up at some tp (400.0000001 peak periods: every bin refused)."""
    tps = np.linspace(1.0, 30.0, 20001)
    assert any(400.0 * t / t > 400.0 for t in tps)  # the rounding this guards against
    for t in tps:
        rp = repeat_period(400.0, float(t))
        assert rp / t <= 400.0 and rp == pytest.approx(400.0 * t, rel=1e-15)
    # below the top the product is left as it is (the stores' records unchanged)
    assert all(repeat_period(50.0, float(t)) == 50.0 * t for t in tps[::97])


# -- files ---------------------------------------------------------------------------------

def test_site_files_are_read_with_a_cap(tmp_path):
    (tmp_path / "bom.csv").write_bytes(b"\xef\xbb\xbfhs,te,frequency\n1,6,0.5\n2,7,0.5\n")
    assert np.array_equal(read_scatter(tmp_path / "bom.csv", (1.0, 2.0), (6.0, 7.0), "te"),
                          [[0.5, 0.0], [0.0, 0.5]])
    (tmp_path / "bom2.csv").write_bytes(b"\xef\xbb\xbfhs,te\n1,6\n")
    assert [list(v) for v in read_series(tmp_path / "bom2.csv", "te")] == [[1.0], [6.0]]
    (tmp_path / "big.csv").write_text("hs,te,frequency\n1,6," + "1" * 200_000 + "\n")
    with pytest.raises(ParameterError, match="scatter: not a CSV of numbers .*field larger"):
        read_scatter(tmp_path / "big.csv", (1.0, 2.0), (6.0, 7.0), "te")
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "zero.csv").symlink_to("/dev/zero")
    for name, kind in (("fifo", "a FIFO"), ("zero.csv", "a character device")):
        with pytest.raises(ParameterError, match=f"scatter: expected a regular CSV file, got "
                                                 f"{kind}"):
            read_scatter(tmp_path / name, (1.0, 2.0), (6.0, 7.0), "te")
        with pytest.raises(ParameterError, match=f"timeseries: expected a regular CSV file, "
                                                 f"got {kind}"):
            read_series(tmp_path / name, "te")
    (tmp_path / "huge.csv").write_bytes(b"hs,te\n" + b"1,6\n" * (2 << 20))
    with pytest.raises(ParameterError, match="timeseries: .* is larger than"):
        read_series(tmp_path / "huge.csv", "te")


def test_the_command_refuses_a_fifo_site_in_one_line(tmp_path, capsys, no_solve):
    os.mkfifo(tmp_path / "fifo")
    for opt in ("--scatter", "--timeseries"):
        assert main(_argv([opt, str(tmp_path / "fifo")])) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "FIFO" in err, err


def test_counts_near_the_top_of_the_float_range(tmp_path):
    """Counts of 1e308 summed to inf: every share 0, an AEP of 0 marked complete."""
    (tmp_path / "c.csv").write_text("hs,te,count\n1,6,1e308\n2,7,1.7e308\n")
    f = read_scatter(tmp_path / "c.csv", (1.0, 2.0), (6.0, 7.0), "te")
    assert f[0, 0] == pytest.approx(1 / 2.7, rel=1e-15)
    assert f[1, 1] == pytest.approx(1.7 / 2.7, rel=1e-15)
    (tmp_path / "s.csv").write_text("hs,te,count\n1,6,5e-324\n2,7,5e-324\n")
    f = read_scatter(tmp_path / "s.csv", (1.0, 2.0), (6.0, 7.0), "te")
    assert f[0, 0] == 0.5 and f[1, 1] == 0.5


def test_an_unbounded_depth_is_deep_water():
    f, s = record_spectrum(2.0, 8.0, 400.0)
    deep = energy_flux(f, s, gravity=9.81)
    m1 = float(np.sum(s / f) * (f[1] - f[0]))
    assert deep == pytest.approx(1025 * 9.81**2 * m1 / (4 * math.pi), rel=1e-12)
    for h in (1e4, 1e300):
        assert energy_flux(f, s, depth=h, gravity=9.81) == pytest.approx(deep, rel=1e-9)


# -- the annual energy ---------------------------------------------------------------------

P = np.array([[1.0, -2.0], [np.nan, 4.0]])
F = np.array([[0.25, 0.25], [0.125, 0.25]])


def test_annual_energy_is_never_negative_and_an_incomplete_one_has_bounds():
    """8766 h sum max(P, 0) f over the counted bins; the (2, 1) bin has no power (1/8 of
    the year) and 1/8 lies outside the matrix: the lower bound counts that quarter at 0 W,
    and nothing bounds the sea states outside the bins (no upper bound); without them the
    missing bin at its own bound (7 W, not the largest finished bin's 4 W)."""
    assert np.array_equal(bin_power(P), [[1.0, 0.0], [np.nan, 4.0]], equal_nan=True)
    bound = np.full((2, 2), 7.0)
    a = annual_energy(P, F, outside_frequency=0.125, bound=bound)
    lo = HOURS_PER_YEAR * (1.0 * 0.25 + 0.0 * 0.25 + 4.0 * 0.25)
    assert a["wh"] == lo == HOURS_PER_YEAR * 1.25
    assert not a["complete"]
    # missing_frequency agrees with complete: the bins' share and the outside share
    assert a["uncounted_frequency"] == 0.25 == a["missing_frequency"]
    assert a["missing_bin_frequency"] == 0.125
    assert a["wh_bounds"] == [lo, None] and "outside" in a["upper_bound_note"]
    c = annual_energy(P, F / F.sum(), bound=bound)
    lo_c = lo / F.sum()
    assert c["wh_bounds"] == pytest.approx([lo_c, lo_c + HOURS_PER_YEAR * 7.0 * 0.125
                                            / F.sum()], rel=1e-15)
    assert annual_energy(P, F / F.sum())["wh_bounds"] == [pytest.approx(lo_c), None]
    assert a["hours_per_year"] == 8766.0
    assert a["counted_frequency"] == 0.75 and a["rest_frequency"] == 0.25
    # complete: a plain number, no bounds
    b = annual_energy(np.nan_to_num(P, nan=3.0), F[:, :] / F.sum())
    assert b["complete"] and "wh_bounds" not in b
    want = HOURS_PER_YEAR * float(np.sum(np.maximum(np.nan_to_num(P, nan=3.0), 0) * F)) / F.sum()
    assert b["wh"] == pytest.approx(want, rel=1e-15)
    # every optimum negative: the pendulum rests everywhere, AEP 0, not negative
    c = annual_energy(-np.abs(np.nan_to_num(P, nan=1.0)), F / F.sum())
    assert c["wh"] == 0.0 and c["complete"] and c["rest_frequency"] == pytest.approx(1.0)


def _stub(powers, fail=()):
    """A solve_bin replacement: the bin's power from ``powers``, raising in ``fail``."""
    def solve_bin(spec, i, j, r):
        if (i, j) in fail:
            raise RuntimeError("a solver fault")
        p = powers[i][j]
        return {"power": p, "limit_power": abs(p) + 1.0, "uniform_power": p / 2,
                "status": "converged"}
    return solve_bin


def test_a_failed_bin_is_retried_by_the_next_run(tmp_path, monkeypatch):
    import parapend.performance.solve as solve

    monkeypatch.setattr(solve, "solve_bin", _stub([[1.0, 2.0], [3.0, 4.0]], fail={(0, 1)}))
    store = str(tmp_path / "m.zarr")
    kw = {"hs": "1,2", "te": "6,7", "realizations": 2, "waves": 3, "workers": 1,
          "store": store}
    first = parapend.power_matrix(**kw)
    assert first.computed_bins == 4 and first.failed_solves == 2
    from parapend.maps.store import open_sweep

    done = open_sweep(store)["done"].values
    assert not done[0, 1].any() and done[0, 0].all() and done[1].all()
    monkeypatch.setattr(solve, "solve_bin", _stub([[1.0, 2.0], [3.0, 4.0]]))
    second = parapend.power_matrix(**kw)
    assert second.computed_bins == 1 and second.resumed_bins == 3
    assert second.failed_solves == 0
    assert second.power_matrix == [[1.0, 2.0], [3.0, 4.0]]


def test_the_command_reports_rest_bins_and_an_incomplete_aep(tmp_path, monkeypatch, capsys):
    """A negative optimum is a bin at rest (0 W); a sea state outside the matrix makes the
    AEP incomplete: null in the JSON, bounds instead, and no capacity factor but bounds."""
    import parapend.performance.solve as solve

    monkeypatch.setattr(solve, "solve_bin", _stub([[1.0, -2.0], [3.0, 4.0]]))
    (tmp_path / "t.csv").write_text("hs,te\n1,6\n1,7\n2,7\n9,9\n")
    argv = _argv(["--timeseries", str(tmp_path / "t.csv"), "--rated-power", "10"])
    assert main(argv + ["--json"]) == 3  # the annual energy incomplete: no resolved answer
    out = json.loads(capsys.readouterr().out)
    assert out["operating_mode"] == [["rotation", "rest"], ["rotation", "rotation"]]
    assert out["power_matrix"] == [[1.0, 0.0], [3.0, 4.0]]
    assert out["hours_per_year"] == 8766.0
    a = out["annual_energy"]["power"]
    assert out["annual_energy_complete"] is False and out["annual_energy_mwh"] is None
    assert out["capacity_factor"] is None
    lo = 8766.0 * (1.0 * 0.25 + 0.0 * 0.25 + 4.0 * 0.25)  # (1, 6), (1, 7) at rest, (2, 7)
    assert a["wh"] == pytest.approx(lo, rel=1e-15)
    # the sea state outside every bin: nothing bounds its power, so no upper bound
    assert a["wh_bounds"][0] == pytest.approx(lo, rel=1e-15) and a["wh_bounds"][1] is None
    assert a["capacity_factor_bounds"][0] == pytest.approx(lo / 8766 / 10, rel=1e-15)
    assert a["capacity_factor_bounds"][1] is None
    assert a["uncounted_frequency"] == 0.25 == a["missing_frequency"]
    assert not a["complete"]
    # the JSON's AEP is 8766 h sum P f over the bins it counted
    pm = np.array(out["power_matrix"])
    freq = np.array(out["frequency"])
    assert np.array_equal(freq, [[0.25, 0.25], [0.0, 0.25]])
    assert a["wh"] == pytest.approx(8766.0 * float(np.sum(pm * freq)), rel=1e-15)
    assert a["counted_frequency"] == float(freq.sum())
    assert main(argv) == 3
    text = capsys.readouterr().out
    assert "optimum at least 10.96 kWh/yr" in text  # 1.25 W, no upper bound
    assert "incomplete: 0.25 of the year has no power" in text
    assert "outside the matrix's bins, where nothing bounds the power" in text
    assert "capacity factor at least 0.125 (no upper bound) (incomplete)" in text
    assert "1 bins with a negative mean optimum: the pendulum rests there" in text


@pytest.mark.slow
def test_a_large_damping_rests_every_bin_and_the_aep_is_zero(tmp_path, capsys):
    """--gamma 2: every bin's optimum is a forced turn per wave (negative); the device rests,
    so the AEP is 0 Wh (it printed -1478 Wh/yr), complete."""
    (tmp_path / "s.csv").write_text("hs,te,frequency\n1,6,0.5\n2,7,0.5\n")
    assert main(_argv(["--gamma", "2", "--scatter", str(tmp_path / "s.csv")])
                + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    means = np.array(out["statistics"]["power"]["mean"], dtype=float)
    assert np.all(means < 0)
    assert out["operating_mode"] == [["rest", "rest"], ["rest", "rest"]]
    assert out["annual_energy"]["power"]["wh"] == 0.0
    assert out["annual_energy_complete"] is True and out["annual_energy_mwh"] == 0.0


@pytest.mark.slow
def test_the_old_failing_inputs_neighbours_give_a_result(capsys):
    """One decade inside the refusals the command runs and every bin converges or rests:
    Hm0 at sea's floor, g = 0.01."""
    for extra in (["--hs", "1e-6,2e-6"], ["--gravity", "1e-2"]):
        assert main(_argv(extra) + ["--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["failed_solves"] == 0
        assert all(m in ("rotation", "rest") for row in out["operating_mode"] for m in row)


def test_the_zarr_export_is_checked_before_and_written_after(tmp_path, monkeypatch, capsys):
    import parapend.performance.solve as solve

    monkeypatch.setattr(solve, "solve_bin", _stub([[1.0, 2.0], [3.0, 4.0]]))
    z = tmp_path / "out.zarr"
    assert main(_argv(["--zarr", str(z), "--netcdf", str(tmp_path / "o.nc"),
                       "--csv", str(tmp_path / "o.csv")])) == 0
    capsys.readouterr()
    assert (z / "zarr.json").exists() and Path(tmp_path / "o.nc").stat().st_size > 0
    # an earlier export is replaced; a --store never is
    assert main(_argv(["--zarr", str(z)])) == 0
    capsys.readouterr()
    store = tmp_path / "s.zarr"
    assert main(_argv(["--store", str(store)])) == 0
    capsys.readouterr()
    assert main(_argv(["--zarr", str(store)])) == 2
    assert "zarr: " in capsys.readouterr().err


def test_long_work_is_announced_before_it_starts(caplog, no_solve):
    """300 solves of 50-wave records on 2 processes: about 3 s each, 8 minutes (over the
    2 minutes a matrix in memory may take without --time-limit: given here)."""
    import logging

    with caplog.at_level(logging.INFO, logger="parapend.performance"), \
            pytest.raises(AssertionError, match="the engine ran"):
        parapend.power_matrix(hs="0.5:5:10", te="4:13:10", workers=2, time_limit=3600.0)
    (msg,) = [r.getMessage() for r in caplog.records if r.name == "parapend.performance"]
    assert msg.startswith("power matrix: 100 bins x 3 realizations = 300 solves of 50-wave "
                          "records on 2 processes: roughly 8 minutes")
    caplog.clear()  # one of each: singular
    with caplog.at_level(logging.INFO, logger="parapend.performance"), \
            pytest.raises(AssertionError, match="the engine ran"):
        parapend.power_matrix(hs="0.5:5:10", te="4:13:10", workers=1, realizations=1,
                              time_limit=3600.0)
    (msg,) = [r.getMessage() for r in caplog.records if r.name == "parapend.performance"]
    assert msg.startswith("power matrix: 100 bins x 1 realization = 100 solves of 50-wave "
                          "records on 1 process: roughly"), msg


def test_a_resume_announces_what_is_left(caplog, no_solve, tmp_path):
    """A rerun over a store that holds half the points announces half the work (it
    announced the whole matrix's); another sweep's store counts for nothing."""
    import logging

    import zarr

    from parapend.maps.store import _prepare, make_store_dir, stored_points
    from parapend.performance import matrix_spec

    grid = {"hs": "0.5:5:10", "te": "4:13:10"}
    spec = matrix_spec(**grid)
    store = tmp_path / "m.zarr"
    make_store_dir(store)
    _prepare(store, spec, "test", False)
    group = zarr.open_group(store, mode="r+")
    for v in spec.variables:  # the first half's blocks finished (status 0, powers 1 W)
        a = group[v]
        a[:5] = 0 if a.dtype.kind in "iu" else 1.0
    group["done"][:5] = True
    assert stored_points(spec, store) == 150 and stored_points(spec, store, True) == 0
    assert stored_points(matrix_spec(hs="0.5:5:10", te="4:13:9"), store) == 0
    with caplog.at_level(logging.INFO, logger="parapend.performance"), \
            pytest.raises(AssertionError, match="the engine ran"):
        parapend.power_matrix(**grid, workers=2, store=str(store))
    (msg,) = [r.getMessage() for r in caplog.records if r.name == "parapend.performance"]
    assert msg.startswith("power matrix: 100 bins x 3 realizations = 300 solves of 50-wave "
                          "records (150 of them in the store) on 2 processes: roughly "
                          "225 s"), msg


def test_the_buoys_flux_is_of_the_water_its_body_was_solved_in(monkeypatch):
    """A --hydro dataset's own rho and depth make the flux (it was 1025 kg/m^3 in deep
    water whatever the dataset said); a g other than the pendulum's, or a rho no water has,
    is refused."""
    from types import SimpleNamespace

    from parapend.performance import buoy_device

    spec = SimpleNamespace(hydro="body.nc")
    for (rho, g, depth), want in (((1000.0, 9.81, math.inf), (1000.0, None)),
                                  ((1025.0, 9.81, 30.0), (1025.0, 30.0))):
        h = SimpleNamespace(rho=rho, g=g, water_depth=depth)
        monkeypatch.setattr(buoy_device, "body_hydro", lambda s, h=h: (h, None))
        assert buoy_device.water_of(spec) == want
    for (rho, g), needle in (((1e-300, 9.81), "rho = 1e-300 kg/m^3"),
                             ((1025.0, 9.80665), "g = 9.80665 m/s^2")):
        h = SimpleNamespace(rho=rho, g=g, water_depth=math.inf)
        monkeypatch.setattr(buoy_device, "body_hydro", lambda s, h=h: (h, None))
        with pytest.raises(ParameterError,
                           match=f"hydro: the dataset of body.nc .*{re.escape(needle)}"):
            buoy_device.water_of(spec)


@pytest.mark.parametrize("opt", ["--hydro", "--mesh"])
def test_a_device_or_fifo_as_the_buoys_file_is_refused_unread(opt, tmp_path, capsys,
                                                               no_solve):
    """/dev/zero (or a link to it) was read whole for the store's digest: memory without
    end; a FIFO blocked for ever."""
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "zero.nc").symlink_to("/dev/zero")
    for path, kind in ((tmp_path / "fifo", "a FIFO"), (tmp_path / "zero.nc", "a device"),
                       ("/dev/zero", "a device"), (tmp_path, "a directory")):
        assert main(_argv(["--device", "buoy", opt, str(path)])) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1, err
        assert f"{opt[2:]}: expected a regular file, got {kind}" in err, err


def test_another_sweeps_store_is_refused_before_the_announcement(caplog, no_solve, tmp_path):
    """A resume over a store of another sweep (here other Te bins) exits before it announces
    hours of work it will not do; with --overwrite it is announced and runs."""
    import logging

    from parapend.maps.store import _prepare, make_store_dir
    from parapend.performance import matrix_spec

    store = tmp_path / "m.zarr"
    make_store_dir(store)
    _prepare(store, matrix_spec(hs="0.5:5:10", te="4:13:9"), "test", False)
    with caplog.at_level(logging.INFO, logger="parapend.performance"), \
            pytest.raises(ParameterError, match="holds a different sweep"):
        parapend.power_matrix(hs="0.5:5:10", te="4:13:10", workers=2, store=str(store))
    assert not [r for r in caplog.records if r.name == "parapend.performance"]
    with caplog.at_level(logging.INFO, logger="parapend.performance"), \
            pytest.raises(AssertionError, match="the engine ran"):
        parapend.power_matrix(hs="0.5:5:10", te="4:13:10", workers=2, store=str(store),
                              overwrite=True)
    (msg,) = [r.getMessage() for r in caplog.records if r.name == "parapend.performance"]
    assert msg.startswith("power matrix: 100 bins x 3 realizations"), msg
