"""Cummins' equation coupled with the pendulum (hydro/timedomain.py), on a synthetic, exactly
causal dataset (tests/buoy_synthetic.py): no BEM, fast."""

import math

import numpy as np
import pytest
from buoy_synthetic import A_INF, W0, ZETA, K, kernel, synthetic

from parapend.errors import ParameterError
from parapend.hydro import timedomain as td

HYDRO = synthetic()


def test_kernel_matches_the_closed_form():
    # K is the cosine transform of B truncated at w_max = 60 rad/s: the tail of B
    # (~ 2 k zeta w0 / w^2) changes K by at most (2/pi) * 2 k zeta w0 / w_max
    t = np.linspace(0.0, 8.0, 81)
    tail = (2 / math.pi) * 2 * K * ZETA * W0 / HYDRO.omega[-1]
    err = np.max(np.abs(td.radiation_kernel(HYDRO, t) - kernel(t)))
    assert err < 1.2 * tail
    assert err < 0.03 * K


def test_a_infinity_from_kramers_kronig():
    est = td.a_infinity(HYDRO)
    # the truncation of B's tail above w_max shifts the estimates by ~ (2/pi) int B / v^2
    assert np.max(np.abs(est - A_INF)) < 0.01 * A_INF


def _free(w, dt, match=True):
    z = complex(HYDRO.free_response(w))
    hist = lambda t: np.real(1j * w * z * np.exp(1j * w * t))  # noqa: E731
    periods = 6
    r = td.simulate(HYDRO, mass=0.0, length=0.0, inertia=1.0,
                    wave=td.regular_wave_force(HYDRO, w, 1.0), t_end=periods * 2 * math.pi / w,
                    z0=z.real, zdot0=(1j * w * z).real, history=hist, dt=dt,
                    match_omega=w if match else None, memory=15.0)
    t = r["t"]
    n = round(2 * math.pi / w / r["dt"])  # the last period, one sample per step
    zf = 2 * np.mean(r["z"][-n:] * np.exp(-1j * w * t[-n:]))
    return z, zf, r


@pytest.mark.parametrize("w", [1.2, 2.6, 5.0])
def test_free_buoy_continues_its_periodic_response(w):
    # Started on the frequency-domain response with its past prefilled, the simulated motion
    # stays on it. The time-domain model's own impedance differs from Hydro.impedance by the
    # discrete memory (model_impedance): the tolerance is that difference plus 2e-3 for the
    # integrator and the one-period Fourier fit.
    dt = 2 * math.pi / w / 200
    z, zf, r = _free(w, dt)
    model = td.model_impedance(HYDRO, w, dt=r["dt"], memory=r["memory"], match_omega=w)
    tol = abs(complex(HYDRO.impedance(w)) / complex(model) - 1) + 2e-3
    assert abs(abs(zf) / abs(z) - 1) < tol
    assert abs(np.angle(zf / z)) < tol


def test_time_step_refinement():
    w = 2.6
    _, z1, _ = _free(w, 2 * math.pi / w / 100)
    _, z2, _ = _free(w, 2 * math.pi / w / 200)
    assert abs(z1 / z2 - 1) < 2e-3


def test_coupled_energy_balance():
    # No invariant is shared with the solver: the mechanical energy
    # E = 1/2 (M + A_inf) z'^2 - m l sin(theta) z' theta' + 1/2 I theta'^2 + 1/2 C z^2
    #     + m g l cos(theta)
    # changes by the work of the wave, the radiation memory, the damper and the torque.
    m, ell, inertia, c = 120.0, 0.6, 60.0, 3.0
    w = 2.2
    tq = lambda t, th, om: -8.0 * om  # noqa: E731
    r = td.simulate(HYDRO, mass=m, length=ell, inertia=inertia, damping_coefficient=c,
                    torque=tq, wave=td.regular_wave_force(HYDRO, w, 0.3), t_end=6.0,
                    theta0=0.3, omega0=2.0, dt=0.004, a_inf=A_INF, memory=10.0)
    t, z, zd, th, om = r["t"], r["z"], r["zdot"], r["theta"], r["omega"]
    g = HYDRO.g
    e = (0.5 * (HYDRO.mass + A_INF) * zd**2 - m * ell * np.sin(th) * zd * om
         + 0.5 * inertia * om**2 + 0.5 * HYDRO.hydrostatic_stiffness * z**2
         + m * g * ell * np.cos(th))
    # the memory force mu at each step, recomputed independently by trapezoid on the
    # closed-form-free kernel of the data
    dt = r["dt"]
    kern = td.radiation_kernel(HYDRO, np.arange(0, r["memory"] + dt / 2, dt))
    mu = np.array([np.trapezoid(kern[: i + 1] * zd[i::-1][: kern.size], dx=dt)
                   if i + 1 <= kern.size else np.trapezoid(kern * zd[i::-1][: kern.size], dx=dt)
                   for i in range(t.size)])
    fex = td.regular_wave_force(HYDRO, w, 0.3)(t)
    p = zd * (fex - mu) + r["tau"] * om - c * om**2
    work = np.concatenate(([0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * dt)))
    scale = np.max(np.abs(e - e[0])) + np.max(np.abs(work))
    assert np.max(np.abs((e - e[0]) - work)) < 1e-3 * scale
    assert np.max(np.abs(th)) > 1.0  # the pendulum moved: the coupling was exercised


def test_pendulum_without_buoy_motion_is_the_free_pendulum():
    # m l != 0 but an enormous buoy: the pendulum swings as on a fixed pivot; energy of the
    # undamped pendulum, 1/2 I theta'^2 + m g l cos(theta), is conserved
    big = synthetic()
    object.__setattr__(big, "mass", 1e12)
    object.__setattr__(big, "hydrostatic_stiffness", 1e14)
    r = td.simulate(big, mass=1.0, length=1.0, inertia=1.0, t_end=5.0, theta0=math.pi - 0.5,
                    dt=0.002, memory=1.0)
    e = 0.5 * r["omega"] ** 2 + 9.81 * np.cos(r["theta"])
    assert np.ptp(e) < 1e-8 * abs(e[0])
    assert np.max(np.abs(r["z"])) < 1e-9


def test_bad_input():
    with pytest.raises(ParameterError, match="inertia"):
        td.simulate(HYDRO, mass=10.0, length=1.0, inertia=5.0, t_end=1.0)
    with pytest.raises(ParameterError, match="mass"):
        td.simulate(HYDRO, mass=-1.0, length=1.0, inertia=5.0, t_end=1.0)
    with pytest.raises(ParameterError, match="mass"):
        td.simulate(HYDRO, mass=1e6, length=0.0, inertia=5.0, t_end=1.0)


def test_spinning_flywheel_drives_the_heave_as_the_harmonic_balance_says():
    # A pendulum of huge inertia spins at a constant rate W: cos(theta) = Re(exp(i W t)), so
    # Chat_1 = 1 and the interface's per-harmonic heave equation gives
    # D(W) Z = m l W^2 Chat_1 (no wave). The simulation knows nothing of that formula.
    m, ell, spin = 50.0, 0.5, 2.6
    d = complex(HYDRO.impedance(spin))
    z = m * ell * spin**2 / d
    hist = lambda t: np.real(1j * spin * z * np.exp(1j * spin * t))  # noqa: E731
    dt = 2 * math.pi / spin / 200
    r = td.simulate(HYDRO, mass=m, length=ell, inertia=1e9, t_end=4 * 2 * math.pi / spin,
                    omega0=spin, z0=z.real, zdot0=(1j * spin * z).real, history=hist, dt=dt,
                    match_omega=spin, memory=15.0)
    assert np.ptp(r["omega"]) < 1e-6 * spin  # the flywheel's rate stays put
    n = round(2 * math.pi / spin / r["dt"])
    zf = 2 * np.mean(r["z"][-n:] * np.exp(-1j * spin * r["t"][-n:]))
    model = td.model_impedance(HYDRO, spin, dt=r["dt"], memory=r["memory"], match_omega=spin)
    tol = abs(d / complex(model) - 1) + 2e-3
    assert abs(zf / z - 1) < tol


def test_the_default_buoys_memory_is_passive():
    """The heaving buoy's discrete radiation memory (the plant of its closed loop and of
    :func:`parapend.hydro.timedomain.simulate`) takes energy out at every frequency up to
    its step's Nyquist frequency: ``Im D_td(w) / w = sum_j w_j cos(w t_j) >= 0`` to 1e-4 of
    the body's largest damping ``B`` (measured: -5.6e-6 of it, at 10.2 rad/s, near the top
    of the data), and it is ``B(w)`` to 2e-3 of that largest value over the wave band
    (measured: 1.2e-3; the same checks as the hull plant's memory)."""
    from parapend.hydro import bem
    from parapend.hydro.api import _dimensions

    hydro = bem.cylinder(*_dimensions(None, None, None), omega="body")
    wn, bn = td._b_nodes(hydro)
    for dt in (0.01, 0.05, 0.1):
        w = np.linspace(1e-3, math.pi / dt, 4000)
        kc = td.model_impedance(hydro, w, dt=dt).imag / w
        assert kc.min() >= -1e-4 * bn.max()
        band = (w > 0.3) & (w < 0.9 * wn[-1])
        assert np.max(np.abs(kc[band] - np.interp(w[band], wn, bn))) <= 2e-3 * bn.max()
