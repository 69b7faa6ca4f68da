"""Every bad input becomes one line and a non-zero exit, work is
bounded, nothing is silently ignored or misleading. Fast: no solve here takes over ~1 s."""

import json
import math
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import parapend
from parapend import limits
from parapend.cli import main
from parapend.errors import ParameterError

SRC = str(Path(__file__).resolve().parents[1] / "src")


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, args, code=2):
    c, out, err = run(capsys, *args)
    assert c == code, (args, c, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


def cli(*args, stdout=subprocess.PIPE, limit_fsize=None, timeout=60):
    """Run ``python -m parapend`` in a subprocess (for closed or failing stdout)."""
    def pre():
        if limit_fsize is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_fsize, limit_fsize))
    env = {**os.environ, "PYTHONPATH": SRC}
    return subprocess.run([sys.executable, "-m", "parapend", *args], stdout=stdout,
                          stderr=subprocess.PIPE, text=True, timeout=timeout, env=env,
                          preexec_fn=pre)


def write_csv(path, n=32, q=None, header="tau,q"):
    tau = np.arange(n) / n
    q = -0.3 * np.sin(2 * np.pi * tau) if q is None else q
    path.write_text(header + "\n" + "\n".join(f"{a!r},{b!r}" for a, b in
                                             zip(tau.tolist(), np.asarray(q).tolist())))
    return path


# -- 2. tracebacks -> one line naming the parameter ----------------------------------------
@pytest.mark.parametrize("args, word", [
    (["optimize", "--omega", "1e155"], "omega"),
    (["optimize", "--omega", "1e-308"], "omega"),
    (["optimize", "--delta=1e308"], "delta"),
    (["threshold", "--omega", "1e-320"], "omega"),
    (["optimize", "--excitation", "square", "--square-alpha", "1e-308"], "square-alpha"),
    (["optimize", "--method", "bvp", "--gamma", "1e-320"], "gamma"),
    (["optimize", "--gamma", "1e300"], "gamma"),
    (["optimize", "--fourier", "1:0.3:1e300"], "phase"),
    (["optimize", "--fourier", "1:1e300"], "amplitude"),
    (["optimize", "--omega", "1e"], "omega"),
    (["optimize", "--omega", ""], "omega"),
    (["optimize", "--harmonics", "9" * 5000], "harmonics"),
    (["optimize", "--harmonics", "-3"], "harmonics"),
    (["optimize", "--bogus"], "unrecognized"),
])
def test_extreme_values_one_line(capsys, args, word):
    assert word in one_line_error(capsys, args)


def test_api_ranges_named():
    with pytest.raises(ParameterError, match=r"omega: expected a number in \[0.001, 1000\]"):
        parapend.optimize(omega=1e155)
    with pytest.raises(ParameterError, match=r"delta: expected \|delta\| <= 1000"):
        parapend.harmonic(1e308)
    with pytest.raises(ParameterError, match="square-alpha"):
        parapend.square(alpha=1e-308)
    with pytest.raises(ParameterError, match=r"gamma: expected a number >= 1e-18"):
        parapend.optimize(method="bvp", gamma=1e-320)
    with pytest.raises(ParameterError, match=r"gamma: expected a number in \[0, 1000\]"):
        parapend.harmonic_table([2], gamma=-1.0)
    with pytest.raises(ParameterError, match=r"gamma-max"):
        parapend.damping_sweep(gamma_max=1e300, points=3, harmonics=4)


@pytest.mark.parametrize("content, word", [
    ("tau,q\n0,1\n".encode("latin-1") + "0.5,\xe9\n".encode("latin-1"), "UTF-8"),
    ("tau,q\n0,0\n".encode("utf-16"), "NUL"),
    (bytes(range(256)) * 4, "NUL"),
    (b"", "header"),
])
def test_csv_encodings_one_line(tmp_path, capsys, content, word):
    p = tmp_path / "q.csv"
    p.write_bytes(content)
    assert word in one_line_error(capsys, ["optimize", "--file", str(p)])


def test_csv_utf8_bom_accepted(tmp_path, capsys):
    p = write_csv(tmp_path / "q.csv")
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    code, out, _ = run(capsys, "optimize", "--file", str(p), "--harmonics", "4", "--json")
    assert code == 0 and json.loads(out)["excitation"]["excitation"] == "file"


def test_csv_huge_values_tiny_gaps_and_directories(tmp_path, capsys):
    p = write_csv(tmp_path / "big.csv", q=np.full(32, 1e308))
    assert "|q| <= 1000" in one_line_error(capsys, ["optimize", "--file", str(p)])
    tau = np.concatenate(([0.0, 1e-300], np.arange(2, 32) / 32)).tolist()
    p = tmp_path / "gap.csv"
    p.write_text("tau,q\n" + "\n".join(f"{t!r},{math.sin(2 * math.pi * t)!r}" for t in tau))
    assert "spacing" in one_line_error(capsys, ["optimize", "--file", str(p)])
    assert "directory" in one_line_error(capsys, ["optimize", "--file", str(tmp_path)])


def test_csv_reading_is_bounded(tmp_path, capsys):
    err = one_line_error(capsys, ["optimize", "--file", "/dev/zero"])
    assert "regular" in err and "character device" in err
    big = tmp_path / "sparse.csv"  # refused by its size before a byte is read
    with open(big, "wb") as fh:
        fh.truncate(limits.MAX_BYTES_FILE + 1)
    assert "larger than" in one_line_error(capsys, ["optimize", "--file", str(big)])
    p = write_csv(tmp_path / "long.csv", n=limits.MAX_FILE_ROWS + 1)
    assert str(limits.MAX_FILE_ROWS) in one_line_error(capsys, ["optimize", "--file", str(p)])


@pytest.mark.parametrize("args", [
    ["optimize", "--save", "/proc/x.csv"],
    ["optimize", "--plot", "/sys/x.png"],
    ["optimize", "--save", "x" * 300 + ".csv"],
    ["reproduce", "--out", "/proc/x"],
    ["reproduce", "--out", ""],
    ["optimize", "--save", ""],
])
def test_unwritable_outputs_one_line(capsys, args):
    one_line_error(capsys, args)


def test_reproduce_out_below_a_file(tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_text("x")
    err = one_line_error(capsys, ["reproduce", "--out", str(f / "sub")])
    assert "is a file" in err and "afile" in err


@pytest.mark.slow
def test_full_disk_one_line(tmp_path):
    r = cli("optimize", "--harmonics", "4", "--save", str(tmp_path / "m.csv"),
            limit_fsize=1000)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1 and "m.csv" in r.stderr
    assert [p.name for p in tmp_path.iterdir()] == []  # no temporary left behind


@pytest.mark.slow
def test_stdout_full_or_closed():
    with open("/dev/full", "w") as full:
        r = cli("optimize", "--harmonics", "4", stdout=full)
    assert r.returncode == 1 and "Traceback" not in r.stderr and r.stderr.count("\n") == 1
    r = subprocess.run(f"{sys.executable} -m parapend optimize --harmonics 4 >&-", shell=True,
                       capture_output=True, text=True, env={**os.environ, "PYTHONPATH": SRC},
                       timeout=60)
    assert r.returncode == 1 and "Traceback" not in r.stderr and "closed" in r.stderr


# -- 3. bounded time and memory ------------------------------------------------------------
@pytest.mark.parametrize("args, words", [
    (["optimize", "--harmonics", "4096"], ["harmonics", "1024"]),
    (["optimize", "--harmonics", "2048"], ["harmonics", "1024"]),
    (["optimize", "--fourier", "1000000:0.3"], ["k", "1024"]),
    (["optimize", "--fourier", "999999999999:0.3"], ["k", "1024"]),
    (["optimize", "--fourier", "-1:0.3"], ["k", "1024", "-1"]),
    (["damping-sweep", "--points", "100000"], ["points", "1001"]),
    (["damping-sweep", "--points", "1000", "--harmonics", "64"], ["points", "harmonics"]),
    (["harmonics", "--to", "4096"], ["--to", "128", "4096"]),
    (["harmonics", "--to", "512"], ["--to", "128"]),
    (["harmonics", "--to", "1000000000"], ["--to", "1000000000"]),
    (["threshold", "--harmonics", "1024"], ["harmonics", "512"]),
])
def test_caps_name_parameter_and_cap(capsys, args, words):
    err = one_line_error(capsys, args)
    assert all(w in err for w in words), err


def test_bvp_refuses_rough_excitation():
    rng = np.random.default_rng(0)
    tau = np.arange(512) / 512
    exc = parapend.excitation.SampledExcitation(
        1.8, tuple(tau), tuple(-0.3 * np.sin(2 * np.pi * tau) + 0.01 * rng.standard_normal(512)))
    with pytest.raises(ParameterError, match="extrema per period"):
        parapend.optimize(excitation=exc, method="bvp", gamma=1e-4)


def test_peak_torque_long_spectrum_bounded_memory():
    """q on the torque grid by folding: exact, and no dense (points x K) matrix."""
    from parapend.excitation import _evaluate, _evaluate_uniform

    rng = np.random.default_rng(1)
    spec = rng.standard_normal(3000) + 1j * rng.standard_normal(3000)
    s = 2 * np.pi * np.arange(512) / 512
    np.testing.assert_allclose(_evaluate_uniform(spec, 512), _evaluate(spec, s), atol=1e-9)
    n = limits.MAX_FILE_ROWS
    tau = np.arange(n) / n
    exc = parapend.excitation.SampledExcitation(1.8, tuple(tau),
                                                tuple(-0.3 * np.sin(2 * np.pi * tau)))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    q = exc.q_uniform(4096)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 200_000  # KB
    np.testing.assert_allclose(q, -0.3 * np.sin(2 * np.pi * np.arange(4096) / 4096),
                               atol=1e-12)


# -- 4. nothing silently ignored or misleading ---------------------------------------------
def test_excitation_inferred_from_file_and_fourier(tmp_path, capsys):
    p = write_csv(tmp_path / "q.csv")
    code, out, _ = run(capsys, "optimize", "--file", str(p), "--harmonics", "4", "--json")
    assert code == 0 and json.loads(out)["excitation"]["excitation"] == "file"
    code, out, _ = run(capsys, "optimize", "--fourier", "1:-0.3,2:0.1", "--harmonics", "4",
                       "--json")
    assert code == 0 and json.loads(out)["excitation"]["excitation"] == "fourier"


@pytest.mark.parametrize("args, word", [
    (["optimize", "--excitation", "harmonic", "--file", "x.csv"], "file"),
    (["optimize", "--excitation", "square", "--fourier", "1:0.3"], "fourier"),
    (["optimize", "--fourier", "1:0.3", "--delta", "0.2"], "delta"),
    (["optimize", "--fourier", "1:0.3", "--file", "x.csv"], "file"),
    (["optimize", "--square-alpha", "0.01"], "square-alpha"),
    (["threshold", "--excitation", "file", "--file", "x.csv", "--delta", "1"], "delta"),
])
def test_ignored_options_refused(capsys, args, word):
    err = one_line_error(capsys, args)
    assert word in err and ("not used" in err or "both" in err)


def test_api_refuses_bad_types_and_values():
    with pytest.raises(ParameterError, match=r"fourier k: expected an integer"):
        parapend.optimize(fourier=[(2.9, 0.3, 0)])
    with pytest.raises(ParameterError, match="points"):
        parapend.mean_power(parapend.optimize(harmonics=2).motion, parapend.harmonic(),
                            points=0)
    with pytest.raises(ParameterError, match="gamma"):
        parapend.uniform_power(parapend.harmonic(), -1)
    for kwargs, name in [({"omega": "1.8"}, "omega"), ({"harmonics": [3]}, "harmonics"),
                         ({"fourier": 5}, "fourier"), ({"fourier": [(1,)]}, "fourier"),
                         ({"file": 5}, "file"), ({"excitation": 3}, "excitation"),
                         ({"method": None}, "method"), ({"gamma": None}, "gamma"),
                         ({"warm": "x"}, "warm"), ({"delta": [1, 2]}, "delta")]:
        with pytest.raises(ParameterError, match=f"^{name}"):
            parapend.optimize(**kwargs)
    with pytest.raises(ParameterError, match="excitation: expected an Excitation"):
        parapend.uniform_power("harmonic")
    with pytest.raises(ParameterError, match="harmonics"):
        parapend.harmonic_table(5)


def test_constant_excitation_is_explicit(capsys):
    r = parapend.optimize(delta=0.0, gamma=0.01)
    assert r.status == "no_power" and r.success and r.power == -0.01 * 1.8**2
    assert r.peak_torque == pytest.approx(1 + 0.01 * 1.8, rel=1e-9)  # hold the uniform turn
    code, out, _ = run(capsys, "optimize", "--delta", "0")
    assert code == 0 and "status: no_power" in out and "constant" in out
    assert "peak torque |T|: 1 " in out
    err = one_line_error(capsys, ["damping-sweep", "--delta", "0"])
    assert "constant" in err
    ds = parapend.damping_sweep(delta=0.0, gamma_max=0.1, points=3, harmonics=4)
    assert set(ds["status"].values) == {"no_power"}
    np.testing.assert_allclose(ds["power"].values, -np.array([0, 0.05, 0.1]) * 1.8**2)
    with pytest.raises(ParameterError, match="excitation: expected an Excitation"):
        parapend.limit("harmonic")


def test_above_threshold_says_no_power(capsys):
    r = parapend.optimize(gamma=0.09, harmonics=16)
    assert r.success and r.status == "no_power" and r.power < 0
    assert "gamma*" in r.message
    code, out, _ = run(capsys, "optimize", "--gamma", "0.09", "--harmonics", "16")
    assert code == 0 and "status: no_power" in out and "gamma*" in out


def test_negative_scientific_numbers_parse(capsys):
    code, out, _ = run(capsys, "optimize", "--delta", "-1e-3", "--harmonics", "4", "--json")
    assert code == 0 and json.loads(out)["excitation"]["delta"] == -1e-3
    code, out, _ = run(capsys, "optimize", "--delta", "-1E+0", "--harmonics", "4", "--json")
    assert code == 0 and json.loads(out)["excitation"]["delta"] == -1.0


def test_method_all_labels_undamped_limit(capsys):
    code, out, _ = run(capsys, "optimize", "--method", "all", "--gamma", "0.01",
                       "--harmonics", "8")
    assert code == 0 and "undamped" in out and "gamma = 0.01" in out


def test_number_format():
    from parapend.cli._common import _fmt

    assert _fmt(0.0) == "0" and _fmt(-0.0) == "0"
    assert _fmt(-5.551115123125783e-17) == "-5.55112e-17"
    assert _fmt(2.9e-9, 10) != "0.0000000029" and "e-09" in _fmt(2.9e-9, 10)
    assert _fmt(0.27) == "0.270000"


# -- 5. user experience -------------------------------------------------------------------
def test_bare_parapend_lists_commands(capsys):
    code, out, err = run(capsys)
    assert code == 2 and out == ""
    assert all(c in err for c in ("optimize", "threshold", "damping-sweep", "harmonics",
                                  "figure", "reproduce"))


def test_figure_default_name_and_pdf(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, _ = run(capsys, "figure", "8")
    assert code == 0 and (tmp_path / "fig8.png").read_bytes()[:4] == b"\x89PNG"
    assert "fig8.png" in out and "default" in out
    code, _, _ = run(capsys, "optimize", "--harmonics", "4", "--plot", str(tmp_path / "o.pdf"))
    assert code == 0 and (tmp_path / "o.pdf").read_bytes()[:4] == b"%PDF"


def test_progress_bar_only_on_a_terminal(capsys, monkeypatch):
    from parapend.cli._common import _Progress

    bar = _Progress("sweep", delay=0.0)
    assert bar.on is False  # captured stderr is not a terminal
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    bar = _Progress("sweep", delay=0.0)
    bar(1, 3)
    bar(3, 3)
    err = capsys.readouterr().err
    assert "sweep [" in err and "1/3" in err and err.endswith("\r")


def test_gamma_is_the_one_name(capsys):
    r = parapend.optimize(harmonics=4, gamma=0.01)
    assert r.gamma == 0.01 and "gamma" in r.to_dict() and "damping" not in r.to_dict()
    ds = parapend.damping_sweep(harmonics=4, points=3)
    assert "gamma" in ds.coords and "damping" not in ds.coords


# -- 6. inputs checked where they are used (second audit) ----------------------------------
def _rows(path, header, a, b):
    path.write_text(header + "\n" + "\n".join(f"{float(x)!r},{float(y)!r}"
                                              for x, y in zip(a, b)))
    return str(path)


def test_file_samples_must_cover_the_period(tmp_path, capsys):
    """Samples within tau in [0.5, 0.500063]: the periodic spline across the rest of the
    period is not data (it reached |q| = 2842 and a 'converged' P = 3232 before)."""
    tau = 0.5 + np.linspace(0.0, 0.000063, 32)
    p = _rows(tmp_path / "narrow.csv", "tau,q", tau, 900 * np.sin(np.linspace(0, 6, 32)))
    err = one_line_error(capsys, ["optimize", "--file", p])
    assert "gap" in err and "0.125" in err


def test_file_interpolant_is_capped_not_only_its_samples(tmp_path, capsys):
    """Samples within |q| <= 1e3, spread over the period, whose interpolant overshoots."""
    from scipy.interpolate import CubicSpline

    tau = np.sort(np.append(np.arange(16) / 16, 0.5 + 1e-4))
    q = np.zeros(tau.size)
    q[tau == 0.5], q[tau == 0.5 + 1e-4] = 1000.0, -1000.0
    p = _rows(tmp_path / "spike.csv", "tau,q", tau, q)
    err = one_line_error(capsys, ["optimize", "--file", p])
    assert "|q(t)| <= 1000" in err and "interpolant" in err
    # independent: the periodic cubic spline through the samples itself exceeds the cap
    spline = CubicSpline(np.append(tau, 1.0), np.append(q, q[0]), bc_type="periodic")
    assert np.max(np.abs(spline(np.linspace(0, 1, 200001)))) > 1000
    # a file whose interpolant peaks exactly at the cap is accepted (exact extrema)
    tau = np.arange(32) / 32
    p = _rows(tmp_path / "cap.csv", "tau,q", tau, 1000 * np.sin(2 * np.pi * tau))
    exc = parapend.from_csv(p)
    assert parapend.excitation.max_abs_q(exc) == pytest.approx(1000, rel=1e-12)


@pytest.mark.slow
def test_max_abs_q_against_dense_evaluation():
    from parapend.excitation import max_abs_q

    rng = np.random.default_rng(7)
    for _ in range(6):
        k = int(rng.integers(1, 60))
        terms = [(j, float(rng.normal()), float(rng.uniform(0, 2 * np.pi)))
                 for j in range(1, k + 1)]
        exc = parapend.fourier(terms, omega=float(rng.uniform(0.5, 3)), mean=0.2)
        dense = np.max(np.abs(exc.q(np.linspace(0, exc.period, 400001))))
        # the dense grid is below the maximum by at most (K pi/400000)^2 / 2 relative
        assert dense <= max_abs_q(exc) <= dense * (1 + 1e-7)
    assert max_abs_q(parapend.square(-0.3)) == 0.3
    assert max_abs_q(parapend.harmonic(0.0)) == 0.0


@pytest.mark.parametrize("terms, ok", [
    ("1:1000,1:1000,1:1000", False),   # duplicate orders add up: max |q| = 3000
    ("1:1000,2:1", False),             # just above the cap (a grid point sits at 1000)
    ("1:999,2:1", True),
    ("1:600,3:600", True),             # 4 x(1 - x^2) at x = 1/sqrt 3: 923.8
])
def test_fourier_series_capped_as_summed(capsys, terms, ok):
    if ok:
        exc = parapend.build_excitation(fourier=terms)
        dense = np.max(np.abs(exc.q(np.linspace(0, exc.period, 200001))))
        assert dense <= 1000
    else:
        err = one_line_error(capsys, ["optimize", "--fourier", terms])
        assert "fourier: expected |q(t)| <= 1000" in err and "summed" in err
        # independent: the series summed on a dense grid exceeds the cap
        terms_ = parapend.excitation.parse_fourier_terms(terms)
        s = np.linspace(0, 2 * np.pi, 200001)
        assert np.max(np.abs(sum(a * np.sin(k * s + ph) for k, a, ph in terms_))) > 1000


def test_subnormal_amplitudes_one_line(tmp_path, capsys):
    tau = np.arange(32) / 32
    f = _rows(tmp_path / "sub.csv", "tau,q", tau, 1e-320 * np.sin(2 * np.pi * tau))
    t = np.arange(400) * 0.1
    rec = _rows(tmp_path / "subrec.csv", "t,z", t, 1e-320 * np.sin(t))
    for args in (["optimize", "--delta", "5e-324"], ["optimize", "--fourier", "1:1e-320"],
                 ["optimize", "--file", f], ["threshold", "--delta", "5e-324"],
                 ["track", "--delta", "5e-324", "--periods", "20"],
                 ["track", "--fourier", "1:1e-320", "--periods", "20"],
                 ["sea", "--record", rec], ["sea", "--hs", "1e-320"],
                 ["sweep", "--delta=-0.3,5e-324", "--store", str(tmp_path / "st")],
                 ["optimize", "--length", "1", "--mass", "1", "--frequency", "1",
                  "--amplitude", "1e-320"]):
        err = one_line_error(capsys, args)
        assert "1e-100" in err or "1e-06" in err, err


def test_smallest_amplitude_still_solved_exactly():
    """At gamma = 0 the optimum scales with delta (the set of motions does not depend on
    it and P = <q sin(theta) theta'>): the smallest admissible delta gives the same gain."""
    big = parapend.optimize(delta=-0.3, harmonics=8)
    small = parapend.optimize(delta=-0.3e-99, harmonics=8)
    assert small.status == "converged"
    assert small.power / 0.3e-99 == pytest.approx(big.power / 0.3, rel=1e-9)
    with pytest.raises(ParameterError, match=r"delta: expected 0 or 1e-100 <= \|delta\|"):
        parapend.optimize(delta=1e-101)
    # the rule is on the series' largest harmonic: a subnormal term beside others is harmless
    tiny = parapend.optimize(fourier=[(1, -0.3), (2, 1e-320)], harmonics=8)
    assert tiny.power == pytest.approx(big.power, rel=1e-12)


@pytest.mark.parametrize("args, word", [
    (["optimize", "--length", "1e308", "--mass", "1", "--frequency", "1"], "length"),
    (["optimize", "--length", "1e-320", "--mass", "1"], "length"),
    (["optimize", "--length", "1", "--mass", "1e308"], "mass"),
    (["optimize", "--length", "1", "--mass", "1", "--gravity", "1e-320"], "gravity"),
    (["optimize", "--length", "1", "--mass", "1", "--inertia", "0.5"], "inertia"),
    (["optimize", "--length", "1", "--mass", "1", "--frequency", "1e6"], "frequency"),
    (["optimize", "--length", "1", "--mass", "1", "--frequency", "1", "--amplitude", "1e6"],
     "amplitude"),
    (["optimize", "--length", "1", "--mass", "1", "--damping-coefficient", "1e308"],
     "damping-coefficient"),
    (["sea", "--length", "1e308"], "length"),
    (["sea", "--mass", "1e308"], "mass"),
])
def test_physical_units_have_ranges(capsys, args, word):
    err = one_line_error(capsys, args)
    assert err.split("error: ")[1].startswith(word + ":"), err


def test_units_scales_finite_over_the_ranges():
    from parapend.units import Units

    for l_ in limits.UNIT_LENGTH_RANGE:
        for m in limits.UNIT_MASS_RANGE:
            for g in limits.UNIT_GRAVITY_RANGE:
                for ratio in limits.UNIT_INERTIA_RATIO:
                    u = Units(l_, m, g, ratio * m * l_**2)
                    scales = (u.time, u.torque, u.power, u.damping, u.moment_of_inertia)
                    assert all(1e-35 < x < 1e35 for x in scales), (l_, m, g, ratio)
                    # power unit = torque unit / time unit, independently
                    assert u.power == pytest.approx(m * g * l_ / math.sqrt(ratio * l_ / g),
                                                    rel=1e-13)


def test_track_refuses_plants_it_cannot_sample(capsys):
    err = one_line_error(capsys, ["track", "--gamma", "1e3", "--periods", "20"])
    assert err.split("error: ")[1].startswith("gamma: expected gamma <= 38.6")
    err = one_line_error(capsys, ["track", "--omega", "1e-3", "--periods", "20"])
    # 2 pi sqrt(1 + 1.9 * 0.3) / 256
    assert err.split("error: ")[1].startswith(
        f"omega: expected omega >= {2 * math.pi * math.sqrt(1 + 1.9 * 0.3) / 256:.4g}")


@pytest.mark.slow  # several seconds; the default run stays within its budget
def test_track_divergence_is_a_status(monkeypatch):
    """The safety net behind the sampling rule: a run that blows up ends with a status."""
    from parapend.control.closedloop import Diverged, run_closed_loop
    from parapend.control.track import prepare, track

    monkeypatch.setattr(limits, "TRACK_MAX_STEP_RATE", 1e9)
    r = track(gamma=1e3, periods=20)  # h gamma = 13.6: RK4 over h/4 is unstable
    assert r.status == "diverged" and not r.success and math.isnan(r.mean_power)
    with pytest.raises(parapend.errors.SolverError, match="diverged"):
        track(gamma=1e3, periods=20, throw=True)
    d = prepare(harmonics=8)
    with pytest.raises(Diverged):
        run_closed_loop(d.target, d.lqr.gains, periods=20, torque_limit=None,
                        plant_q=lambda t: 0 * t, plant_gamma=-200.0)


def test_threshold_out_of_range_names_the_excitation(capsys):
    err = one_line_error(capsys, ["threshold", "--omega", "1e-3", "--delta", "1e3"])
    assert err.split("error: ")[1].startswith("excitation:")
    assert "omega = 0.001" in err and "delta = 1000" in err and "500000.0" not in err
    # the uniform rotation's threshold, |Q1|/(2 omega) = 1e3/(2e-3), is the number named
    assert "5e+05" in err


def test_sea_q_cap_applies_to_the_record(capsys):
    err = one_line_error(capsys, ["sea", "--gravity", "1e-3"])
    assert err.split("error: ")[1].startswith("sea: expected |q(t)| <= 1000")
    assert "gravity" in err


@pytest.mark.parametrize("option", ["--file", "--record", "--response"])
def test_fifo_refused_without_blocking(tmp_path, option):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    cmd = ["sea", option, str(fifo)] if option != "--file" else ["optimize", option, str(fifo)]
    r = cli(*cmd, timeout=60)  # a blocking open would hang until the timeout
    assert r.returncode == 2 and "FIFO" in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_sea_record_resampled_length_capped(tmp_path):
    t = np.append(np.arange(40) * 0.01, 3e5)
    rec = _rows(tmp_path / "late.csv", "t,z", t, 0.1 * np.sin(t))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(ParameterError, match=rf"record: resampling .* more than "
                                             rf"{limits.SEA_MAX_RESAMPLED}"):
        parapend.sea(record=rec)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100_000  # KB


def test_sea_response_arrays_checked():
    f = [0.0, 0.1, 0.2]
    with pytest.raises(ParameterError, match=r"response: expected gains in \[0, 1e3\]"):
        parapend.sea(response=(f, [1.0, -1.0, 1.0], [0.0, 0.0, 0.0]))
    with pytest.raises(ParameterError, match="response: expected three 1-D arrays"):
        parapend.sea(response=(f, [1.0, 1.0], [0.0, 0.0, 0.0]))
    with pytest.raises(ParameterError, match="response: expected a CSV path or three"):
        parapend.sea(response=42)
    with pytest.raises(ParameterError, match="response: expected finite"):
        parapend.sea(response=(f, [1.0, np.nan, 1.0], [0.0, 0.0, 0.0]))


def test_any_real_number_accepted_anything_else_refused():
    from decimal import Decimal
    from fractions import Fraction

    ref = parapend.optimize(omega=1.8, delta=-0.3, gamma=0.01, harmonics=4)
    for conv in (Decimal, lambda x: Fraction(str(x)), np.float32, np.array):
        r = parapend.optimize(omega=conv("1.8") if conv is Decimal else conv(1.8),
                              delta=conv("-0.3") if conv is Decimal else conv(-0.3),
                              gamma=conv("0.01") if conv is Decimal else conv(0.01),
                              harmonics=4)
        if conv is np.float32:  # float32(1.8) is another number than 1.8
            assert r.power == pytest.approx(ref.power, rel=1e-6)
        else:
            assert r.power == ref.power and r.omega == 1.8
    for bad in ("1.8", 1.8 + 0j, [1.8], np.array([1.8]), None, True, Decimal("NaN")):
        with pytest.raises(ParameterError, match=r"^omega: expected a (real|finite) number"):
            parapend.optimize(omega=bad, harmonics=4)


def test_an_oversized_record_is_described_as_a_record(tmp_path):
    """A measured record over its size cap (64 bytes for each of its most rows: a full
    record at full precision fits, where the 4 MiB of a 'tau,q' file did not) is refused
    before reading with what a record holds ('t,z' rows), not a forcing period's 'tau,q'."""
    from parapend import limits
    from parapend.seas import measured_record
    from parapend.units import Units

    p = tmp_path / "big.csv"
    with open(p, "wb") as f:
        f.write(b"t,z\n")
        f.truncate(64 * limits.SEA_MAX_RECORD_ROWS + 1)
    with pytest.raises(ParameterError, match=r"^record: .* larger than 8 MiB; expected a CSV "
                                             r"of at most 131072 rows 't,z'"):
        measured_record(Units(length=1.0, mass=10.0), p)
