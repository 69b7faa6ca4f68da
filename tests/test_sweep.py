"""Design maps (issue 13): sweep engine, resumable Zarr store, Dask execution, heat maps."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import parapend
from parapend import sweep as sw
from parapend.cli import main
from parapend.errors import ParameterError

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


@pytest.mark.skipif(sys.platform == "win32", reason="kill -9")
def test_kill_9_then_resume_equals_uninterrupted(reference, tmp_path):
    ref_store, _ = reference
    store = tmp_path / "killed.zarr"
    code = ("import sys, time; from parapend import sweep as sw\n"
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
    with sw._locked(store), pytest.raises(ParameterError,
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
    # a creation cut short (arrays, no root zarr.json) is ours: made again, then computed
    cut = tmp_path / "cut.zarr"
    (cut / "power").mkdir(parents=True)
    (cut / "power" / "zarr.json").write_text("{")
    assert sw.sweep(cut, omega="1.8,1.9", workers=1).computed_points == 2
    assert bool(sw.open_sweep(cut, complete=True)["done"].all())


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
    assert any("paper" in t.get_text() for t in fig.axes[0].get_legend().get_texts())


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
