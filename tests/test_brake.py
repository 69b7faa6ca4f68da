"""The constant brake (parapend.optimal.brake): the torque-limited optimum at small limits.

Checked against a closed form (its power is the bound ``T_max omega`` of every monotone
rotation), an independent integration of Eq. 14 (SciPy's DOP853 from the motion's own
initial state) and the Hermite optimum (which may approach the bound, never pass it).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import parapend
from parapend.model import peak_torque
from parapend.optimal.brake import constant_brake
from parapend.optimal.hermite import solve_hermite
from parapend.pto import optimize_pto


@pytest.mark.parametrize("gamma, tmax", [(0.01, 0.02), (0.01, 0.08), (0.01, 0.12),
                                         (0.05, 0.02)])
def test_small_limits_give_the_constant_brake_at_the_bound(gamma, tmax):
    r = optimize_pto(gamma=gamma, torque_limit=tmax)
    assert r.status == "converged" and r.method == "constant-brake"
    omega = r.omega
    assert r.power == pytest.approx(tmax * omega, rel=1e-12)  # P = T_max <theta'>
    assert r.peak_torque <= tmax * (1 + 1e-9)
    assert r.refinement_change <= 1e-12
    # the motion solves Eq. 14 under T = -T_max: integrate it independently over a period
    exc = r._excitation
    m = r.motion
    period = 2 * math.pi / omega

    def rhs(t, y):
        return [y[1], -gamma * y[1] + (1 + exc.q(t)) * math.sin(y[0]) - tmax]

    y0 = [float(m.theta(0.0)), float(m.theta_dot(0.0))]
    t = np.linspace(0.0, period, 257)
    sol = solve_ivp(rhs, (0.0, period), y0, method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=t)
    assert sol.y[0, -1] == pytest.approx(y0[0] + 2 * math.pi, abs=1e-8)
    assert sol.y[1, -1] == pytest.approx(y0[1], abs=1e-8)
    assert np.max(np.abs(sol.y[0] - m.theta(t))) <= 1e-8
    assert np.max(np.abs(sol.y[1] - m.theta_dot(t))) <= 1e-8


def test_hermite_creeps_up_to_the_brake_from_below():
    """The Hermite optimum at the same limit is monotone and stays below the bound, coming
    closer as the intervals double: the brake, at the bound, is the better answer."""
    gamma, tmax = 0.01, 0.1
    ideal = parapend.optimize(gamma=gamma)
    exc = ideal._excitation
    powers = []
    for k in (64, 128):
        s = solve_hermite(exc, gamma, k, ideal.motion, torque_limit=tmax)
        powers.append(s.power)
    assert powers[0] < powers[1] <= tmax * exc.omega
    motion, n, _ = constant_brake(exc, gamma, tmax, s.motion)
    assert peak_torque(motion, exc, gamma) == pytest.approx(tmax, rel=1e-9)
    assert np.min(motion.theta_dot(np.linspace(0, 2 * math.pi / exc.omega, 1001))) > 0


def test_no_brake_above_what_the_excitation_sustains():
    """At gamma = 0.01, T_max = 0.3 no rotation holds a constant brake of 0.3 (the optimum,
    0.2354, is far below 0.3 omega = 0.54): Newton fails, None, and optimize_pto keeps the
    Hermite optimum."""
    ideal = parapend.optimize(gamma=0.01)
    assert constant_brake(ideal._excitation, 0.01, 0.3, ideal.motion) is None
    r = optimize_pto(gamma=0.01, torque_limit=0.3, ideal=ideal)
    assert r.method == "hermite" and r.status == "converged"
    assert r.power < 0.3 * r.omega

