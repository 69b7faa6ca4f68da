"""The coupled optimum does not depend on rounding: a regular wave's ideal optimum and its
half-period image ``theta(t + T/2) + pi`` tie in power (hydro/optimum.py,
``half_period_image``), and the result is the one of the two with the smaller peak torque,
whatever the last bits of the data or the calls made before.

Independent sources: the derivation of the image (its heave ``-(-1)^k Z_k``, its torque
``tau(s + pi) + 2 m l g sin(theta(s + pi))``), the energy balance of the image, and the same
call with the data perturbed by a few ulp (before the rule, rounding picked either copy:
peaks 297.1 and 318.7 N m on the default design).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from buoy_synthetic import toy_hydro

from parapend.hydro.coupled import Pendulum, Wave
from parapend.hydro.optimum import BALANCE_TOL, coupled_optimum
from parapend.optimal.fourier import motion_distance

# a buoy like the default design (M = 402 kg, resonance near 1.74 s) without BEM
HYDRO = toy_hydro(radius=0.5, top=12.0)
PEND = Pendulum(80.0, 0.3, 7.2, 1.0)
WAVE = Wave.regular(0.2, 1.8)
ULP = 2.0**-52


def test_half_period_image_has_the_same_power_and_another_torque():
    from parapend.hydro.optimum import _heave_and_balance, half_period_image

    s = coupled_optimum(HYDRO, PEND, WAVE)
    x = np.asarray(s.theta_coefficients["x"])
    y = half_period_image(x, 1)
    m = 4096
    px, zx, rx, tx = _heave_and_balance(HYDRO, PEND, WAVE, x, 1, m, True, True)
    py, zy, ry, ty = _heave_and_balance(HYDRO, PEND, WAVE, y, 1, m, True, True)
    assert py == pytest.approx(px, rel=1e-12)
    assert max(rx, ry) <= BALANCE_TOL
    k = np.arange(zx.size)
    assert np.allclose(zy, -((-1.0) ** k) * zx, rtol=0, atol=1e-12 * np.max(np.abs(zx)))
    # tau~(s) = tau(s + pi) + 2 m l g sin(theta(s + pi)), from the motion sampled directly
    t = s.period * np.arange(m) / m
    half = s.sample(t + s.period / 2)
    grav = 2 * PEND.mass * PEND.length * HYDRO.g * np.sin(half["theta"])
    assert np.allclose(ty, half["tau"] + grav, rtol=0, atol=1e-9 * np.max(np.abs(tx)))
    # the two torques differ; the result is the copy with the smaller peak
    assert np.max(np.abs(ty)) > np.max(np.abs(tx)) * (1 + 1e-3)
    assert s.evidence["ideal_peak_torque"] == pytest.approx(np.max(np.abs(tx)), rel=1e-12)
    assert s.evidence["image_peak_torque"] == pytest.approx(np.max(np.abs(ty)), rel=1e-12)


def test_winding_two_image_turns_the_offset_by_pi():
    from parapend.hydro.optimum import half_period_image

    x = np.array([0.3, 0.1, 0.2, -0.4, 0.5])  # N = 2: a1, a2, b1, b2
    for k, a0 in ((1, 0.3), (2, 0.3 + math.pi), (3, 0.3)):
        y = half_period_image(x, k)
        assert y[0] == pytest.approx(a0)
        assert list(y[1:]) == [-0.1, 0.2, 0.4, 0.5]
        # theta~(s) = theta(s + pi) + pi, modulo 2 pi, at a few phases
        for s_ in (0.0, 0.7, 2.5):
            th = k * s_ + y[0] + y[1] * math.sin(s_) + y[2] * math.sin(2 * s_) + \
                y[3] * math.cos(s_) + y[4] * math.cos(2 * s_)
            sp = s_ + math.pi
            ref = k * sp + x[0] + x[1] * math.sin(sp) + x[2] * math.sin(2 * sp) + \
                x[3] * math.cos(sp) + x[4] * math.cos(2 * sp) + math.pi
            assert math.remainder(th - ref, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


def test_the_choice_does_not_depend_on_the_last_bits():
    """The mass changed by 0 to 7 ulp: the same motion (before the rule, the copy with the
    peak 318.7 N m or 297.1 N m, as rounding fell)."""
    base = None
    for j in range(8):
        h = dataclasses.replace(HYDRO, mass=HYDRO.mass * (1 + j * ULP))
        s = coupled_optimum(HYDRO if j == 0 else h, PEND, WAVE)
        assert s.success, s.status
        peak = s.peak_torque()
        if base is None:
            base = (s.power, peak, s.theta_coefficients["x"])
            continue
        assert s.power == pytest.approx(base[0], rel=1e-12)
        assert peak == pytest.approx(base[1], rel=1e-9), j
        assert motion_distance(s.theta_coefficients["x"], base[2]) < 1e-6, j


def test_the_same_call_after_others_is_bit_identical():
    first = coupled_optimum(HYDRO, PEND, WAVE)
    coupled_optimum(HYDRO, PEND, Wave.regular(0.3, 2.2))
    coupled_optimum(HYDRO, PEND, WAVE, one_way=True)
    again = coupled_optimum(HYDRO, PEND, WAVE)
    assert again.power == first.power
    assert np.array_equal(again.theta_coefficients["x"], first.theta_coefficients["x"])
    assert np.array_equal(again.heave, first.heave)


def test_a_wave_with_even_harmonics_has_no_image():
    """A record with a second harmonic: no symmetry, the search's own optimum stands."""
    t = np.linspace(0.0, 3.6, 256, endpoint=False)
    w = 2 * math.pi / 3.6
    eta = 0.1 * np.sin(2 * w * t) + 0.03 * np.cos(4 * w * t + 0.3)
    s = coupled_optimum(HYDRO, PEND, Wave.from_record(t, eta), winding=2)
    assert s.evidence["image_peak_torque"] is None
