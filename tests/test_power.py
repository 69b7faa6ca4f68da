"""Power and torque: closed forms, two independent quadratures, energy balance."""

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

import parapend
from parapend.model import rhs, torque
from parapend.power import limit_motion_power, mean_power, power_by_parts, uniform_power
from parapend.trajectory import FourierMotion


@pytest.mark.parametrize("phi", [0.0, 1.0, math.pi, 4.0])
def test_uniform_rotation_power_closed_form(paper, phi):
    """Eq. 17 generalized to any phase: P = omega delta cos(phi)/2 - gamma omega^2."""
    m = FourierMotion(1.8, phi, np.zeros(3), np.zeros(3))
    expected = 1.8 * (-0.3) * math.cos(phi) / 2 - 0.05 * 1.8**2
    assert mean_power(m, paper, 0.05) == pytest.approx(expected, abs=1e-15)


def test_best_uniform_is_eq17(paper):
    p, phi = uniform_power(paper)
    assert p == pytest.approx(0.27, abs=1e-15)  # Table 1
    assert math.cos(phi) == pytest.approx(-1.0)  # theta = omega t + pi


def test_power_forms_agree_and_match_adaptive_quadrature(paper):
    rng = np.random.default_rng(7)
    m = FourierMotion(1.8, 0.4, rng.normal(size=5) * 0.4, rng.normal(size=5) * 0.4)
    p1 = mean_power(m, paper, 0.01, points=4096)
    p2 = power_by_parts(m, paper, 0.01, points=4096)
    T = 2 * math.pi / 1.8
    direct = quad(lambda t: (1 + paper.q(t)) * math.sin(m.theta(t)) * m.theta_dot(t)
                  - 0.01 * m.theta_dot(t) ** 2, 0, T, limit=400, epsabs=1e-13)[0] / T
    assert p1 == pytest.approx(p2, abs=1e-13)
    assert p1 == pytest.approx(direct, abs=1e-11)
    assert m.mean_square_speed() == pytest.approx(
        quad(lambda t: m.theta_dot(t) ** 2, 0, T, limit=400)[0] / T, rel=1e-12)


def test_energy_balance_torque_power(paper):
    """P = -<T theta'> (Eq. 6) with T from Eq. 14."""
    r = parapend.optimize(gamma=0.02, harmonics=12)
    t = paper.period * np.arange(4096) / 4096
    tq = torque(r.motion, paper, 0.02, t)
    assert -np.mean(tq * r.motion.theta_dot(t)) == pytest.approx(r.power, abs=1e-12)


def test_torque_reproduces_motion_when_simulated(paper):
    """Simulating Eq. 14 under the optimum's torque T(t) retraces the motion."""
    r = parapend.optimize(gamma=0.03, harmonics=10)
    m = r.motion

    def control(t, th, om):
        return float(torque(m, paper, 0.03, t))

    y0 = [float(m.theta(0.0)), float(m.theta_dot(0.0))]
    sol = solve_ivp(rhs(paper, 0.03, control), (0, paper.period), y0, rtol=1e-12, atol=1e-12,
                    dense_output=True, method="DOP853")
    t = np.linspace(0, paper.period, 50)
    np.testing.assert_allclose(sol.sol(t)[0], m.theta(t), atol=1e-8)
    assert sol.y[0, -1] - y0[0] == pytest.approx(2 * math.pi, abs=1e-8)  # Eq. 3


def test_limit_motion_power_equals_total_variation_formula():
    for exc in [parapend.harmonic(), parapend.two_harmonic(),
                parapend.fourier([(1, 0.2, 0), (2, 0.15, 1.0), (4, 0.08, 0.3)], omega=2.0)]:
        lim = parapend.limit(exc)
        assert limit_motion_power(lim.motion, exc) == pytest.approx(lim.power, abs=1e-14)


@pytest.mark.slow  # about 2-6 s: the default set stays under 5 minutes
def test_peak_torque_against_dense_sampling_and_the_bvp(paper):
    """Peak |T| (printed by the CLI): equals a 200k-point pointwise maximum, and the Fourier
    and BVP optima (two methods, same problem) need the same peak torque."""
    r = parapend.optimize(gamma=5e-4, harmonics=64)
    t = np.linspace(0, paper.period, 200_001)
    dense = np.max(np.abs(torque(r.motion, paper, 5e-4, t)))
    assert r.peak_torque == pytest.approx(dense, rel=1e-8)
    b = parapend.optimize(gamma=5e-4, harmonics=64, method="bvp")
    assert b.peak_torque == pytest.approx(r.peak_torque, rel=1e-6)
    assert b.mean_square_speed == pytest.approx(r.mean_square_speed, rel=1e-8)
