"""The coupled optimum in the time domain: Cummins' equation coupled with the pendulum
(:func:`parapend.hydro.timedomain.simulate`, which knows nothing of the harmonic balance),
driven by the optimum's torque, reproduces the optimal periodic motion and its power.

The torque is the optimum's ``tau*(t)`` plus a stiff tracking term ``k_p (theta* - theta) +
k_d (theta*' - theta')``, which is zero on the optimal motion: if the simulation stays on that
motion, the tracking term stays negligible and the harvested power is the optimum's. The
buoy and the pendulum start on the optimal motion, with the buoy's past heave velocity
prefilled, so there is no transient. Hydrodynamics: the exactly causal synthetic dataset of
tests/buoy_synthetic.py (no BEM).
"""

import math

import numpy as np
from buoy_synthetic import synthetic

from parapend.hydro import timedomain as td
from parapend.hydro.coupled import Pendulum, Wave
from parapend.hydro.optimum import coupled_optimum

HYDRO = synthetic()


def test_the_optimal_torque_reproduces_the_optimal_motion_and_power():
    height, period = 0.4, 2 * math.pi / 2.6
    pend = Pendulum(mass=100.0, length=0.5, inertia=30.0, damping_coefficient=5.0)
    wave = Wave.regular(height, period)
    sol = coupled_optimum(HYDRO, pend, wave, harmonics=16)
    assert sol.success and sol.power > 0
    one_way = coupled_optimum(HYDRO, pend, wave, harmonics=16, one_way=True)
    # the design is one where the coupling matters, so the check is not of the one-way motion
    assert abs(one_way.power / sol.power - 1) > 0.05

    w = wave.omega
    periods = 3
    dt = period / 400
    kp, kd = 4e3, 2e2  # N m/rad, N m s/rad: stiff against the pendulum's 30 kg m^2

    def tau(t, th, om):
        s = sol.sample(np.array([t]))
        return float(s["tau"][0] + kp * (s["theta"][0] - th) + kd * (s["theta_dot"][0] - om))

    s0 = sol.sample(np.array([0.0]))
    r = td.simulate(HYDRO, mass=pend.mass, length=pend.length, inertia=pend.inertia,
                    damping_coefficient=pend.damping_coefficient, torque=tau,
                    wave=td.regular_wave_force(HYDRO, w, height / 2), t_end=periods * period,
                    theta0=float(s0["theta"][0]), omega0=float(s0["theta_dot"][0]),
                    z0=float(s0["z"][0]), zdot0=float(s0["z_dot"][0]),
                    history=lambda t: sol.sample(np.asarray(t))["z_dot"], dt=dt,
                    match_omega=w, memory=15.0)
    t = r["t"]
    ref = sol.sample(t)
    # the time-domain model's impedance differs from Hydro.impedance by its discrete memory
    # and A_inf: that difference (at the harmonics that carry the heave) plus 2e-3 for the
    # integrator is the tolerance
    ks = np.arange(1, 4) * w
    model = td.model_impedance(HYDRO, ks, dt=r["dt"], memory=r["memory"], match_omega=w)
    tol = float(np.max(np.abs(HYDRO.impedance(ks) / model - 1))) + 2e-3
    zscale = float(np.max(np.abs(ref["z"])))
    assert np.max(np.abs(r["z"] - ref["z"])) < 2 * tol * zscale
    assert np.max(np.abs(r["theta"] - ref["theta"])) < 2 * tol
    n = round(period / r["dt"])  # the last period, one sample per step (trapezoid = mean)
    p_sim = float(np.mean(r["power"][-n:]))
    assert abs(p_sim / sol.power - 1) < 2 * tol
    # the tracking term did (almost) nothing: the motion is the optimum's own
    track = np.abs(r["tau"] - ref["tau"])
    assert np.max(track) < 2 * tol * np.max(np.abs(ref["tau"]))
