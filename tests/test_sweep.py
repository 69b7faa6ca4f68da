"""Design maps: sweep engine, resumable Zarr store, Dask execution, heat maps."""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import parapend
from parapend import maps as sw
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.maps import compute as sw_compute
from parapend.maps import store as sw_store

SRC = str(Path(__file__).resolve().parents[1] / "src")
# a 4 x 3 map in 4 blocks of 3 points (runs along delta): small, but several blocks
GRID = {"omega": "1.6:2.0:4", "delta": "-0.3,-0.2,-0.1", "gamma": 0.01}


def _files(store: Path) -> dict:
    """Every file of a store and the hash of its bytes."""
    return {str(p.relative_to(store)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(store.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The 4 x 3 map computed in one process, uninterrupted, into a store."""
    store = tmp_path_factory.mktemp("ref") / "map.zarr"
    run = sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    return store, run


# -- every point is parapend.optimize --------------------------------------------------------

def test_every_point_equals_optimize(reference):
    _, run = reference
    ds = run.dataset
    assert ds["power"].dims == ("omega", "delta")
    assert bool(ds["done"].all())
    for o in ds["omega"].values:
        for d in ds["delta"].values:
            r = parapend.optimize(omega=float(o), delta=float(d), gamma=0.01, harmonics=24)
            v = ds.sel(omega=o, delta=d)
            assert abs(float(v["power"]) - r.power) <= 1e-9
            assert float(v["uniform_power"]) == pytest.approx(r.uniform_power, abs=1e-15)
            assert float(v["limit_power"]) == pytest.approx(r.limit_power, abs=1e-15)
            assert sw.STATUSES[int(v["status"])] == r.status
            # the closed forms beside them (Eqs. 17, 19): omega |delta| / 2 - gamma omega^2
            assert float(v["uniform_power"]) == pytest.approx(
                o * abs(d) / 2 - 0.01 * o**2, abs=1e-12)
            assert float(v["limit_power"]) == pytest.approx(2 * o * abs(d) / np.pi, abs=1e-12)
    # the warm start (continuation along delta) found no branch above the global search
    assert float(ds["branch_gap"].max()) == 0.0
    # units and names in the attributes, the command and version in the dataset's
    assert ds["power"].attrs["units"] == "m g l sqrt(g/l)"
    assert "long_name" in ds["status"].attrs and ds["status"].attrs["flag_meanings"].split() \
        == list(sw.STATUSES)
    assert ds.attrs["command"] == "test" and ds.attrs["parapend_version"] == parapend.__version__


def _same_search(a, b):
    """Two FourierSearch results equal bit for bit: every run and the evidence."""
    assert len(a.runs) == len(b.runs)
    for r, s in zip(a.runs, b.runs):
        assert np.array_equal(r.x, s.x)
        assert (r.power, r.status, r.iterations, r.seed, r.points, r.strict_maximum,
                r.gradient_norm) == (s.power, s.status, s.iterations, s.seed, s.points,
                                     s.strict_maximum, s.gradient_norm)
    assert a.best.power == b.best.power and np.array_equal(a.best.x, b.best.x)
    assert a.evidence == b.evidence


def test_batched_search_is_search_fourier_bit_for_bit():
    """The sweep's batched global search (optimal/batch.py) gives every point exactly what
    search_fourier gives it alone: each run's coefficients, power, status, iterations and
    strictness, and the evidence. Gamma 0, gamma > 0, above gamma* (no power), both signs
    of delta, N below and above the 8-harmonic uniform start, two excitations of one
    shape in one batch with others, and a point with several patterns (handed to
    search_fourier)."""
    from parapend.optimal.batch import search_fourier_batch
    from parapend.optimal.fourier import search_fourier

    for n in (6, 12):
        pts = [(parapend.harmonic(d, om), g) for om in (1.3, 2.2) for d in (-0.4, -0.1, 0.25)
               for g in (0.0, 0.01, 0.4)]
        pts += [(parapend.two_harmonic(-0.3, 1.8), 0.01),
                (parapend.fourier([(1, 0.2, 0.0), (3, 0.15, 0.4)], omega=1.8), 0.01)]
        got = search_fourier_batch(pts, n)
        for (exc, g), (found, problem) in zip(pts, got):
            _same_search(found, search_fourier(exc, n, g))
            if problem is not None:
                assert problem.points == found.runs[0].points
        assert got[-1][1] is None and got[-1][0].evidence.candidate_patterns > 1
        statuses = {f.best.status for f, _ in got}
        assert "converged" in statuses and min(f.best.power for f, _ in got) < 0


def test_batched_problems_and_limit_seeds_are_the_scalar_ones():
    """dq/dt on the grids and the limit seeds, built for many points at once, equal those
    of FourierProblem and limit_seed (any grid, N, excitation, sign of delta)."""
    from parapend.optimal.batch import _limit_seeds, _problems
    from parapend.optimal.fourier import FourierProblem
    from parapend.optimal.limit import limit, limit_seed

    ex = [parapend.harmonic(d, om) for om in (0.3, 1.7, 3.0) for d in (-0.5, -0.02, 0.4)]
    ex += [parapend.two_harmonic(-0.3, 1.8), parapend.square(-0.3, 1.8, 0.05),
           parapend.fourier([(1, 0.2, 0.0), (7, 0.1, 1.0)], omega=1.5)]
    pts = [(e, 0.01) for e in ex]
    for n in (5, 8, 24):
        for grids in (None, [1024] * len(pts)):
            for (e, g), p in zip(pts, _problems(pts, n, grids)):
                q = FourierProblem(e, n, g, None if grids is None else 1024)
                assert q.points == p.points and np.array_equal(q.w, p.w)
        lims = [limit(e) for e in ex[:-1]]
        for lim, x in zip(lims, _limit_seeds(lims, n)):
            assert np.array_equal(x, limit_seed(lim, n).vector)


def _check_pto(ds, n):
    from parapend.pto import optimize_pto

    for g in ds["gamma"].values:
        for t in ds["torque_limit"].values:
            r = optimize_pto(torque_limit=float(t), gamma=float(g), omega=1.8, harmonics=n)
            v = ds.sel(gamma=g, torque_limit=t)
            assert sw.STATUSES[int(v["status"])] == r.status
            assert abs(float(v["power"]) - r.power) <= 1e-9
            assert abs(float(v["electrical_power"]) - r.electrical_power) <= 1e-9


def test_torque_limit_axis_equals_optimize_pto():
    run = sw.sweep(None, omega=1.8, gamma="0.05,0.12", torque_limit="0.5,3", harmonics=4,
                   workers=1)
    ds = run.dataset
    assert ds["power"].dims == ("gamma", "torque_limit") and "branch_gap" not in ds
    _check_pto(ds, 4)


def test_efficiency_axis_headline_is_the_electrical_power(tmp_path, capsys):
    """With an efficiency the map's ``power`` is the electrical power of the electrically
    optimal motion and ``mechanical_power`` that motion's mechanical power (the
    rule of ``optimize``, ``pto-curve`` and ``buoy``), each equal to the same point through
    ``parapend.optimize(..., efficiency=...)``, an independent call (at efficiency 1 the
    three are the ideal optimum); the JSON and the text headline name the electrical power
    and give the mechanical one beside it. An efficiency map is another sweep than the same
    axes in an earlier version's store (there ``power`` was the mechanical power)."""
    store = tmp_path / "m.zarr"
    grid = {"omega": 1.8, "gamma": 0.05, "efficiency": "0.8,1", "harmonics": 4}
    rec = parapend.sweep(store=str(store), **grid, workers=1, length=1.0, mass=10.0)
    ds = rec.dataset
    assert "branch_gap" not in ds and ds["power"].attrs["units"] == "m g l sqrt(g/l)"
    assert "electrical" in ds["power"].attrs["long_name"]
    for eta in (0.8, 1.0):
        r = parapend.optimize(omega=1.8, gamma=0.05, efficiency=eta, harmonics=4)
        v = ds.sel(efficiency=eta)
        assert sw.STATUSES[int(v["status"])] == r.status == "converged"
        assert abs(float(v["power"]) - r.power) <= 1e-9
        assert abs(float(v["mechanical_power"]) - r.mechanical_power) <= 1e-9
        assert float(v["electrical_power"]) == float(v["power"])
    p, m = ds["power"].values, ds["mechanical_power"].values
    assert p[0] < m[0] and p[1] == m[1]  # losses at 0.8, none at 1
    best = rec.largest_power
    k = int(np.argmax(p))
    assert best == {"power": float(p[k]), "mechanical_power": float(m[k]),
                    "efficiency": float(ds["efficiency"][k])}
    units = parapend.units.Units(1.0, 10.0, 9.81)
    assert math.isclose(rec.largest_power_w, units.to_watts(best["power"]), rel_tol=1e-14)
    assert math.isclose(rec.largest_power_mechanical_w,
                        units.to_watts(best["mechanical_power"]), rel_tol=1e-14)
    # its figure (one axis: the curves) names the electrical power, with SI scales beside
    fig = rec.plot()
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[:3] == ["limit (gamma -> 0)", "optimum, electrical power",
                          "mechanical power of the electrical optimum"]
    assert any(c.get_ylabel() == "power (W)" for c in fig.axes[0].child_axes)
    # the command line, resuming the store: the same headline, named
    argv = ["sweep", "--omega", "1.8", "--gamma", "0.05", "--efficiency", "0.8,1",
            "--harmonics", "4", "--workers", "1", "--store", str(store)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert (f"largest electrical power {best['power']:.8f} at efficiency = "
            f"{best['efficiency']:.6g} (mechanical {best['mechanical_power']:.8f})") in text
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["resumed_points"] == 2 and out["largest_power"] == best
    ident = json.loads(sw.sweep_spec(**grid).to_json())
    assert ident.pop("power") == "electrical"  # the earlier identity had no such key


@pytest.mark.slow
def test_infeasible_torque_limit_is_recorded():
    """A torque limit too small at a damping above gamma*: status infeasible (a few
    seconds per such point), kept in the map with its power, never dropped."""
    run = sw.sweep(None, omega=1.8, gamma="0.05,0.12", torque_limit="0.05,3", harmonics=4,
                   workers=1)
    ds = run.dataset
    _check_pto(ds, 4)
    st = [sw.STATUSES[int(c)] for c in ds["status"].values.ravel()]
    assert "infeasible" in st
    assert bool(ds["done"].all()) and not np.isnan(ds["power"].values).any()


def test_failed_points_are_recorded_with_their_status():
    """A square wave's smoothing width must stay below a period / 8: valid at omega = 1.8,
    not at 2.4. That point fails (status "error", values NaN), recorded, not dropped; the
    others equal optimize."""
    run = sw.sweep(None, omega="1.8,2.4", delta="-0.3,-0.2", excitation="square",
                   square_alpha=0.4, harmonics=8, workers=1)
    ds = run.dataset
    assert bool(ds["done"].all())
    st = ds["status"].values
    assert list(st[1]) == [sw.STATUSES.index("error")] * 2
    assert np.isnan(ds["power"].values[1]).all()
    with pytest.raises(ParameterError, match="square"):
        parapend.optimize(omega=2.4, delta=-0.3, excitation="square", square_alpha=0.4)
    for j, d in enumerate((-0.3, -0.2)):
        r = parapend.optimize(omega=1.8, delta=d, excitation="square", square_alpha=0.4,
                              harmonics=8)
        assert sw.STATUSES[int(st[0, j])] == r.status
        assert abs(float(ds["power"].values[0, j]) - r.power) <= 1e-9
    z, failed, *_ = sw.map_data(ds, "power")
    assert failed[:, 1].all() and not failed[:, 0].any() and np.isnan(z[:, 1]).all()


def test_no_power_above_threshold_and_threshold_equals_api():
    run = sw.sweep(None, omega="1.8,2.0", gamma="0,0.1", threshold=True, harmonics=16,
                   workers=1)
    ds = run.dataset
    for o in (1.8, 2.0):
        t = parapend.threshold(omega=o)
        v = ds.sel(omega=o)
        assert np.all(v["damping_threshold"].values == t.damping_threshold)
        assert np.all(v["threshold_status"].values == sw.STATUSES.index(t.status))
    # gamma = 0.1 > gamma* = 0.0856 at the paper's case: nothing to extract, still recorded
    v = ds.sel(omega=1.8, gamma=0.1)
    assert sw.STATUSES[int(v["status"])] == "no_power" and float(v["power"]) < 0
    assert float(ds.sel(omega=1.8)["damping_threshold"][0]) == pytest.approx(0.0855891, 1e-6)


# -- the store ------------------------------------------------------------------------------

def test_resume_recomputes_nothing_and_local_processes_match(reference, tmp_path):
    ref_store, _ = reference
    # a second run on the finished store computes nothing
    again = sw.sweep(ref_store, **GRID, workers=1, block_points=3, command="test")
    assert again.computed_points == 0 and again.resumed_points == 12
    # two local processes write the same bytes as one
    store = tmp_path / "two.zarr"
    run = sw.sweep(store, **GRID, workers=2, block_points=3, command="test")
    assert run.executor == "2 local processes"
    assert _files(store) == _files(ref_store)


def test_resume_after_partial_store(reference, tmp_path):
    """Blocks marked done are kept, the others computed: the store ends byte for byte the
    same. The "done" mask is what counts: data without the mask is recomputed."""
    import zarr

    ref_store, _ = reference
    store = tmp_path / "part.zarr"
    sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    g = zarr.open_group(store, mode="r+")
    g["done"][1:3, :] = False  # as if blocks 1 and 2 never finished
    g["power"][2, :] = 7.0  # data written, mask not: must be recomputed
    run = sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    assert run.computed_points == 6 and run.resumed_points == 6
    assert _files(store) == _files(ref_store)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="kill -9")
def test_kill_9_then_resume_equals_uninterrupted(reference, tmp_path):
    ref_store, _ = reference
    store = tmp_path / "killed.zarr"
    code = ("import sys, time; from parapend import maps as sw\n"
            "def slow(done, total):\n"
            "    print(done, flush=True)\n"
            "    time.sleep(0.3)\n"
            f"sw.sweep(sys.argv[1], **{GRID!r}, workers=1, block_points=3, command='test',"
            " progress=slow)\n")
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.Popen([sys.executable, "-c", code, str(store)], env=env,
                            stdout=subprocess.PIPE, text=True)
    seen = []
    for line in proc.stdout:  # wait until two of the four blocks are in the store
        seen.append(int(line))
        if seen[-1] >= 6:
            break
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    proc.stdout.close()
    assert proc.returncode == -signal.SIGKILL
    import zarr

    done = np.asarray(zarr.open_group(store, mode="r")["done"][...])
    assert 0 < done.sum() < done.size  # interrupted in the middle
    run = sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    assert 0 < run.computed_points < 12
    assert _files(store) == _files(ref_store)


def test_lock_refuses_a_second_sweep(tmp_path):
    store = tmp_path / "locked.zarr"
    store.mkdir()
    with sw_store._locked(store), pytest.raises(ParameterError,
                                          match="^store: .* is being written by another"):
        sw.sweep(store, **GRID, workers=1)
    # after the lock is gone (its process ended), the sweep runs
    assert sw.sweep(store, omega="1.8,1.9", workers=1).computed_points == 2


def test_store_of_another_sweep_is_refused(reference, tmp_path):
    ref_store, _ = reference
    with pytest.raises(ParameterError, match="holds a different sweep"):
        sw.sweep(ref_store, omega="1.6:2.0:5", delta="-0.3,-0.2,-0.1", gamma=0.01,
                 block_points=3)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(ParameterError, match="not a parapend sweep store"):
        sw.sweep(foreign, omega="1.8,1.9")
    assert (foreign / "notes.txt").read_text() == "mine"
    # a creation cut short (its root says so: parapend writes that first) is ours: made
    # again, then computed
    cut = tmp_path / "cut.zarr"
    (cut / "power").mkdir(parents=True)
    (cut / "power" / "zarr.json").write_text("{")
    sw_store._write_marker(cut)
    assert sw.sweep(cut, omega="1.8,1.9", workers=1).computed_points == 2
    assert bool(sw.open_sweep(cut, complete=True)["done"].all())
    # arrays without that root are not recognised as parapend's: refused, kept
    (cut / "zarr.json").unlink()
    with pytest.raises(ParameterError, match="not a parapend sweep store"):
        sw.sweep(cut, omega="1.8,1.9", workers=1, overwrite=True)
    assert (cut / "power" / "zarr.json").is_file()


# -- Dask distributed -----------------------------------------------------------------------

@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    # a real scheduler and two workers talking TCP on loopback (threads of this process:
    # quick to start, and the blocks they compute are the same)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  protocol="tcp", host="127.0.0.1",
                                  dashboard_address="127.0.0.1:0",
                                  silence_logs=50) as c:
        yield c


def test_dask_cluster_writes_the_same_store(reference, cluster, tmp_path):
    ref_store, _ = reference
    store = tmp_path / "dask.zarr"
    run = sw.sweep(store, **GRID, block_points=3, command="test",
                   scheduler=cluster.scheduler_address)
    assert run.executor.startswith("Dask cluster at tcp://127.0.0.1")
    assert _files(store) == _files(ref_store)
    # the command line, on the same cluster: the same arrays (the command attribute differs)
    cli = tmp_path / "cli.zarr"
    assert main(["sweep", "--omega", "1.6:2.0:4", "--delta", "-0.3,-0.2,-0.1", "--gamma",
                 "0.01", "--block-points", "3", "--store", str(cli), "--scheduler",
                 cluster.scheduler_address, "--json"]) == 0
    a, b = sw.open_sweep(cli), sw.open_sweep(ref_store)
    for v in b.data_vars:
        assert np.array_equal(a[v].values, b[v].values, equal_nan=v != "done")


# -- input ----------------------------------------------------------------------------------

@pytest.mark.parametrize("kw,match", [
    ({"omega": "1:2"}, "^omega: expected START:STOP:COUNT"),
    ({"omega": "1:2:x"}, "^omega: expected an integer COUNT"),
    ({"omega": "0:2:3"}, r"^omega: expected a number in \[0.001, 1000\]"),
    ({"delta": "-0.3,,0.2", "omega": "1,2"}, "^delta: expected numbers separated"),
    ({"omega": "1,1"}, "^omega: expected distinct values"),
    ({"omega": 1.8}, "expected at least one axis with two or more values"),
    ({"omega": "1:2:2000", "delta": "-1:1:1000"}, "^omega, delta: expected at most"),
    ({"omega": "1,2", "efficiency": "0,0.5"}, r"^efficiency: expected a number in \(0, 1\]"),
    ({"omega": "1,2", "harmonics": 129}, r"^harmonics: expected an integer in \[1, 128\]"),
    ({"omega": "1,2", "fourier": "1:0.3", "delta": -0.3}, "^delta: not used"),
])
def test_bad_input(kw, match):
    with pytest.raises(ParameterError, match=match):
        sw.sweep_spec(**kw)


def test_parse_axis():
    assert np.array_equal(sw.parse_axis("omega", "1.2:2.4:3"), np.linspace(1.2, 2.4, 3))
    assert sw.parse_axis("delta", "-0.3,-0.1") == (-0.3, -0.1)
    assert sw.parse_axis("gamma", [0, 0.01]) == (0.0, 0.01)


# -- command line and heat map ----------------------------------------------------------------

def test_cli_sweep_map_and_netcdf(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = ["sweep", "--omega", "1.6:2.0:4", "--delta", "-0.3,-0.2,-0.1", "--gamma", "0.01",
            "--block-points", "3", "--workers", "1", "--netcdf", "map.nc", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["points"] == 12 and out["computed_points"] == 12
    assert out["status_counts"] == {"converged": 12}
    # the largest power of the map is at the largest omega |delta| (2 omega |delta| / pi grows)
    assert out["largest_power"]["omega"] == 2.0 and out["largest_power"]["delta"] == -0.3
    ds = sw.open_sweep("map.zarr", complete=True)
    assert ds.attrs["command"].startswith("parapend ")
    nc = sw.open_sweep("map.nc")
    assert np.array_equal(nc["power"].values, ds["power"].values)
    assert np.array_equal(nc["status"].values, ds["status"].values)
    assert main(["map", "--variable", "gain", "--plot", "gain.png", "--json"]) == 0
    m = json.loads(capsys.readouterr().out)
    assert m["x"] == "omega" and m["y"] == "delta" and m["failed"] == 0
    # gain over uniform at gamma = 0.01: between 0 and the limit's 4/pi - 1 (27.3 %) + damping
    assert 0 < m["min"] < m["max"] < 100
    gain = 100 * (ds["power"].values / ds["uniform_power"].values - 1)
    assert m["max"] == pytest.approx(gain.max(), rel=1e-14)
    assert m["min"] == pytest.approx(gain.min(), rel=1e-14)
    i, j = np.unravel_index(np.argmax(gain), gain.shape)
    assert m["max_at"] == {"omega": float(ds["omega"][i]), "delta": float(ds["delta"][j])}
    assert Path("gain.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the same command again resumes: nothing computed
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["computed_points"] == 0


@pytest.mark.parametrize("argv,match", [
    (["sweep", "--omega", "1:2"], "omega: expected START:STOP:COUNT"),
    (["sweep", "--omega", "1,2", "--netcdf", "x.csv"], "--netcdf: expected a file name"),
    (["sweep", "--omega", "1,2", "--workers", "2", "--scheduler", "tcp://x:1"],
     "workers: the processes are the cluster's"),
    (["map", "--store", "missing.zarr"], "store: 'missing.zarr' does not exist"),
    (["map", "--at", "omega"], "at: expected AXIS=VALUE"),
])
def test_cli_bad_input_one_line(argv, match, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1 and "Traceback" not in err


def test_map_of_a_partial_store_marks_missing_points(reference, tmp_path):
    import zarr

    ref_store, _ = reference
    store = tmp_path / "p.zarr"
    sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    zarr.open_group(store, mode="r+")["done"][0, :] = False
    z, failed, xs, ys, xn, yn, label, title = sw.map_data(sw.open_sweep(store), "power")
    assert z.shape == (3, 4) and np.isnan(z[:, 0]).all() and np.isfinite(z[:, 1:]).all()
    assert not failed.any() and title == "gamma = 0.01"
    with pytest.raises(ParameterError, match="not complete"):
        sw.open_sweep(store, complete=True)


@pytest.mark.slow
def test_cli_kill_9_with_two_processes_then_resume(tmp_path):
    """The command line with its pool of two processes: kill -9 in the middle, run the same
    command again, and every file of the store equals an uninterrupted run's."""
    import zarr

    # --threshold makes each point slower (several solves), so the kill lands mid-run
    argv = [sys.executable, "-m", "parapend", "sweep", "--omega", "1.4:2.2:16", "--delta",
            "-0.4:-0.1:24", "--gamma", "0.02", "--block-points", "24", "--workers", "2",
            "--threshold"]
    env = {**os.environ, "PYTHONPATH": SRC}
    ref, cut = tmp_path / "ref", tmp_path / "cut"
    ref.mkdir()
    cut.mkdir()
    subprocess.run(argv, cwd=ref, env=env, check=True, capture_output=True)
    proc = subprocess.Popen(argv, cwd=cut, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    done = 0
    while time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
        try:
            done = int(np.asarray(zarr.open_group(cut / "map.zarr", mode="r")["done"][...]).sum())
        except Exception:  # not created yet
            continue
        if done >= 24:
            break
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    mask = np.asarray(zarr.open_group(cut / "map.zarr", mode="r")["done"][...])
    assert 0 < mask.sum() < mask.size
    subprocess.run(argv, cwd=cut, env=env, check=True, capture_output=True)
    assert _files(cut / "map.zarr") == _files(ref / "map.zarr")


@pytest.mark.parametrize("excitation", ["two-harmonic", "square"])
def test_every_point_equals_optimize_more_excitations(excitation):
    """Several extrema per period (the pattern seeds of the global search), gamma = 0 and
    gamma > 0, continuation along gamma: every point is optimize's."""
    kw = {"square_alpha": 0.05} if excitation == "square" else {}
    run = sw.sweep(None, omega="1.5,2.1", delta="-0.35,-0.2", gamma="0:0.04:5",
                   excitation=excitation, harmonics=16, workers=1, **kw)
    ds = run.dataset
    for o in ds["omega"].values:
        for d in ds["delta"].values:
            for g in ds["gamma"].values:
                r = parapend.optimize(omega=float(o), delta=float(d), gamma=float(g),
                                      excitation=excitation, harmonics=16, **kw)
                v = ds.sel(omega=o, delta=d, gamma=g)
                assert abs(float(v["power"]) - r.power) <= 1e-9
                assert sw.STATUSES[int(v["status"])] == r.status
    assert float(ds["branch_gap"].min()) >= 0.0


def test_branch_gap_records_a_better_continued_branch(monkeypatch):
    """When the global search misses the best maximum (here: crippled to one Newton step
    from the uniform rotation), the continuation from the neighbour finds it: branch_gap is
    the difference to optimize's true optimum, and power stays the search's own value."""
    import parapend.optimal.batch as batch
    import parapend.optimal.fourier as fourier

    def crippled(points, n, **kw):
        out = []
        for exc, gamma in points:
            problem = fourier.FourierProblem(exc, n, gamma)
            r = fourier.newton_maximize(problem, fourier._uniform_seed(exc, n, gamma),
                                        "uniform", maxiter=1)
            out.append((fourier.FourierSearch(r, [r], None), problem))
        return out

    true = {d: parapend.optimize(omega=1.8, delta=d, gamma=0.01, harmonics=12).power
            for d in (-0.3, -0.25, -0.2)}
    monkeypatch.setattr(batch, "search_fourier_batch", crippled)
    ds = sw.sweep(None, omega=1.8, delta="-0.3,-0.25,-0.2", gamma=0.01, harmonics=12,
                  workers=1).dataset
    gap, power = ds["branch_gap"].values, ds["power"].values
    assert gap[0] == 0.0  # the first point of a run has no neighbour to continue
    assert list(ds["status"].values) == [sw.STATUSES.index("max_iterations")] * 3
    for j, d in enumerate((-0.25, -0.2), start=1):
        assert power[j] < true[d] - 1e-6
        assert gap[j] == pytest.approx(true[d] - power[j], abs=1e-9)


def test_map_of_three_axes_selects_the_third(tmp_path):
    ds = sw.sweep(None, omega="1.8,2.0", delta="-0.3,-0.2", gamma="0,0.01", harmonics=8,
                  workers=1).dataset
    z, failed, xs, ys, xn, yn, label, title = sw.map_data(ds, "power", at={"gamma": 0.011})
    assert (xn, yn) == ("omega", "delta") and title == "gamma = 0.01"
    assert np.array_equal(z, ds["power"].sel(gamma=0.01).values.T)
    z0, *_ = sw.map_data(ds, "power", x="delta", y="gamma", at={"omega": 2.0})
    assert np.array_equal(z0, ds["power"].sel(omega=2.0).values.T)
    with pytest.raises(ParameterError, match="^at: 'delta' is not another axis"):
        sw.map_data(ds, "power", at={"delta": -0.3})
    with pytest.raises(ParameterError, match="^variable: 'damping_threshold' is not in"):
        sw.map_data(ds, "damping_threshold")
    fig = sw.plot_map(ds, "gain", at={"gamma": 0.0}, path=tmp_path / "g.svg")
    assert (tmp_path / "g.svg").read_text().startswith("<?xml")
    # the paper's case is inside the map: the star is drawn
    assert any("paper" in t.get_text() for t in fig.legends[0].get_texts())


def test_colour_scale_covers_the_data_and_compresses_a_long_tail():
    """The colours of a heat map span the whole range of the values; only a tail longer than
    half the 1st-to-99th-percentile span is compressed, into the last 15 % of the bar."""
    from parapend.maps.figures import colour_scale

    z = np.linspace(-2.0, 3.0, 400).reshape(20, 20)
    z[0, 0] = np.nan
    assert colour_scale(z) == ((z[0, 1], 3.0), (0.0, 1.0))
    rng = np.random.default_rng(7)
    z = rng.normal(10.0, 1.0, 1000)  # a normal sample: no long tail
    assert colour_scale(z) == ((z.min(), z.max()), (0.0, 1.0))
    z[:5] = [70.0, 50.0, 40.0, 30.0, np.nan]  # the gain where the uniform power tends to 0
    knots, shares = colour_scale(z)
    p1, p99 = np.nanpercentile(z, [1, 99])
    assert knots == (np.nanmin(z), p99, 70.0) and shares == (0.0, 0.85, 1.0)
    assert p1 - np.nanmin(z) < 0.5 * (p99 - p1)  # the low end is not a long tail
    knots, shares = colour_scale(-z)
    assert knots == (-70.0, -p99, -np.nanmin(z)) and shares == (0.0, 0.15, 1.0)
    assert colour_scale(np.full(4, np.nan)) == ((0.0, 1.0), (0.0, 1.0))
    assert colour_scale(np.ones(4)) == ((0.5, 1.5), (0.0, 1.0))


def _gain_store(n=12):
    """A map's Dataset, made up: the uniform rotation's power nearly vanishes at one corner
    (omega, delta) = (2.4, -0.05), so the gain has a long tail there (as on the documented
    128 x 128 map)."""
    import xarray as xr

    om = np.linspace(1.2, 2.4, n)
    de = np.linspace(-0.5, -0.05, n)
    o, d = np.meshgrid(om, de, indexing="ij")
    uniform = 0.3 * (-d) * o
    uniform[-1, -1] *= 0.2
    power = 1.15 * 0.3 * (-d) * o + 0.01 * o
    return xr.Dataset(
        {"power": (("omega", "delta"), power), "uniform_power": (("omega", "delta"), uniform),
         "status": (("omega", "delta"), np.zeros((n, n), dtype=np.int8)),
         "done": (("omega", "delta"), np.ones((n, n), dtype=bool))},
        coords={"omega": om, "delta": de, "gamma": 0.01}, attrs={"sweep": "{}"})


@pytest.mark.parametrize("quantity", ["gain", "power"])
def test_heat_map_colour_bar_covers_the_data_range(quantity, tmp_path):
    """The colour bar of ``parapend map`` reaches the smallest and the largest value, and
    says where its scale is compressed; the contour labels are inside the map; the axes
    have units; the legend is not over the map."""
    from matplotlib.collections import QuadMesh

    ds = _gain_store()
    z, *_ = sw.map_data(ds, quantity)
    fig = sw.plot_map(ds, quantity, path=tmp_path / "m.png")
    ax = fig.axes[0]
    mesh = next(c for c in ax.collections if isinstance(c, QuadMesh))
    lo, hi = float(np.nanmin(z)), float(np.nanmax(z))
    assert mesh.norm.vmin <= lo and mesh.norm.vmax >= hi
    cb = mesh.colorbar
    ticks = cb.get_ticks()
    assert ticks.min() <= lo * (1 + 1e-12) or quantity == "power"
    label = cb.ax.get_ylabel()
    if quantity == "gain":  # 12 % in the bulk, up to 437 % in the last row
        assert hi > 5 * np.nanpercentile(z, 99)
        p99 = np.nanpercentile(z, 99)
        assert f"compressed above {p99:.3g}" in label
        assert np.isclose(ticks, hi).any() and np.isclose(ticks, p99).any()
        # the bulk takes 85 % of the bar, the tail the rest
        assert mesh.norm(p99) == pytest.approx(0.85)
    else:  # no long tail: one linear scale over the data
        assert "compressed" not in label
        assert (mesh.norm.vmin, mesh.norm.vmax) == (lo, hi)
    texts = [t for t in ax.texts if t.get_text()]
    assert texts  # labelled contours
    to_axes = ax.transData + ax.transAxes.inverted()
    for t in texts:
        u, v = to_axes.transform(t.get_position())
        assert 0.05 < u < 0.95 and 0.05 < v < 0.95, t.get_text()
    assert "(sqrt(g/l))" in ax.get_xlabel() and "/ $g$)" in ax.get_ylabel()
    assert ax.get_legend() is None and "paper" in fig.legends[0].get_texts()[0].get_text()


def test_delta_through_zero_symmetric_and_constant_case():
    """q -> -q is a half-period shift: the map is even in delta; delta = 0 is a constant q,
    no_power with the uniform rotation's loss -gamma omega^2 (as optimize)."""
    ds = sw.sweep(None, omega=1.8, delta="-0.2,-0.1,0,0.1,0.2", gamma=0.01, harmonics=12,
                  workers=1).dataset
    p = ds["power"].values
    assert np.allclose(p, p[::-1], rtol=0, atol=1e-12)
    assert p[2] == pytest.approx(-0.01 * 1.8**2, abs=1e-15)
    assert sw.STATUSES[int(ds["status"][2])] == "no_power"
    assert [sw.STATUSES[int(c)] for c in ds["status"].values[[0, 1, 3, 4]]] == ["converged"] * 4


# -- foreign directories, damaged stores, interruptions --------------------------------------

def _copy(store: Path, to: Path) -> Path:
    import shutil

    shutil.copytree(store, to)
    return to


def _one_line(capsys, match):
    err = capsys.readouterr().err
    assert match in err, err
    assert err.count("\n") == 1 and "Traceback" not in err, err


def test_a_foreign_directory_is_never_deleted(reference, tmp_path, capsys, monkeypatch):
    """A directory that parapend did not create is refused with one line, --overwrite or
    not, even when its names look like a store's (the audit's case: power/measurements.csv
    and a file omega); and so is a store that also holds a file parapend did not write."""
    monkeypatch.chdir(tmp_path)
    d = tmp_path / "data"
    (d / "power").mkdir(parents=True)
    (d / "power" / "measurements.csv").write_text("t,p\n0,1\n")
    (d / "omega").write_text("mine")
    before = _files(d)
    for extra in ([], ["--overwrite"]):
        assert main(["sweep", "--store", "data", "--omega", "1:2:3", "--workers", "1",
                     *extra]) == 2
        _one_line(capsys, "store: 'data' exists and is not a parapend sweep store")
        assert _files(d) == before
    # another Zarr group (not a sweep's), and arrays without a root: refused too
    other = tmp_path / "other.zarr"
    other.mkdir()
    (other / "zarr.json").write_text('{"zarr_format": 3, "node_type": "group", '
                                     '"attributes": {"title": "mine"}}')
    with pytest.raises(ParameterError, match="not a parapend sweep store"):
        sw.sweep(other, omega="1.8,1.9", workers=1, overwrite=True)
    assert (other / "zarr.json").is_file()
    # a sweep store holding a file of the user's: resumed, but never emptied
    store = _copy(reference[0], tmp_path / "map.zarr")
    (store / "notes.txt").write_text("mine")
    assert sw.sweep(store, **GRID, workers=1, block_points=3).computed_points == 0
    with pytest.raises(ParameterError, match="also holds 'notes.txt', which parapend did not"):
        sw.sweep(store, omega="1.8,1.9", workers=1, overwrite=True)
    assert (store / "notes.txt").read_text() == "mine"
    # nor one inside an array's directory (it was deleted with the store)
    (store / "notes.txt").unlink()
    (store / "power" / "notes.txt").write_text("mine")
    with pytest.raises(ParameterError, match="also holds 'power/notes.txt'"):
        sw.sweep(store, omega="1.8,1.9", workers=1, overwrite=True)
    assert (store / "power" / "notes.txt").read_text() == "mine"
    # without them, --overwrite replaces the store (another sweep) and an empty directory is
    # used as it is
    (store / "power" / "notes.txt").unlink()
    assert sw.sweep(store, omega="1.8,1.9", workers=1, overwrite=True).computed_points == 2
    (tmp_path / "empty").mkdir()
    assert sw.sweep(tmp_path / "empty", omega="1.8,1.9", workers=1).computed_points == 2


@pytest.mark.slow  # about 2-6 s: the default set stays under 5 minutes
@pytest.mark.skipif(sys.platform == "win32", reason="kill -9")
def test_kill_9_during_creation_leaves_nothing_behind(reference, tmp_path, capsys):
    """kill -9 while the store is created (after its first two arrays are moved in): the
    store's root says "being created", so the next run recognises it as parapend's, makes it
    again and computes it; the temporary directory was inside the store and is gone, and
    nothing is left beside the store."""
    ref_store, _ = reference
    work = tmp_path / "work"
    work.mkdir()
    store = work / "map.zarr"
    code = ("import os, signal, sys\n"
            "from parapend import maps as sw\n"
            "from pathlib import Path\n"
            "real, calls = os.replace, [0]\n"
            "def replace(a, b):\n"
            "    a, b = Path(a), Path(b)\n"
            "    if a.parent.name.startswith('.tmp-parapend-') and b.parent == store:\n"
            "        calls[0] += 1  # an entry moved from the temporary into the store\n"
            "        if calls[0] == 3:  # two arrays are in: kill -9\n"
            "            os.kill(os.getpid(), signal.SIGKILL)\n"
            "    real(a, b)\n"
            "store = Path(sys.argv[1])\n"
            "os.replace = replace\n"
            f"sw.sweep(sys.argv[1], **{GRID!r}, workers=1, block_points=3, command='test')\n")
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.run([sys.executable, "-c", code, str(store)], env=env,
                          capture_output=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL
    inside = sorted(e.name for e in store.iterdir())
    assert any(n.startswith(".tmp-parapend-") for n in inside) and len(inside) == 4
    assert json.loads((store / "zarr.json").read_text())["attributes"]["parapend_store"] \
        == "creating"
    assert sorted(e.name for e in work.iterdir()) == ["map.zarr"]
    with pytest.raises(ParameterError, match="was not created completely"):
        sw.open_sweep(store)
    assert main(["map", "--store", str(store), "--plot", str(tmp_path / "m.png")]) == 2
    _one_line(capsys, "was not created completely")
    run = sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    assert run.computed_points == 12
    assert _files(store) == _files(ref_store)
    assert sorted(e.name for e in work.iterdir()) == ["map.zarr"]
    assert not any(e.name.startswith(".tmp-parapend-") for e in store.iterdir())


def test_stale_temporaries_of_an_earlier_version_are_removed(tmp_path):
    """Earlier versions created a store in a .tmp-parapend-* directory beside it, left there
    by kill -9: such a directory (holding only a store's entries) is removed once ten
    minutes old; a recent one, one with other files, and parapend's temporary files are
    kept."""
    old = time.time() - 3600

    def temp(name, entries, when):
        d = tmp_path / name
        d.mkdir()
        for e in entries:
            (d / e).mkdir()
        if "zarr.json" not in entries:
            (d / "zarr.json").write_text('{"zarr_format": 3, "node_type": "group", '
                                         '"attributes": {"title": "parapend design map"}}')
        os.utime(d, (when, when))
        return d

    stale = temp(".tmp-parapend-abc", ["power", "done"], old)
    fresh = temp(".tmp-parapend-new", ["power"], time.time())
    mixed = temp(".tmp-parapend-mix", ["power", "photos"], old)
    f = tmp_path / ".tmp-parapend-x.nc"
    f.write_text("")
    os.utime(f, (old, old))
    sw.sweep(tmp_path / "map.zarr", omega="1.8,1.9", workers=1)
    assert not stale.exists() and fresh.exists() and mixed.exists() and f.exists()


def _reference_blocks(tmp_path, **kw):
    """A store and its copy to damage."""
    store = tmp_path / "ref.zarr"
    sw.sweep(store, **kw, workers=1, command="test")
    return store


@pytest.mark.parametrize("damage", ["delete power", "garbage status", "flip limit_power",
                                    "garbage done", "delete done", "truncate branch_gap",
                                    "huge power", "link power", "link done"])
def test_damaged_chunks_are_found_and_recomputed(reference, tmp_path, capsys, damage):
    """A chunk of a finished block deleted by hand, replaced by garbage, with one bit
    flipped (zstd's checksum), or truncated: `map` says the store is damaged (one line,
    exit 2) instead of drawing NaNs, and the same sweep recomputes that block, never
    passing it off as done; the store then equals an uninterrupted one, byte for byte."""
    ref_store, _ = reference
    store = _copy(ref_store, tmp_path / "d.zarr")
    action, var = damage.split()
    chunk = store / var / "c" / "2" / "0"  # block 2 of 4 (omega = 1.867, 3 points)
    data = chunk.read_bytes()
    if action == "delete":
        chunk.unlink()
    elif action == "garbage":
        chunk.write_bytes(bytes(range(7, 47)))
    elif action == "flip":
        b = bytearray(data)
        b[len(b) // 2] ^= 1
        chunk.write_bytes(bytes(b))
    elif action == "huge":  # a sparse file far larger than any chunk: never read (1 GB of
        chunk.unlink()      # it took 2.2 GB of memory to be found undecodable)
        with open(chunk, "wb") as f:
            f.truncate(1 << 30)
    elif action == "link":  # not a regular file (a link to /dev/zero was read until memory
        chunk.unlink()      # ran out): never read, and removed, not followed, on resume
        chunk.symlink_to(os.devnull if sys.platform == "win32" else "/dev/zero")
    else:
        chunk.write_bytes(data[: len(data) // 2])
    if damage == "delete done":  # the block is not marked finished: as if never computed
        assert not sw.open_sweep(store)["done"].values[2].any()
        assert main(["map", "--store", str(store), "--plot", str(tmp_path / "m.png"),
                     "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["not_computed"] == 3
    else:
        with pytest.raises(ParameterError, match=r"is damaged: 1 of 4 blocks \(3 points\)"):
            sw.open_sweep(store)
        assert main(["map", "--store", str(store), "--plot", str(tmp_path / "m.png")]) == 2
        _one_line(capsys, "is damaged: 1 of 4 blocks (3 points) marked finished have missing")
    run = sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    assert run.computed_points == 3
    assert run.repaired_points == (0 if damage == "delete done" else 3)
    assert _files(store) == _files(ref_store)


def test_damage_in_a_partial_edge_chunk_and_all_nan_blocks(tmp_path):
    """A block whose points all failed (status error, every value NaN) is written whole, so
    it is not mistaken for damage and a missing chunk of it is found; a garbage chunk at the
    edge of the grid (a block smaller than the chunk) is recomputed without being read."""
    kw = {"omega": "1.8,2.4", "delta": "-0.3,-0.2,-0.1", "excitation": "square",
          "square_alpha": 0.4, "harmonics": 8, "block_points": 2}
    ref = _reference_blocks(tmp_path, **kw)
    ds = sw.open_sweep(ref)
    assert (ds["status"].values[1] == sw.STATUSES.index("error")).all()
    assert np.isnan(ds["power"].values[1]).all()
    run = sw.sweep(ref, **kw, workers=1, command="test")
    assert (run.computed_points, run.repaired_points) == (0, 0)
    store = _copy(ref, tmp_path / "d.zarr")
    (store / "power" / "c" / "1" / "1").unlink()  # all NaN, but written: its loss is seen
    (store / "uniform_power" / "c" / "0" / "1").write_bytes(b"garbage")  # edge: 1 of 2
    with pytest.raises(ParameterError, match=r"is damaged: 2 of 4 blocks \(2 points\)"):
        sw.open_sweep(store)
    run = sw.sweep(store, **kw, workers=1, command="test")
    assert (run.computed_points, run.repaired_points) == (2, 2)
    assert _files(store) == _files(ref)


def test_damaged_structure_is_one_line_then_overwrite(reference, tmp_path, capsys):
    """An array deleted (KeyError before), `done` of another dtype (ValueError before),
    garbage array metadata, a coordinate changed: `sweep` and `map` stop with one line
    (exit 2) naming what is damaged; --overwrite computes the store again."""
    import zarr

    ref_store, _ = reference
    argv = ["sweep", "--omega", "1.6:2.0:4", "--delta", "-0.3,-0.2,-0.1", "--gamma", "0.01",
            "--block-points", "3", "--workers", "1", "--store"]

    def power_deleted(s):
        import shutil

        shutil.rmtree(s / "power")

    def done_int64(s):
        g = zarr.open_group(s, mode="r+")
        d = np.asarray(g["done"][...])
        del g["done"]
        g.create_array("done", shape=d.shape, dtype="int64", chunks=(1, 3), fill_value=0,
                       dimension_names=("omega", "delta"))[...] = d

    def garbage_meta(s):
        (s / "status" / "zarr.json").write_text("{not json")

    def coordinate(s):
        zarr.open_group(s, mode="r+")["omega"][0] = 1.5

    for damage, match in ((power_deleted, "array 'power' is missing"),
                          (done_int64, "array 'done' is int64"),
                          (garbage_meta, "array 'status' is unreadable"),
                          (coordinate, "coordinate 'omega' differs")):
        store = _copy(ref_store, tmp_path / damage.__name__)
        damage(store)
        for cmd in (argv + [str(store)], ["map", "--store", str(store), "--plot",
                                          str(tmp_path / "m.png")]):
            assert main(cmd) == 2
            _one_line(capsys, f"store: {str(store)!r} is damaged ({match}")
        assert main(argv + [str(store), "--overwrite", "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["computed_points"] == 12
        a, b = sw.open_sweep(store), sw.open_sweep(ref_store)
        for v in b.data_vars:
            assert np.array_equal(a[v].values, b[v].values, equal_nan=v != "done")


def test_full_disk_while_writing_the_store_then_resume(reference, tmp_path, monkeypatch):
    """No space left after two blocks: one line naming the store and the reason, the
    finished blocks kept; the same sweep then resumes to the uninterrupted store."""
    import errno

    import zarr

    ref_store, _ = reference
    store = tmp_path / "full.zarr"
    real, masks = zarr.Array.__setitem__, [0]

    def setitem(self, key, value):  # the disk is full once two blocks are written
        if masks[0] == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(self, key, value)
        masks[0] += self.path.endswith("done")

    monkeypatch.setattr(zarr.Array, "__setitem__", setitem)
    with pytest.raises(parapend.errors.OutputError,
                       match=r"^cannot write .*full.zarr': No space left on device; the "
                             "finished blocks are in the store"):
        sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    monkeypatch.setattr(zarr.Array, "__setitem__", real)
    run = sw.sweep(store, **GRID, workers=1, block_points=3, command="test")
    assert run.resumed_points == 6 and run.computed_points == 6
    assert _files(store) == _files(ref_store)


def test_netcdf_on_a_full_disk_says_so(reference, tmp_path, monkeypatch, capsys):
    """HDF5 reports a full disk as "Permission denied" (on creating the file) or "NetCDF:
    HDF error" (RuntimeError, a traceback before): with (almost) no space left the message
    says "No space left on device"; with space left the writer's own reason stays."""
    import errno

    import xarray as xr

    from parapend import fileio
    from parapend.errors import OutputError

    ds = sw.open_sweep(reference[0])
    free = [0]

    class Stat:
        f_frsize = 4096

        @property
        def f_bavail(self):
            return free[0] // 4096

        f_bfree = f_bavail

    monkeypatch.setattr(fileio.os, "statvfs", lambda d: Stat())
    for exc in (PermissionError(errno.EACCES, "Permission denied"),
                RuntimeError("NetCDF: HDF error"),
                OSError(errno.ENOSPC, "No space left on device")):
        def fail(self, name, exc=exc):
            Path(name).write_bytes(b"CDF")
            raise exc

        monkeypatch.setattr(xr.Dataset, "to_netcdf", fail)
        free[0] = 0
        with pytest.raises(OutputError, match=r"^cannot write '.*m.nc': No space left on "
                                              "device"):
            fileio.write_dataset(ds, tmp_path / "m.nc")
        free[0] = 1 << 30
        reason = {PermissionError: "Permission denied", RuntimeError: "NetCDF: HDF error",
                  OSError: "No space left on device"}[type(exc)]
        with pytest.raises(OutputError, match=f"^cannot write '.*m.nc': .*{reason}"):
            fileio.write_dataset(ds, tmp_path / "m.nc")
        assert sorted(p.name for p in tmp_path.iterdir()) == []
    free[0] = 0
    monkeypatch.setattr(xr.Dataset, "to_netcdf", lambda self, name: (_ for _ in ()).throw(
        PermissionError(errno.EACCES, "Permission denied")))
    monkeypatch.chdir(tmp_path)
    _copy(reference[0], tmp_path / "map.zarr")
    assert main(["sweep", "--omega", "1.6:2.0:4", "--delta", "-0.3,-0.2,-0.1", "--gamma",
                 "0.01", "--block-points", "3", "--workers", "1", "--netcdf", "m.nc"]) == 1
    _one_line(capsys, "cannot write 'm.nc': No space left on device")


def _interrupt(proc, ready, timeout=120):
    """Wait until ``ready()`` (the sweep is under way), send SIGINT, return (rc, stderr);
    stderr without the first-use compile notice, which a clean install's first power
    take-off sweep prints before its workers start, and the estimate of long work, printed
    before the run starts."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None and not ready():
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=timeout)
    err = "".join(line for line in err.splitlines(keepends=True)
                  if not line.startswith(("parapend: compiling ", "parapend: sweep: ")))
    return proc.returncode, err


def _blocks_done(store):
    import zarr

    try:
        return int(np.asarray(zarr.open_group(store, mode="r")["done"][...]).sum())
    except Exception:  # noqa: BLE001 - not created yet
        return 0


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
@pytest.mark.slow
def test_ctrl_c_with_local_processes_is_one_line(tmp_path):
    """Ctrl-C while two local processes compute blocks with a power take-off (up to half a
    minute each): one line and exit code 130 at once, the running blocks are not waited
    for; the blocks written are sound."""
    argv = [sys.executable, "-m", "parapend", "sweep", "--omega", "1.6:2.0:8", "--gamma",
            "0.01,0.05", "--torque-limit", "0.3,1,2", "--workers", "2", "--store", "m.zarr"]
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.Popen(argv, cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    rc, err = _interrupt(proc,
                         lambda: "sweep" in (sw_store._root_attrs(tmp_path / "m.zarr") or {}))
    assert rc == 130 and err == "parapend sweep: interrupted\n"
    sw.open_sweep(tmp_path / "m.zarr")  # verified: no damage


@pytest.mark.slow  # about 2-6 s: the default set stays under 5 minutes
def test_bad_scheduler_address_is_one_line(tmp_path):
    """`--scheduler garbage` printed its line, then a TimeoutError traceback 20 s later
    (the half-made Client's destructor): now one line, exit 2, nothing created."""
    pytest.importorskip("distributed")
    env = {**os.environ, "PYTHONPATH": SRC}
    for address, match in (("garbage", "scheduler: expected an address such as "
                                        "tcp://host:8786, got 'garbage'"),
                           ("tcp://host-without-port", "scheduler: expected an address")):
        p = subprocess.run([sys.executable, "-m", "parapend", "sweep", "--omega", "1,2",
                            "--scheduler", address], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=120)
        assert p.returncode == 2 and p.stderr.count("\n") == 1 and match in p.stderr, p.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
def test_silent_scheduler_is_one_line_and_ctrl_c_during_connect(tmp_path):
    """A server that accepts the connection but never answers (distributed would wait for
    ever): one line after the deadline (here lowered to 1 s), exit 2; Ctrl-C while
    connecting: one line, exit 130."""
    import socket

    pytest.importorskip("distributed")
    env = {**os.environ, "PYTHONPATH": SRC}
    def listener():
        srv = socket.socket()
        srv.bind(("127.0.0.1", 0))
        srv.listen(8)
        srv.settimeout(60)
        return srv, f"tcp://127.0.0.1:{srv.getsockname()[1]}"

    srv, address = listener()
    with srv:
        code = ("import sys; from parapend.maps import run; run._CONNECT_SECONDS = 1\n"
                "from parapend.cli import main\n"
                f"sys.exit(main(['sweep', '--omega', '1,2', '--scheduler', {address!r}]))\n")
        p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1, p.stderr
    assert f"cannot connect to {address!r}: no answer within 2 s" in p.stderr
    srv, address = listener()
    with srv:
        proc = subprocess.Popen([sys.executable, "-m", "parapend", "sweep", "--omega", "1,2",
                                 "--scheduler", address], cwd=tmp_path, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        conn, _ = srv.accept()  # connected: it waits for the handshake
        with conn:
            rc, err = _interrupt(proc, lambda: True)
    assert rc == 130 and err == "parapend sweep: interrupted\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
@pytest.mark.slow
def test_ctrl_c_during_a_scheduler_sweep_is_one_line(cluster, tmp_path):
    """Ctrl-C while the blocks run on a Dask cluster: one line, exit 130, no traceback; the
    blocks written are sound."""
    argv = [sys.executable, "-m", "parapend", "sweep", "--omega", "1.4:2.2:32", "--delta",
            "-0.4:-0.1:24", "--gamma", "0.02", "--threshold", "--block-points", "24",
            "--store", "m.zarr", "--scheduler", cluster.scheduler_address]
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.Popen(argv, cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    rc, err = _interrupt(proc, lambda: _blocks_done(tmp_path / "m.zarr") >= 24)
    assert rc == 130 and err == "parapend sweep: interrupted\n"
    sw.open_sweep(tmp_path / "m.zarr")


def test_a_success_without_a_finite_power_is_recorded_as_nonfinite(tmp_path, monkeypatch):
    """What a store's check relies on holds by construction: a point whose solver says
    converged but whose power is NaN is stored as "nonfinite" (and is then a legitimate NaN,
    not damage)."""
    real = sw_compute._continue

    def nan_power(*a, **k):
        power, status, gap, x = real(*a, **k)
        return math.nan, status, gap, x

    monkeypatch.setattr(sw_compute, "_continue", nan_power)
    store = tmp_path / "m.zarr"
    run = sw.sweep(store, omega="1.8,1.9", workers=1)
    assert (run.dataset["status"].values == sw.STATUSES.index("nonfinite")).all()
    again = sw.sweep(store, omega="1.8,1.9", workers=1)
    assert (again.computed_points, again.repaired_points) == (0, 0)


def test_map_and_sweep_in_si_for_a_stated_pendulum(reference, tmp_path, capsys):
    """The store is non-dimensional; with --length and --mass, `sweep` reports its largest
    power in W and `map` draws the quantity in W (or gamma* in N m s/rad) with omega as the
    base frequency in Hz: the scales of a 1 m, 10 kg pendulum, m g^1.5 l^0.5 = 307.26 W and
    f = omega / (2 pi sqrt(l/g)), written out here."""
    import math

    import matplotlib.pyplot as plt

    from parapend import fileio

    ref_store = _copy(reference[0], tmp_path / "c.zarr")
    watt = 10.0 * 9.81 ** 1.5 * 1.0 ** 0.5
    axes = [a for k, v in GRID.items() for a in (f"--{k}", str(v))]
    assert main(["sweep", "--store", str(ref_store), *axes, "--block-points", "3",
                 "--length", "1", "--mass", "10", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["computed_points"] == 0  # the store is the same sweep: units change nothing
    assert out["largest_power_w"] == pytest.approx(out["largest_power"]["power"] * watt,
                                                   rel=1e-12)
    seen = []
    save = fileio.save_figure

    def keep(fig, path, *a, **k):
        seen.append(fig)
        return save(fig, path, *a, close=False, **k)

    fileio.save_figure = keep
    try:
        assert main(["map", "--store", str(ref_store), "--plot", str(tmp_path / "m.png"),
                     "--length", "1", "--mass", "10", "--json"]) == 0
    finally:
        fileio.save_figure = save
    m = json.loads(capsys.readouterr().out)
    assert m["unit_si"] == "W"
    assert m["min_si"] == pytest.approx(m["min"] * watt, rel=1e-12)
    assert m["max_si"] == pytest.approx(m["max"] * watt, rel=1e-12)
    fig = seen[0]
    bar = [a for a in fig.axes if getattr(a, "_colorbar", None) is not None][0]
    assert bar.get_ylabel().endswith("(W)")
    lo, hi = bar.get_ylim()
    assert lo <= m["min_si"] * (1 + 1e-9) and hi >= m["max_si"] * (1 - 1e-9)
    ax = [a for a in fig.axes if a is not bar][0]
    top = [c for c in ax.child_axes if c.get_xlabel() == "frequency (Hz)"][0]
    t0 = math.sqrt(1.0 / 9.81)
    assert top._functions[0](1.8) == pytest.approx(1.8 / (2 * math.pi * t0), rel=1e-12)
    plt.close(fig)
    # a ratio has no SI unit; frequency and amplitude belong to the axes, not to the map
    assert main(["map", "--store", str(ref_store), "--variable", "gain", "--plot",
                 str(tmp_path / "g.png"), "--length", "1", "--mass", "10", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["unit_si"] is None
    assert main(["map", "--store", str(ref_store), "--frequency", "1", "--plot",
                 str(tmp_path / "g.png")]) == 2
    capsys.readouterr()


def test_a_pool_worker_beside_others_runs_numba_on_one_thread(monkeypatch):
    """A worker process of a pool of several sets ``NUMBA_NUM_THREADS=1`` before numba is
    loaded (unless the user set it); the only worker of a pool keeps numba's default."""
    import os
    import signal
    import threading

    from parapend.maps import run

    monkeypatch.setattr(signal, "signal", lambda *a: None)
    monkeypatch.setattr(threading.Thread, "start", lambda self: None)
    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)
    run._worker_init(os.getpid(), 1)
    assert "NUMBA_NUM_THREADS" not in os.environ
    run._worker_init(os.getpid(), 2)
    assert os.environ["NUMBA_NUM_THREADS"] == "1"
    monkeypatch.setenv("NUMBA_NUM_THREADS", "2")
    run._worker_init(os.getpid(), 2)
    assert os.environ["NUMBA_NUM_THREADS"] == "2"
