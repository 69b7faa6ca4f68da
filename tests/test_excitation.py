"""Excitations: spectra against their defining formulas, extrema, total variation, files."""

import math

import numpy as np
import pytest

import parapend
from parapend import excitation as E
from parapend.errors import ParameterError


def test_harmonic_extrema_and_total_variation(paper):
    e = paper.extrema
    # q = -0.3 sin(1.8 t): minimum at tau = 1/4, maximum at tau = 3/4
    np.testing.assert_allclose(e.t * paper.omega / (2 * np.pi), [0.25, 0.75], atol=1e-13)
    np.testing.assert_allclose(e.q, [-0.3, 0.3], atol=1e-15)
    assert list(e.is_max) == [False, True]
    assert paper.total_variation == pytest.approx(1.2, abs=1e-14)


def test_two_harmonic_switching_instants_of_paper():
    """Paper Section 7.1: q' vanishes at omega t / 2 pi = 0.1903 and 0.8096 for Eq. 23."""
    e = parapend.two_harmonic(-0.3, 1.8)
    tau = e.extrema.t * 1.8 / (2 * np.pi)
    np.testing.assert_allclose(tau, [0.1903, 0.8096], atol=1e-4)
    # exact: cos s + cos(2s)/2 = 0 -> cos s = (-1 + sqrt 3)/2
    s1 = math.acos((math.sqrt(3) - 1) / 2)
    np.testing.assert_allclose(tau, [s1 / (2 * np.pi), 1 - s1 / (2 * np.pi)], atol=1e-12)
    np.testing.assert_allclose(e.dq(e.extrema.t), 0, atol=1e-13)


def test_extrema_found_once_per_shape_in_the_phase():
    """The extrema are found in s = omega t for the shape of q (spectrum over its largest
    harmonic amplitude), once per shape: they equal Brent's method on dq/dt in t itself, and
    a map over omega and delta of one excitation computes them twice (one per sign)."""
    from scipy.optimize import brentq

    E._phase_extrema.cache_clear()
    terms = [(1, -0.3, 0.2), (3, 0.15, 1.0), (5, 0.05, -0.4)]
    for e in (parapend.fourier(terms, omega=2.1), parapend.two_harmonic(0.2, 1.3),
              parapend.harmonic(-0.45, 0.7)):
        ex = e.extrema
        assert ex.t.size in (2, 4, 6, 8, 10)
        for t, q in zip(ex.t, ex.q):
            h = 1e-3 * e.period
            r = brentq(lambda x, e=e: float(e.dq(x)), t - h, t + h, xtol=1e-15)
            assert t == pytest.approx(r, abs=4e-15 * e.period)
            assert q == float(e.q(t))
    E._phase_extrema.cache_clear()
    for om in (1.2, 1.7, 2.4):
        for d in (-0.5, -0.17, 0.05, 0.3):
            ex = parapend.harmonic(d, om).extrema
            s = ex.t * om
            np.testing.assert_allclose(s, [np.pi / 2, 3 * np.pi / 2], rtol=1e-15)
            assert list(ex.is_max) == [d > 0, d < 0]
    assert E._phase_extrema.cache_info().misses == 2


def test_fourier_series_matches_definition():
    terms = [(1, -0.3, 0.2), (3, 0.15, 1.0), (5, 0.05, -0.4)]
    e = parapend.fourier(terms, omega=2.1)
    t = np.linspace(0, 3, 57)
    q = sum(a * np.sin(k * 2.1 * t + p) for k, a, p in terms)
    dq = sum(a * k * 2.1 * np.cos(k * 2.1 * t + p) for k, a, p in terms)
    np.testing.assert_allclose(e.q(t), q, atol=1e-14)
    np.testing.assert_allclose(e.dq(t), dq, atol=1e-13)
    # extrema alternate and are roots of q'
    ex = e.extrema
    assert np.all(ex.is_max[1:] != ex.is_max[:-1])
    np.testing.assert_allclose(e.dq(ex.t), 0, atol=1e-12)
    # total variation equals the integral of |q'| over a period (independent quadrature)
    tt = np.linspace(0, e.period, 400001)
    tv = np.trapezoid(np.abs(e.dq(tt)), tt)
    assert e.total_variation == pytest.approx(tv, rel=1e-8)


def test_square_wave_spectrum_matches_eq26_formula():
    e = parapend.square(-0.3, 1.8, alpha=0.01)
    m = 1 << 15
    t = e.period * np.arange(m) / m
    np.testing.assert_allclose(e.q_grid(m), e.q(t), atol=1e-12)
    np.testing.assert_allclose(e.dq_grid(m), e.dq(t), atol=1e-9 * np.max(np.abs(e.dq(t))))
    # plateaus at -delta*... : q = delta on the first half (H = +1), -delta on the second
    assert e.q(e.period / 4) == pytest.approx(-0.3, abs=1e-12)
    assert e.q(3 * e.period / 4) == pytest.approx(0.3, abs=1e-12)
    assert e.total_variation == pytest.approx(1.2, abs=1e-12)


def _csv(tau, q):
    return "tau,q\n" + "\n".join(f"{float(a)!r},{float(b)!r}" for a, b in zip(tau, q))


def _write(tmp_path, text, name="q.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_csv_uniform_samples_reproduce_trig_polynomial(tmp_path):
    tau = np.arange(32) / 32
    q = 0.2 * np.sin(2 * np.pi * tau + 0.3) - 0.1 * np.cos(4 * np.pi * tau)
    p = _write(tmp_path, _csv(tau, q))
    e = parapend.from_csv(p, omega=1.5)
    t = np.linspace(0, e.period, 101)
    s = 1.5 * t
    np.testing.assert_allclose(e.q(t), 0.2 * np.sin(s + 0.3) - 0.1 * np.cos(2 * s), atol=1e-14)


def test_csv_nonuniform_samples_are_splined(tmp_path):
    rng = np.random.default_rng(3)
    tau = np.sort(rng.uniform(0, 1, 80))
    q = 0.3 * np.sin(2 * np.pi * tau)
    p = _write(tmp_path, _csv(tau, q))
    e = parapend.from_csv(p, omega=1.8)
    assert e.total_variation == pytest.approx(1.2, rel=2e-3)


@pytest.mark.parametrize("text, match", [
    ("t,q\n" + "0,1\n" * 20, "header"),
    ("tau,q\n" + "\n".join(f"{i / 10},{i}" for i in range(10)), "at least 16"),
    ("tau,q\n" + "\n".join(f"{i / 16},{i}" for i in range(17)), r"\[0, 1\)"),
    ("tau,q\n" + "\n".join(f"{(i % 8) / 16},{i}" for i in range(16)), "increasing"),
    ("tau,q\n" + "\n".join(f"{i / 16},x" for i in range(16)), "two numbers"),
    ("tau,q\n" + "\n".join(f"{i / 16},nan" for i in range(16)), "finite"),
])
def test_csv_errors(tmp_path, text, match):
    with pytest.raises(ParameterError, match=match):
        parapend.from_csv(_write(tmp_path, text))


def test_csv_unreadable(tmp_path):
    with pytest.raises(ParameterError, match="cannot read"):
        parapend.from_csv(tmp_path / "missing.csv")


@pytest.mark.parametrize("kwargs, match", [
    ({"omega": 0.0}, "omega"), ({"omega": float("nan")}, "omega"),
    ({"delta": float("inf")}, "delta"),
])
def test_parameter_errors(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        parapend.harmonic(**kwargs)


def test_fourier_terms_parse_and_errors():
    assert E.parse_fourier_terms("1:-0.3, 3:0.1:0.5") == ((1, -0.3, 0.0), (3, 0.1, 0.5))
    for bad in ["", "1", "a:1", "0:1:0", "1.5:1"]:
        with pytest.raises(ParameterError):
            parapend.fourier(E.parse_fourier_terms(bad))


def test_nonuniform_record_resampled_from_its_own_density(tmp_path):
    """A non-uniform record is resampled at eight points per sample (at least 256): the
    spline's spectrum is the signal's to the spline's accuracy, and a record of up to 256
    rows stays within the harmonics a power take-off solve follows (it was refused)."""
    from parapend.excitation import _resample_points

    assert [_resample_points(n) for n in (16, 100, 256, 257, 16384)] == [256, 1024, 2048,
                                                                          4096, 4096]
    rng = np.random.default_rng(5)
    tau = np.sort(rng.uniform(0, 1, 200))
    q = -0.3 * np.sin(2 * np.pi * tau)
    e = parapend.from_csv(_write(tmp_path, _csv(tau, q)), omega=1.8)
    spec = e.spectrum
    assert spec.size == 1025
    # the fundamental of -0.3 sin s is 0.3i in this project's exp(+i s) convention; the
    # spline through 200 random samples carries the rest at its O(h^4) accuracy
    assert abs(spec[1] - 0.3j) < 1e-5 and np.max(np.abs(spec[2:])) < 1e-5
    from parapend.pto import optimize_pto

    pto = optimize_pto(file=str(tmp_path / "q.csv"), omega=1.8, gamma=0.03, torque_limit=2.0)
    ref = optimize_pto(omega=1.8, delta=-0.3, gamma=0.03, torque_limit=2.0)
    assert pto.success and abs(pto.power - ref.power) < 1e-4 * ref.power
