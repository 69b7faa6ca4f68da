"""The parallel functions from a plain script: no ``if __name__ == "__main__":`` guard.

multiprocessing starts a ``forkserver`` or ``spawn`` worker by running the parent's main
script again, so an unguarded call of :func:`parapend.sweep` used to be made again in every
worker, which stopped with the "bootstrapping phase" error, reported as a worker "killed,
or out of memory". The engine's workers skip the main script (parapend.maps._forkserver);
these tests run such scripts in a subprocess, in an empty working directory that must stay
empty (the Python functions write no store unless given one).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

SRC = str(Path(__file__).resolve().parents[1] / "src")

#: the tiny sweep of the scripts: 4 points in 2 blocks, run on 2 worker processes
SWEEP = {"omega": "1.6:2.0:4", "delta": "-0.3", "harmonics": 4, "block_points": 2}

SWEEP_SCRIPT = f"""\
import json
import parapend

# at the top level, as in a notebook cell or a first script
a = parapend.sweep(**{SWEEP!r}, workers=2)
c = parapend.sweep(omega="1.7,1.9", delta="-0.3,-0.2", harmonics=4, block_points=2, workers=2)
print(json.dumps({{
    "executors": [a.executor, c.executor], "stores": [a.store, c.store],
    "dims": [dict(a._dataset.sizes), dict(c._dataset.sizes)],
    "power": a._dataset["power"].values.tolist(),
    "status": a._dataset["status"].values.tolist(),
    "done": bool(a._dataset["done"].values.all() and c._dataset["done"].values.all()),
}}))
"""


def _run_script(tmp_path, text, timeout=300):
    work = tmp_path / "work"
    work.mkdir()
    script = tmp_path / "plain.py"  # outside the working directory, which must stay empty
    script.write_text(text)
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.run([sys.executable, str(script)], cwd=work, env=env, text=True,
                          capture_output=True, timeout=timeout)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert sorted(os.listdir(work)) == [], "the script wrote into the working directory"
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc.stderr


def test_an_unguarded_script_sweeps_on_two_processes_and_writes_nothing(tmp_path):
    """Two workers from an unguarded script: the same map as one process here, bit for bit
    (the same computation); a second call with other axes works too (no default store in
    the working directory that holds the first sweep); nothing is written."""
    import numpy as np

    from parapend import maps as sw

    out, err = _run_script(tmp_path, SWEEP_SCRIPT)
    assert out["executors"] == ["2 local processes", "2 local processes"]
    assert out["stores"] == [None, None]
    assert out["dims"][0]["omega"] == 4 and out["dims"][1] == {"omega": 2, "delta": 2}
    assert out["done"]
    here = sw.sweep(**SWEEP, workers=1)
    assert here.executor == "serial"
    assert np.array_equal(np.array(out["power"]), here.dataset["power"].values)
    assert np.array_equal(np.array(out["status"]), here.dataset["status"].values)
    assert "bootstrapping" not in err and "Traceback" not in err


@pytest.mark.slow
def test_an_unguarded_script_runs_a_power_matrix_on_two_processes(tmp_path):
    """``power_matrix`` (the same engine, a MatrixSpec) from an unguarded script, two
    workers against one: equal matrices (one computation), nothing written."""
    text = """\
import json
import numpy as np
import parapend

kw = dict(hs="1:2:2", te="7:8:2", realizations=1, waves=8, harmonics=4)
a = parapend.power_matrix(**kw, workers=2)
b = parapend.power_matrix(**kw, workers=1)
pa, pb = np.asarray(a.power_matrix, float), np.asarray(b.power_matrix, float)
print(json.dumps({"executors": [a.executor, b.executor], "stores": [a.store, b.store],
                  "same": bool(np.array_equal(pa, pb, equal_nan=True)),
                  "finite": bool(np.isfinite(pa).all())}))
"""
    out, _ = _run_script(tmp_path, text)
    assert out["executors"] == ["2 local processes", "serial"]
    assert out["stores"] == [None, None]
    assert out["same"] and out["finite"]


@pytest.mark.slow
def test_workers_that_could_not_start_are_reported_so(tmp_path):
    """Where the caller's own forkserver pool started the server first (without parapend's
    preload), the workers run the unguarded script again and fail to start: the error says
    that, names the script and the guard, and does not call it a kill."""
    text = f"""\
import multiprocessing as mp
import os
if __name__ == "__main__":
    p = mp.get_context("forkserver").Process(target=os.getpid)
    p.start()
    p.join()
import parapend
try:
    parapend.sweep(**{SWEEP!r}, workers=2)
except parapend.SolverError as err:
    print(err)
"""
    work = tmp_path / "work"
    work.mkdir()
    script = tmp_path / "first.py"
    script.write_text(text)
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.run([sys.executable, str(script)], cwd=work, env=env, text=True,
                          capture_output=True, timeout=300)
    msg = proc.stdout.strip().splitlines()[-1]
    assert msg.startswith("the worker processes could not start (exit status 1"), msg
    assert "'first.py'" in msg and 'if __name__ == "__main__":' in msg
    assert "killed" not in msg and "memory" not in msg and "resume" not in msg
    assert "bootstrapping phase" in proc.stderr  # the workers' own error, on stderr


def _pool(codes, started):
    procs = [SimpleNamespace(exitcode=c) for c in codes]
    return SimpleNamespace(context=SimpleNamespace(started=procs), started=lambda: started)


def test_a_dead_worker_is_reported_by_its_real_cause():
    """A worker's exit status (a Python error, e.g. multiprocessing's bootstrapping error)
    is not reported as a kill, and only a signal suggests that a rerun resumes; the pool's
    own SIGTERM of the other workers does not hide the cause."""
    from parapend.maps.run import worker_death

    term, kill = -int(signal.SIGTERM), -int(signal.SIGKILL)
    msg = worker_death(_pool([1, term], started=False), store=True)
    assert msg.startswith("the worker processes could not start (exit status 1")
    assert "killed" not in msg and "memory" not in msg and "resume" not in msg
    msg = worker_death(_pool([0, 1], started=True), store=True)
    assert msg.startswith("a worker process failed (exit status 1")
    assert "resume" not in msg
    msg = worker_death(_pool([kill, term], started=True), store=True)
    assert msg.startswith("a worker process was killed by SIGKILL (the system's out-of-memory")
    assert msg.endswith("run the same command again to resume")
    msg = worker_death(_pool([kill], started=True), store=False)
    assert "killed by SIGKILL" in msg and "resume" not in msg  # no store: nothing kept
    assert worker_death(_pool([term], started=True), store=False) == \
        "a worker process was killed by SIGTERM"


def test_the_forkserver_preload_changes_nothing_outside_a_forkserver():
    """Imported anywhere but as the forkserver's preload, the module leaves
    ``multiprocessing.spawn.prepare`` alone; the wrapper drops the main module only for the
    engine's workers."""
    from multiprocessing import spawn

    from parapend.maps import _forkserver

    before = spawn.prepare
    assert _forkserver._install() is False and spawn.prepare is before
    seen = []
    wrapped = _forkserver._prepare_without_main(seen.append)
    data = {"name": "ParapendWorker-3", "init_main_from_path": "/x/plain.py", "dir": "/x"}
    wrapped(data)
    wrapped({**data, "name": "ForkServerProcess-1"})
    assert seen == [{"name": "ParapendWorker-3", "dir": "/x"},
                    {**data, "name": "ForkServerProcess-1"}]
    ctx = _forkserver.WorkerContext()
    proc = ctx.Process(target=print)
    assert proc.name.startswith(_forkserver.WORKER_NAME) and ctx.started == [proc]
    assert ctx.get_start_method() == "forkserver"
