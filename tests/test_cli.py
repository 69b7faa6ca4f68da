"""The command line: output, JSON keys, files, one-line errors with exit code 2."""

import csv
import json
import subprocess
import sys

import numpy as np
import pytest

from parapend.cli import main

KEYS = {"power", "uniform_power", "limit_power", "gain_over_uniform", "harmonics", "gamma",
        "omega", "success", "status", "message", "iterations", "coefficients", "peak_torque"}


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_optimize_text_defaults_paper_case(capsys):
    code, out, _ = run(capsys, "optimize")
    assert code == 0
    assert "0.270000" in out and "0.343468" in out and "0.343775" in out


def test_optimize_json_keys(capsys):
    code, out, _ = run(capsys, "optimize", "--json", "--harmonics", "8")
    d = json.loads(out)
    assert code == 0 and KEYS <= set(d)
    assert set(d["coefficients"]) == {"a0", "a", "b"} and len(d["coefficients"]["a"]) == 8
    assert d["success"] is True and d["harmonics"] == 8


def test_save_and_plot(tmp_path, capsys):
    csvp, png = tmp_path / "m.csv", tmp_path / "m.png"
    code, _, _ = run(capsys, "optimize", "--harmonics", "12", "--gamma", "0.01",
                     "--save", str(csvp), "--plot", str(png))
    assert code == 0
    rows = list(csv.reader(csvp.read_text().splitlines()))
    assert rows[0] == ["time", "phase", "theta", "theta_dot", "torque",
                       "instantaneous_power"]
    assert rows[1] == ["sqrt(l/g)", "1", "rad", "rad sqrt(g/l)", "m g l",
                       "m g l sqrt(g/l)"]  # non-dimensional: the units row
    data = np.array(rows[2:], dtype=float)
    assert data.shape[1] == 6 and data[-1, 1] < 1.0
    # theta advances by one turn per period (Eq. 3) on the saved samples
    assert data[-1, 2] - data[0, 2] == pytest.approx(2 * np.pi, abs=0.1)
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_threshold_and_sweep_json(tmp_path, capsys):
    code, out, _ = run(capsys, "threshold", "--json")
    assert code == 0 and round(json.loads(out)["damping_threshold"], 4) == 0.0856
    code, out, _ = run(capsys, "damping-sweep", "--json", "--points", "5", "--harmonics", "8",
                       "--plot", str(tmp_path / "s.svg"))
    d = json.loads(out)
    assert code == 0 and len(d["power"]) == 5 and "damping_threshold" in d
    assert (tmp_path / "s.svg").read_text().lstrip().startswith("<?xml")


def test_harmonics_command(capsys):
    code, out, _ = run(capsys, "harmonics", "--from", "2", "--to", "6", "--json")
    d = json.loads(out)
    assert code == 0 and d["harmonics"] == [2, 3, 4, 5, 6]
    assert all(b >= a for a, b in zip(d["power"], d["power"][1:]))


@pytest.mark.parametrize("args, word", [
    (["optimize", "--omega", "nan"], "omega"),
    (["optimize", "--omega", "0"], "omega"),
    (["optimize", "--omega", "-1"], "omega"),
    (["optimize", "--harmonics", "0"], "harmonics"),
    (["optimize", "--harmonics", "2.5"], "harmonics"),
    (["optimize", "--gamma", "-0.1"], "gamma"),
    (["optimize", "--excitation", "sawtooth"], "excitation"),
    (["optimize", "--excitation", "file", "--file", "/nonexistent.csv"], "cannot read"),
    (["optimize", "--excitation", "fourier"], "fourier"),
    (["optimize", "--excitation", "fourier", "--fourier", "x:1"], "fourier"),
    (["optimize", "--excitation", "square", "--square-alpha", "0"], "square-alpha"),
    (["optimize", "--save", "/nonexistent-dir/m.csv"], "save"),
    (["threshold", "--delta", "inf"], "delta"),
    (["bogus"], "invalid choice"),
])
def test_bad_input_one_line_exit_2(capsys, args, word):
    with pytest.raises(SystemExit) as e:
        code = main(args)
        raise SystemExit(code)
    assert e.value.code == 2
    _, err = capsys.readouterr()
    assert err.count("\n") == 1 and word in err and "Traceback" not in err


def test_non_periodic_file(tmp_path, capsys):
    p = tmp_path / "q.csv"
    p.write_text("tau,q\n" + "\n".join(f"{i / 16},{np.sin(i / 16)}" for i in range(17)))
    code, _, err = run(capsys, "optimize", "--excitation", "file", "--file", str(p))
    assert code == 2 and "[0, 1)" in err


def test_failed_run_keeps_existing_output(tmp_path, capsys):
    out = tmp_path / "m.csv"
    out.write_text("precious\n")
    code, _, _ = run(capsys, "optimize", "--omega", "-1", "--save", str(out))
    assert code == 2 and out.read_text() == "precious\n"


def test_entry_point_runs_as_module():
    r = subprocess.run([sys.executable, "-m", "parapend.cli", "threshold", "--json"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "damping_threshold" in r.stdout


def test_method_bvp_json_and_all(capsys):
    code, out, _ = run(capsys, "optimize", "--method", "bvp", "--gamma", "5e-4", "--json")
    d = json.loads(out)
    assert code == 0 and KEYS | {"mesh_nodes", "max_residual"} <= set(d)
    assert d["method"] == "bvp" and d["success"] is True and d["max_residual"] <= 1e-8
    code, out, _ = run(capsys, "optimize", "--method", "all", "--gamma", "5e-4",
                       "--harmonics", "64", "--json")
    d = json.loads(out)
    assert code == 0 and abs(d["fourier"]["power"] - d["bvp"]["power"]) < 1e-9
    code, out, _ = run(capsys, "optimize", "--method", "all")
    assert code == 0 and "needs gamma >= 1e-18" in out


def test_method_bvp_needs_damping(capsys):
    code, _, err = run(capsys, "optimize", "--method", "bvp")
    assert code == 2 and "gamma" in err and err.count("\n") == 1


def test_figure_command(tmp_path, capsys):
    png = tmp_path / "f8.png"
    code, out, _ = run(capsys, "figure", "8", "--plot", str(png))
    assert code == 0 and png.read_bytes()[:4] == b"\x89PNG"


def test_sweeps_save_netcdf(tmp_path, capsys):
    import xarray as xr

    nc = tmp_path / "h.nc"
    code, out, _ = run(capsys, "harmonics", "--to", "5", "--save", str(nc), "--json")
    with xr.open_dataset(nc) as ds:
        np.testing.assert_array_equal(ds["power"].values, json.loads(out)["power"])
        assert ds.attrs["omega"] == 1.8
    nc2 = tmp_path / "s.nc"
    code, _, _ = run(capsys, "damping-sweep", "--points", "4", "--harmonics", "8",
                     "--save", str(nc2))
    with xr.open_dataset(nc2) as ds:
        assert code == 0 and ds.sizes["gamma"] == 4 and "damping_threshold" in ds.attrs


@pytest.mark.parametrize("delay", [0.15, 0.3, 0.5])
def test_ctrl_c_while_loading_is_one_line(delay):
    """Ctrl-C at any moment, loading NumPy and SciPy included, ends in one line and the
    interrupted exit status: 130, or death by SIGINT (-2 to subprocess, 130 to a shell),
    which CPython chooses after an interrupt inside some extension modules' import. Where
    the run printed its result first (the signal came during the interpreter's shutdown),
    nothing more is said. The first delay lands after the interpreter's own start-up
    (about 30 ms), which is not parapend's."""
    import signal
    import time

    p = subprocess.Popen([sys.executable, "-m", "parapend", "optimize", "--gamma", "0.01",
                          "--harmonics", "96"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    if "status:" in out:  # finished before the signal
        assert p.returncode in (0, 130, -signal.SIGINT) and err.count("\n") <= 1
    else:
        assert p.returncode in (130, -signal.SIGINT), (p.returncode, err)
        assert err.count("\n") == 1 and err.rstrip().endswith("interrupted"), err


def test_an_interrupt_a_library_turned_into_its_own_error_is_still_an_interrupt(
        monkeypatch, capsys):
    """numba, interrupted while it compiles, raises its own error: after SIGINT under the
    console script's handler any exception ends as the command's one interrupted line."""
    from parapend import _interrupt
    from parapend import cli as cli_pkg

    def compiling(a):
        raise RuntimeError("numba: lowering failed: KeyboardInterrupt")

    monkeypatch.setitem(cli_pkg.COMMANDS, "threshold", compiling)
    monkeypatch.setattr(_interrupt, "_interrupted", True)
    assert main(["threshold"]) == 130
    assert capsys.readouterr().err == "parapend threshold: interrupted\n"
    monkeypatch.setattr(_interrupt, "_interrupted", False)  # no interrupt: the error is a bug
    with pytest.raises(RuntimeError, match="lowering"):
        main(["threshold"])


def test_an_interrupt_a_callback_swallowed_is_still_an_interrupt(monkeypatch, capsys):
    """SIGINT inside a callback whose exceptions CPython ignores (a weakref callback of the
    import machinery) printed "Exception ignored in ... KeyboardInterrupt" with a traceback
    and the command ran on: the console script keeps it silent and ends in the one
    interrupted line, exit code 130, with the hook restored afterwards."""
    import weakref

    from parapend import _entry, _interrupt
    from parapend import cli as cli_pkg

    def ran_on(argv):
        _interrupt._interrupted = True  # as the SIGINT handler does before it raises

        class Held:
            pass

        def callback(_):
            raise KeyboardInterrupt

        held = Held()
        ref = weakref.ref(held, callback)
        del held  # the callback raises: CPython reports it as unraisable and goes on
        assert ref() is None
        print("status: converged")
        return 0

    monkeypatch.setattr(cli_pkg, "main", ran_on)
    monkeypatch.setattr(_interrupt, "_interrupted", False)
    monkeypatch.setattr(_interrupt, "_swallowed", False)
    hook = sys.unraisablehook
    assert _entry.main([]) == _entry.EXIT_INTERRUPTED
    captured = capsys.readouterr()
    assert captured.err == "parapend: interrupted\n"
    assert sys.unraisablehook is hook
