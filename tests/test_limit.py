"""gamma -> 0 limit: the paper's closed forms and the general total-variation formula."""

import math

import numpy as np
import pytest

import parapend
from parapend.optimal.fourier import solve_fourier


def test_eq19_harmonic():
    lim = parapend.limit(parapend.harmonic(-0.3, 1.8))
    assert lim.power == pytest.approx(2 * 1.8 * 0.3 / math.pi, abs=1e-15)  # 0.34377...
    assert round(lim.power, 4) == 0.3438  # Table 1
    assert lim.power / 0.27 - 1 == pytest.approx(0.2732, abs=1e-4)  # "exceeds by 27.32%"
    assert list(lim.directions) == [1, 1]


def test_eq24_two_harmonic():
    e = parapend.two_harmonic(-0.3, 1.8)
    lim = parapend.limit(e)
    t1, t2 = e.extrema.t
    om, d = 1.8, -0.3
    eq24 = om * d / math.pi * (math.sin(om * t2) - math.sin(om * t1)) \
        + om * d / (4 * math.pi) * (math.sin(2 * om * t2) - math.sin(2 * om * t1))
    assert lim.power == pytest.approx(abs(eq24), abs=1e-14)
    assert round(lim.power, 4) == 0.3785 or round(lim.power, 4) == 0.3784  # Table 2: 0.3784


def test_eq32_square():
    lim = parapend.limit(parapend.square(-0.3, 1.8, alpha=0.001))
    assert lim.power == pytest.approx(2 * 1.8 * 0.3 / math.pi, abs=1e-12)


def multi():
    """Three maxima per period: q = 0.2 sin s + 0.15 sin(3 s + 0.4) + 0.06 sin(5 s)."""
    return parapend.fourier([(1, 0.2, 0.0), (3, 0.15, 0.4), (5, 0.06, 0.0)], omega=1.8)


def test_multi_maxima_directions_and_switches():
    e = multi()
    lim = parapend.limit(e)
    assert e.extrema.t.size >= 6
    assert int(np.sum(lim.directions)) == 2  # one net turn per period (Eq. 3)
    # dwell angle has cos(theta) = sign(q') between switches
    t_mid = 0.5 * (lim.switch_times + np.roll(lim.switch_times, -1))
    t_mid[-1] += e.period / 2
    np.testing.assert_array_equal(np.sign(np.cos(lim.motion.theta(t_mid))),
                                  np.sign(e.dq(t_mid)))


def test_fourier_optimum_approaches_limit_from_below():
    """The Fourier optimum rises towards omega TV / 2 pi as N grows and never exceeds it."""
    e = multi()
    lim = parapend.limit(e).power
    x = None
    gaps = []
    for n in (8, 16, 32, 64, 128):
        best, _ = solve_fourier(e, n, 0.0, warm=x)
        x = best.x
        assert best.power <= lim + 1e-12
        gaps.append(lim - best.power)
    assert all(b <= a + 1e-15 for a, b in zip(gaps, gaps[1:]))
    assert gaps[-1] < 0.02 * gaps[0]
    assert gaps[-1] < 2e-3 * lim
