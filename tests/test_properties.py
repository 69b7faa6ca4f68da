"""Property tests (DESIGN.md section 5) over random excitations and parameters.

Each property runs twice: in the default run over the profile's examples (conftest.py:
derandomized, so every run draws the same examples) at small N, and, marked ``slow``, over
many more examples at larger N.
"""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import parapend
from parapend.optimal.fourier import solve_fourier
from parapend.power import mean_power
from parapend.trajectory import FourierMotion

term = st.tuples(st.integers(1, 4), st.floats(-0.4, 0.4).filter(lambda a: abs(a) > 0.02),
                 st.floats(0, 2 * math.pi))
excitations = st.builds(
    lambda terms, omega: parapend.fourier(terms, omega=omega),
    st.lists(term, min_size=1, max_size=3, unique_by=lambda t: t[0]),
    st.floats(0.8, 3.0),
)
dampings = st.sampled_from([0.0, 0.003, 0.03])


def _bounds_and_monotonicity(exc, gamma, n):
    """uniform <= optimum(N) <= optimum(2N) <= limit, and the motion's power is the reported
    one."""
    pu, _ = parapend.uniform_power(exc, gamma)
    lim = parapend.limit(exc).power
    b1, _ = solve_fourier(exc, n, gamma)
    b2, _ = solve_fourier(exc, 2 * n, gamma, warm=b1.x)
    assert b1.status == "converged" and b2.status == "converged"
    assert pu - 1e-12 <= b1.power <= b2.power + 1e-12
    assert b2.power <= lim - gamma * exc.omega**2 + 1e-12  # damping costs at least gamma omega^2
    m = FourierMotion.from_vector(exc.omega, b2.x)
    assert abs(mean_power(m, exc, gamma, points=8192) - b2.power) < 1e-11


def _threshold_is_where_power_vanishes(exc):
    r = parapend.threshold(excitation=exc)
    assert r.success
    assert r.damping_threshold >= r.uniform_threshold - 1e-12
    below = parapend.optimize(excitation=exc, gamma=0.99 * r.damping_threshold,
                              harmonics=r.harmonics)
    above = parapend.optimize(excitation=exc, gamma=1.01 * r.damping_threshold,
                              harmonics=r.harmonics)
    assert below.power > 0 > above.power


@given(excitations, dampings)
def test_bounds_and_monotonicity(exc, gamma):
    _bounds_and_monotonicity(exc, gamma, 6)


@pytest.mark.slow
@settings(max_examples=200)
@given(excitations, dampings)
def test_bounds_and_monotonicity_many(exc, gamma):
    _bounds_and_monotonicity(exc, gamma, 16)


@given(excitations)
@pytest.mark.slow
def test_threshold_is_where_power_vanishes(exc):
    _threshold_is_where_power_vanishes(exc)


@pytest.mark.slow
@settings(max_examples=100)
@given(excitations)
def test_threshold_is_where_power_vanishes_many(exc):
    _threshold_is_where_power_vanishes(exc)
