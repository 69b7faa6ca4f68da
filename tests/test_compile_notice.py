"""The notice of a first-use compile of the numba kernels: one line on stderr, exactly when
numba compiles (its disk cache missed), never on a cache hit; the library only logs."""

import json
import logging
import os
import subprocess
import sys

import numba
import pytest

import parapend
from parapend import _jit
from parapend.cli import _notice, main

HERMITE = "parapend.optimal._hermite_kernel"
NOTICE = ("parapend: compiling the torque-limited solver's kernels (first use only, "
          "about 10 s)")


@pytest.fixture
def fresh(monkeypatch):
    """No kernel module announced yet in this process, and no CLI handler (an earlier
    in-process ``main`` installs one); both restored afterwards."""
    monkeypatch.setattr(_jit, "_announced", set())
    logger = logging.getLogger("parapend._jit")
    monkeypatch.setattr(logger, "handlers",
                        [h for h in logger.handlers if not isinstance(h, _notice._Notice)])


def test_library_logs_once_per_module_and_never_prints(fresh, caplog, capsys):
    with caplog.at_level(logging.INFO, logger="parapend._jit"):
        _jit._on_compile(HERMITE)
        _jit._on_compile(HERMITE)                    # same module again: nothing
        _jit._on_compile("parapend.dynamics._kernel")
        _jit._on_compile("someone_else.kernels")     # not parapend's: nothing
    msgs = [r.getMessage() for r in caplog.records if r.name == "parapend._jit"]
    assert msgs == ["compiling the torque-limited solver's kernels (first use only, about 10 s)",
                    "compiling the basin-map kernel (first use only, about 15 s)"]
    assert capsys.readouterr() == ("", "")           # without the CLI's handler: silent


def test_cli_handler_prints_each_record_on_stderr_once(fresh, capsys):
    _notice.install()
    _notice.install()                                # idempotent: one handler
    handlers = [h for h in logging.getLogger("parapend._jit").handlers
                if isinstance(h, _notice._Notice)]
    assert len(handlers) == 1
    _jit._on_compile(HERMITE)
    _jit._on_compile(HERMITE)
    out, err = capsys.readouterr()
    assert out == "" and err == NOTICE + "\n"


def test_numba_compile_event_reaches_the_listener(fresh, caplog):
    """A real compile of a function that numba attributes to a parapend module fires the
    listener (numba's ``numba:compile`` event); a second call (compiled) does not."""
    _jit.announce_compiles()

    def twice(x):
        return 2.0 * x

    twice.__module__ = "parapend.test_only_module"
    f = numba.njit(twice)
    with caplog.at_level(logging.INFO, logger="parapend._jit"):
        assert f(1.5) == 3.0
        assert f(2.5) == 5.0
    msgs = [r.getMessage() for r in caplog.records if r.name == "parapend._jit"]
    if numba.config.DISABLE_JIT:
        assert msgs == []
    else:
        assert msgs == ["compiling the kernels of parapend.test_only_module (first use only, "
                        "about 10 s)"]


def _run(cache, *args):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), NUMBA_CACHE_DIR=str(cache))
    env.pop("NUMBA_DISABLE_JIT", None)
    return subprocess.run([sys.executable, "-m", "parapend", *args], capture_output=True,
                          text=True, env=env, timeout=600)


@pytest.mark.slow
def test_first_run_says_it_compiles_and_the_second_does_not(tmp_path):
    """An empty numba cache (``NUMBA_CACHE_DIR``): the first ``optimize --torque-limit 2.5``
    prints the notice once on stderr and its usual JSON on stdout; the second run loads the
    kernels from the cache and prints nothing on stderr. Both agree with the library."""
    args = ("optimize", "--torque-limit", "2.5", "--json")
    first = _run(tmp_path, *args)
    assert first.returncode == 0, first.stderr[-2000:]
    assert first.stderr.splitlines() == [NOTICE]
    second = _run(tmp_path, *args)
    assert second.returncode == 0, second.stderr[-2000:]
    assert second.stderr == ""
    a, b = json.loads(first.stdout), json.loads(second.stdout)   # stdout: one JSON object
    ref = parapend.pto.optimize_pto(torque_limit=2.5)
    assert a["success"] and b["success"] and ref.success
    assert a["power"] == pytest.approx(ref.power, rel=1e-9)
    assert b["power"] == pytest.approx(ref.power, rel=1e-9)
    assert a["peak_torque"] <= 2.5 * (1 + 1e-6)


def test_a_run_without_compiled_kernels_says_nothing(tmp_path, capsys):
    """Commands that use no numba kernel never print the notice."""
    assert main(["optimize", "--gamma", "0.01", "--harmonics", "8", "--json"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and json.loads(out)["success"]


@pytest.mark.slow
def test_sweep_compiles_once_before_its_workers(tmp_path):
    """A power take-off sweep on worker processes compiles the kernels in the main process
    first (one notice; the workers then load them from the cache) and gives the same map as
    a run on a warm cache."""
    args = ("sweep", "--torque-limit", "1,2", "--omega", "1.7,1.8", "--workers", "2",
            "--block-points", "1", "--json")
    cold = _run(tmp_path / "cache", *args, "--store", str(tmp_path / "a.zarr"))
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count("compiling") == 1 and cold.stderr.count("\n") == 1
    warm = _run(tmp_path / "cache", *args, "--store", str(tmp_path / "b.zarr"))
    assert warm.returncode == 0 and warm.stderr == ""
    a, b = json.loads(cold.stdout), json.loads(warm.stdout)
    assert a["largest_power"] == b["largest_power"] and a["status_counts"] == b["status_counts"]
