"""The hull model (surge, heave, pitch; hull_spec.md) replayed in the time domain
(Cummins' equation, 3 x 3 radiation convolution; tests/hull_timedomain.py) against the spec's
frequency-domain Galerkin equations for the same prescribed pendulum motion, on a synthetic,
exactly causal hull with a 10 x 4 x 1 m barge's magnitudes and a cut-off at 25 rad/s.

Tolerances. The time-domain steady state differs from the frequency domain by
(i) the model: its kernel is truncated and sampled, its ``A_inf`` a constant; measured exactly by
solving the frequency domain with the model's own coefficients (``model_coefficients``), and
(ii) the integrator: Newmark's trapezoidal rule answers harmonic ``k`` as if its frequency were
off by ``(k w dt)^2 / 12``, which moves the response by that times the sensitivity
``S_k = || Z_k^-1 (k w) dZ/dw ||``, allowed twice over.
"""

import math

import numpy as np
import pytest
from hull_timedomain import (
    A_INF,
    a_infinity_estimates,
    harmonic_response,
    interpolator,
    kernel,
    phi_fourier,
    replay,
    synthetic_exact,
    synthetic_hull,
    synthetic_kernel,
)

HULL = synthetic_hull()
W = 1.2  # rad/s: a 5.2 s wave; the hull's heave and pitch resonances are near 2.3 rad/s


def swing(psi, amp=0.5):
    """K = 0: phi = pi + amp sin(w t + psi)."""
    return lambda t: (math.pi + amp * np.sin(W * t + psi), amp * W * np.cos(W * t + psi),
                      -amp * W * W * np.sin(W * t + psi))


def rotate(psi, amp=0.3):
    """K = 1: phi = w t + psi + amp sin(w t)."""
    return lambda t: (W * t + psi + amp * np.sin(W * t), W + amp * W * np.cos(W * t),
                      -amp * W * W * np.sin(W * t))


# the brief's two motions (psi = 0.3 and 0 with this bearing: the generator motors, P < 0 for
# the rotation) and two phases that harvest (P > 0), one with a second wave harmonic
CASES = {
    "swing-0.3": (swing(0.3), [0.5]),
    "swing-1.6": (swing(1.6), [0.5]),
    "rotate-0": (rotate(0.0), [0.5]),
    "rotate-4.7-two-harmonics": (rotate(4.7), [0.5, 0.05j]),
}


def _sensitivity(k, hull=HULL, w=W):
    """``|| Z^-1 w dZ/dw ||_2`` at ``k w`` (the pendulum's mass lumped at the pivot)."""
    coef = interpolator(hull["omega_data"], hull["A"], hull["B"], hull["F"], hull["C"])
    d_p, h_p = hull["pivot"]
    g = np.array([[1.0, 0.0, h_p], [0.0, 1.0, -d_p]])
    cp = hull["C"].copy()
    cp[2, 2] -= hull["m"] * hull["g"] * h_p
    mass = hull["Mh"] + hull["m"] * g.T @ g

    def z(x):
        a, b, _ = coef(x)
        return -x * x * (mass + a) + 1j * x * b + cp
    x, h = k * w, 1e-4
    return float(np.linalg.norm(np.linalg.solve(z(x), x * (z(x + h) - z(x - h)) / (2 * h)), 2))


def _compare(phi, amps, spp, periods=18, ramp=6, hull=HULL, w=W):
    # 18 periods with a 6-period ramp: the transients have decayed to 1e-8 of the harmonics;
    # what is left is the surge's drift, 4e-4 of its velocity (1/ramp^4), removed as a trend
    wave = {"wave_omega": w, "amplitudes": amps}
    fd = harmonic_response(**hull, **wave, phi=phi)
    td = replay(**hull, **wave, phi=phi, periods=periods, ramp_periods=ramp, steps_per_period=spp)
    fm = harmonic_response(**hull, **wave, phi=phi, coefficients=td["model_coefficients"])
    return fd, td, fm


def _assert_agree(fd, td, fm, hull=HULL, w=W, kmax=3):
    """The time domain's harmonics 0..kmax and power against the frequency domain's, to the
    model's error (measured) plus twice the integrator's (the module's docstring)."""
    eps = (w * td["dt"]) ** 2 / 12
    scale = np.max(np.abs(fd["Xi"][1]))
    for k in range(1, kmax + 1):
        model = np.max(np.abs(fm["Xi"][k] - fd["Xi"][k]))
        tol = model + 2 * _sensitivity(k, hull, w) * k * k * eps * scale
        assert np.max(np.abs(td["Xi"][k] - fd["Xi"][k])) < tol, k
    # the mean heel and heave (k = 0): heave and pitch only, as in the spec
    s1 = _sensitivity(1, hull, w)
    tol0 = np.max(np.abs(fm["Xi"][0] - fd["Xi"][0])) + 2 * s1 * eps * np.max(np.abs(fd["Xi"][0]))
    assert np.max(np.abs(td["Xi"][0] - fd["Xi"][0])) < tol0
    # power: the model's share plus the integrator's, on the balance's scale
    tol_p = abs(fm["power"] - fd["power"]) + 2 * s1 * eps * fd["energy_scale"]
    assert abs(td["power"] - fd["power"]) < tol_p


# ---------------------------------------------------------------- the pieces

def test_kernel_is_the_cosine_transform_of_the_data():
    # K from the piecewise-linear, cut-off B against the exact K of the causal hull: they
    # differ by the transform of (B_data - B_exact), at most (2/pi) int |B_data - B_exact| dv
    # (|cos| <= 1): B's tail above the cut-off and the linear interpolation below it.
    om = HULL["omega_data"]
    t = np.linspace(0.0, 20.0, 201)
    err = np.max(np.abs(kernel(om, HULL["B"], t) - synthetic_kernel(t)), axis=0)
    v = np.linspace(1e-4, om[-1], 5001)
    bsym = 0.5 * (HULL["B"] + np.swapaxes(HULL["B"], 1, 2))
    b_lin = np.stack([np.interp(v, np.r_[0.0, om], np.r_[0.0, bsym[:, i, j]])
                      for i in range(3) for j in range(3)], axis=1).reshape(-1, 3, 3)
    below = np.abs(b_lin - synthetic_exact(v)[1])
    u = np.geomspace(om[-1], 1e5, 20001)
    above = np.abs(synthetic_exact(u)[1])
    # B ~ 1/w^2 beyond 1e5 rad/s: its integral there is B(1e5) 1e5
    bound = (2 / math.pi) * (np.trapezoid(below, v, axis=0) + np.trapezoid(above, u, axis=0)
                             + above[-1] * u[-1])
    assert np.all(err <= 1.05 * bound + 1e-9 * np.max(np.abs(synthetic_kernel(0.0))))
    assert np.max(err) < 0.07 * np.max(np.abs(synthetic_kernel(0.0)))


def test_the_models_damping_is_the_datas_and_its_added_mass_matches_at_the_fundamental():
    # Poisson: the trapezoidal cosine sum of a band-limited B is exact for dt < pi / (w_max + w);
    # what is left is the memory's truncation, which smooths B over ~2 pi / T_m: at most the
    # linear interpolation's error (dw^2 / 8) |B''| ~ 1e-3 of B here
    td = replay(**HULL, wave_omega=W, amplitudes=[0.5], phi=swing(0.3), periods=2,
                steps_per_period=100)
    coef = interpolator(HULL["omega_data"], HULL["A"], HULL["B"], HULL["F"], HULL["C"])
    for k in range(1, 6):
        a, b, f = coef(k * W)
        am, bm, fm = td["model_coefficients"](k * W)
        assert np.max(np.abs(bm - b)) < 1e-3 * np.max(np.abs(b))
        assert np.max(np.abs(am - a)) < (1e-12 if k == 1 else 1e-3) * np.max(np.abs(a))
        assert np.array_equal(fm, f)
    # A_inf itself is within 0.1 % of the hull's true one (the band limit's Kramers-Kronig
    # shift and the quadrature's dt^2 K(0) / 12 are what it absorbs)
    assert np.max(np.abs(td["a_inf"] - A_INF)) < 1e-3 * np.max(np.abs(A_INF))
    # the continuous Kramers-Kronig estimates agree to the same order
    est = a_infinity_estimates(HULL["omega_data"], HULL["A"], HULL["B"])
    est = est[HULL["omega_data"][:-1] < 10.0]
    assert np.max(np.abs(est - A_INF)) < 3e-3 * np.max(np.abs(A_INF))


def test_frequency_domain_free_hull_and_energy_balance():
    # no pendulum (m = l = I = c = 0): Xi_k = Z0_k^-1 F_k a_k, no mean
    free = dict(HULL, m=0.0, l=0.0, I=0.0, c=0.0)
    fd = harmonic_response(**free, wave_omega=W, amplitudes=[0.5, 0.1], phi=swing(0.3))
    coef = interpolator(HULL["omega_data"], HULL["A"], HULL["B"], HULL["F"], HULL["C"])
    for k, ak in ((1, 0.5), (2, 0.1)):
        a, b, f = coef(k * W)
        z = -(k * W) ** 2 * (HULL["Mh"] + a) + 1j * k * W * b + HULL["C"]
        ref = np.linalg.solve(z, f * ak)
        assert np.max(np.abs(fd["Xi"][k] - ref)) < 1e-12 * np.max(np.abs(ref))
    assert np.max(np.abs(fd["Xi"][0])) == 0.0 and np.max(np.abs(fd["Xi"][3:])) < 1e-15
    # with the pendulum: the spec's energy balance (an invariant the solve does not impose)
    for phi, amps in CASES.values():
        fd = harmonic_response(**HULL, wave_omega=W, amplitudes=amps, phi=phi)
        assert abs(fd["energy_residual"]) < 1e-9 * fd["energy_scale"]


def test_held_pendulum_heels_the_hull_in_both_domains():
    # phi held at 2 rad, no wave: the mean pitch C' Xi_0 = e_beta m l g sin(phi0), closed form
    phi0 = 2.0
    held = lambda t: (np.full_like(t, phi0), 0 * t, 0 * t)  # noqa: E731
    cp = HULL["C"].copy()
    cp[2, 2] -= HULL["m"] * HULL["g"] * HULL["pivot"][1]
    rhs = np.array([0.0, HULL["m"] * HULL["l"] * HULL["g"] * math.sin(phi0)])
    ref = np.linalg.solve(cp[1:, 1:], rhs)
    fd = harmonic_response(**HULL, wave_omega=W, amplitudes=[0.0], phi=held)
    assert np.max(np.abs(fd["Xi"][0, 1:] - ref)) < 1e-12 * np.max(np.abs(ref))
    td = replay(**HULL, wave_omega=W, amplitudes=[0.0], phi=held, periods=18,
                ramp_periods=6, steps_per_period=100)
    assert np.max(np.abs(td["Xi"][0, 1:] - ref)) < 1e-6 * np.max(np.abs(ref))
    assert abs(td["power"]) < 1e-9


def test_phi_fourier_is_the_specs_parametrization():
    x = np.array([0.2, 0.5, -0.1, 0.3, 0.05])  # N = 2
    phi = phi_fourier(x, 1, W)
    t = np.linspace(0.0, 6.0, 7)
    s = W * t
    p = s + 0.2 + 0.5 * np.sin(s) - 0.1 * np.sin(2 * s) + 0.3 * np.cos(s) + 0.05 * np.cos(2 * s)
    d1 = W * (1 + 0.5 * np.cos(s) - 0.2 * np.cos(2 * s) - 0.3 * np.sin(s) - 0.1 * np.sin(2 * s))
    d2 = W**2 * (-0.5 * np.sin(s) + 0.4 * np.sin(2 * s) - 0.3 * np.cos(s) - 0.2 * np.cos(2 * s))
    for got, ref in zip(phi(t), (p, d1, d2)):
        assert np.allclose(got, ref, rtol=0, atol=1e-13)


# ---------------------------------------------------------------- the replay

@pytest.mark.parametrize("name", list(CASES))
def test_replay_matches_the_frequency_domain(name):
    phi, amps = CASES[name]
    spp = 100
    fd, td, fm = _compare(phi, amps, spp)
    assert td["periodicity"] < 1e-6  # settled: the last two periods agree
    assert abs(td["surge_drift"]) < 1e-3 * np.max(np.abs(td["xi_dot"][:, 0]))
    _assert_agree(fd, td, fm)


def _halving(name):
    phi, amps = CASES[name]
    fd, t1, fm1 = _compare(phi, amps, 100)
    _, t2, fm2 = _compare(phi, amps, 200)
    # the integrator's own error (against the frequency domain of the model it integrates)
    # falls by 4 when dt is halved: second order
    e1 = np.max(np.abs(t1["Xi"][1:4] - fm1["Xi"][1:4]))
    e2 = np.max(np.abs(t2["Xi"][1:4] - fm2["Xi"][1:4]))
    assert 3.5 < e1 / e2 < 4.5
    # the power's leading dt^2 term can nearly cancel (rotate-0: 3e-5 of P at 100 steps, 25
    # times less than the other cases), leaving the dt^4 term visible: a ratio above 2.5
    p1, p2 = abs(t1["power"] - fm1["power"]), abs(t2["power"] - fm2["power"])
    assert 2.5 < p1 / p2 < 5.0
    # and Richardson's extrapolation leaves only the model's error (kernel truncation,
    # A_inf), plus O(dt^4)
    rich = (4 * t2["Xi"] - t1["Xi"]) / 3
    model = np.max(np.abs(fm2["Xi"][:4] - fd["Xi"][:4]))
    assert np.max(np.abs(rich[:4] - fd["Xi"][:4])) < 1.5 * model + 1e-6 * np.max(
        np.abs(fd["Xi"][1]))
    prich = (4 * t2["power"] - t1["power"]) / 3
    assert abs(prich - fd["power"]) < 1.5 * abs(fm2["power"] - fd["power"]) + 1e-6 * fd[
        "energy_scale"]


def test_halving_the_step_swinging():
    _halving("swing-1.6")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["swing-0.3", "rotate-0", "rotate-4.7-two-harmonics"])
def test_halving_the_step_slow(name):
    _halving(name)


def test_the_optimum_shaped_motion_from_coefficients():
    # the spec's phi coefficients (as an optimum would give them), K = 1, replayed
    x = np.array([0.4, 0.3, 0.0, 0.1, -0.05])
    phi = phi_fourier(x, 1, W)
    fd, td, fm = _compare(phi, [0.5], 100)
    _assert_agree(fd, td, fm)


@pytest.fixture(scope="module")
def box_barge():
    """A 10 x 4 x 1 m box barge from Capytaine (coarse mesh, lid against irregular
    frequencies), data to 3.6 rad/s (above, the mesh is too coarse and B loses its sign)."""
    cpt = pytest.importorskip("capytaine")
    cpt.set_logging("ERROR")
    rho, g, length, beam, draft, m = 1025.0, 9.81, 10.0, 4.0, 1.0, 4000.0
    mesh = cpt.mesh_parallelepiped(size=(length, beam, 2 * draft), center=(0, 0, 0),
                                   resolution=(20, 8, 4)).immersed_part()
    lid = cpt.mesh_rectangle(size=(length, beam), center=(0, 0, -0.02), normal=(0, 0, 1),
                             resolution=(20, 8))
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid, center_of_mass=(0, 0, 0),
                            dofs=cpt.rigid_body_dofs(rotation_center=(0, 0, 0)))
    body = body.with_only_dofs(["Surge", "Heave", "Pitch"])
    omega = np.linspace(0.2, 3.6, 18)
    pbs = [cpt.RadiationProblem(body=body, omega=w, radiating_dof=d)
           for w in omega for d in body.dofs]
    pbs += [cpt.DiffractionProblem(body=body, omega=w, wave_direction=0.0) for w in omega]
    ds = cpt.assemble_dataset(cpt.BEMSolver().solve_all(pbs, progress_bar=False))
    dofs = ["Surge", "Heave", "Pitch"]
    order = ("omega", "influenced_dof", "radiating_dof")
    a = ds["added_mass"].sel(radiating_dof=dofs, influenced_dof=dofs).transpose(*order).values
    b = ds["radiation_damping"].sel(radiating_dof=dofs, influenced_dof=dofs).transpose(
        *order).values
    f = np.conj(ds["excitation_force"].sel(influenced_dof=dofs, wave_direction=0.0).transpose(
        "omega", "influenced_dof").values)  # Capytaine's exp(-i w t) to exp(+i w t)
    vol = length * beam * draft
    # the box's hydrostatics in closed form, the whole floating mass at O (z_B = -draft / 2)
    c = np.diag([0.0, rho * g * length * beam,
                 rho * g * beam * length**3 / 12 - rho * g * vol * draft / 2])
    return {"omega_data": omega, "A": a, "B": b, "F": f, "C": c,
            "Mh": np.diag([rho * vol - m, rho * vol - m, rho * vol * (length**2 + draft**2) / 12]),
            "m": m, "l": 1.0, "I": 5000.0, "c": 50.0, "g": g, "pivot": (1.0, 1.5)}


@pytest.mark.slow
def test_replay_on_a_capytaine_box_barge(box_barge):
    # BEM data are causal only to the BEM's accuracy and cut off where B is still large: the
    # model's error is larger than the synthetic hull's (1e-3 here), and measured the same way
    w = 1.0
    for phi in (lambda t: (math.pi + 0.5 * np.sin(w * t + 1.6), 0.5 * w * np.cos(w * t + 1.6),
                           -0.5 * w * w * np.sin(w * t + 1.6)),
                phi_fourier([4.7, 0.3, 0.0], 1, w)):
        fd, t1, fm1 = _compare(phi, [0.5], 100, periods=40, ramp=10, hull=box_barge, w=w)
        assert abs(fd["energy_residual"]) < 1e-9 * fd["energy_scale"]
        assert t1["periodicity"] < 1e-5
        _assert_agree(fd, t1, fm1, hull=box_barge, w=w)
        _, t2, fm2 = _compare(phi, [0.5], 200, periods=40, ramp=10, hull=box_barge, w=w)
        e1 = np.max(np.abs(t1["Xi"][1:4] - fm1["Xi"][1:4]))
        e2 = np.max(np.abs(t2["Xi"][1:4] - fm2["Xi"][1:4]))
        assert 3.5 < e1 / e2 < 4.5
