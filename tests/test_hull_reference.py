"""The independent CasADi/IPOPT reference of the hull model (tests/hull_reference.py).

Checks of the reference itself, against what it did not compute: the Galerkin hull
equations re-read by the FFT, the energy balance of (P)+(H) (an invariant its optimization
does not impose), parapend's heave-only coupled optimum (surge and pitch made inert), and
the one-way limit ``m, I, c -> 0``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from buoy_synthetic import toy_hydro
from hull_reference import _Grid, box_case, hull_power, hull_reference, hull_state

from parapend.hydro.coupled import Pendulum, Wave
from parapend.hydro.optimum import coupled_optimum


def _random_x(n, k, seed):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(2 * n + 1) / np.concatenate(([1.0], np.tile(np.arange(1, n + 1),
                                                                            2) ** 2))
    x[0] += math.pi if k == 0 else 0.0
    return x


@pytest.mark.parametrize("winding", [0, 1])
def test_hull_solve_satisfies_the_galerkin_equations_by_fft(winding):
    """The NumPy hull solve, re-read by FFTs of r on the grid (not the projection
    matrices): Z_k Xi_k = Fa_k + R_k for k = 1..Nh, C' Xi_0 = R_0 on heave and pitch."""
    kw = box_case(winding=winding, harmonics=6, pivot=(1.5, 0.8))
    gr = _Grid(**kw)
    x = _random_x(6, winding, 3)
    Xi = gr.Xi(gr.solve_hull(x))
    w, mm, nh = gr.w, gr.M, gr.nh
    s = gr.s
    n = 6
    k = np.arange(1, n + 1)
    ph = winding * s + x[0] + np.sin(np.outer(s, k)) @ x[1:n + 1] + np.cos(np.outer(s, k)) @ x[
        n + 1:]
    d1 = w * (winding + np.cos(np.outer(s, k)) @ (k * x[1:n + 1])
              - np.sin(np.outer(s, k)) @ (k * x[n + 1:]))
    d2 = -w**2 * (np.sin(np.outer(s, k)) @ (k**2 * x[1:n + 1])
                  + np.cos(np.outer(s, k)) @ (k**2 * x[n + 1:]))
    kh = np.arange(1, nh + 1)
    e = np.exp(1j * np.outer(s, kh))
    xi2 = np.real(e @ (-(kh[:, None] * w) ** 2 * Xi[1:]))  # (M, 3)
    m, l_, dp, hp = kw["m"], kw["l"], *kw["pivot"]
    ssd = np.cos(ph) * d2 - np.sin(ph) * d1**2
    csd = -np.sin(ph) * d2 - np.cos(ph) * d1**2
    pz2 = xi2[:, 1] - dp * xi2[:, 2]
    px2 = xi2[:, 0] + hp * xi2[:, 2]
    r = np.stack([-m * l_ * ssd, -m * l_ * csd,
                  -m * l_ * (hp * ssd - dp * csd) - kw["I"] * d2
                  + m * l_ * kw["g"] * np.sin(ph)
                  + m * l_ * (pz2 * np.sin(ph) - px2 * np.cos(ph))], axis=1)
    R = np.fft.fft(r, axis=0) / mm
    Cp = np.array(kw["C"], dtype=float)
    Cp[2, 2] -= m * kw["g"] * hp
    G = np.array([[1, 0, hp], [0, 1, -dp]])
    scale = np.max(np.abs(R))
    for kk in range(1, nh + 1):
        Z = (-(kk * w) ** 2 * (kw["Mh"] + kw["A"][kk] + m * G.T @ G) + 1j * kk * w * kw["B"][kk]
             + Cp)
        fa = kw["F"][kk] * kw["amplitudes"][0] if kk == 1 else 0.0
        res = Z @ Xi[kk] - fa - 2 * R[kk]
        assert np.max(np.abs(res)) <= 1e-10 * scale
    assert Xi[0, 0] == 0.0
    res0 = Cp[1:, 1:] @ Xi[0, 1:].real - R[0, 1:].real
    assert np.max(np.abs(res0)) <= 1e-10 * scale


@pytest.mark.parametrize("winding", [0, 1, 2])
def test_energy_balance_holds_at_any_motion(winding):
    """At any phi (not only an optimum) with the hull from (H), the power and the hull's
    wave and radiation powers balance: the balance is not imposed by the solve."""
    kw = box_case(winding=winding, harmonics=8, pivot=(-1.0, 1.2))
    for seed in range(3):
        st = hull_state(_random_x(8, winding, seed), **kw)
        assert st["energy_balance_residual"] < 1e-9


@pytest.mark.parametrize("winding", [0, 1])
def test_reference_optimum_balances_and_stays_below_the_bound(winding):
    """Energy balance at the reference's optimum (< 1e-9 relative), its power re-evaluated
    by NumPy (hull solved again), positive and below the radiation bound; a start at the
    optimum converges to it at once."""
    kw = box_case(winding=winding, harmonics=8)
    r = hull_reference(**kw, starts=6)
    assert r["success"] and r["status"] == "Solve_Succeeded"
    assert r["energy_balance_residual"] < 1e-9
    assert abs(r["power_check"] - r["power"]) <= 1e-9 * r["power"]
    assert abs(hull_power(r["x"], **kw) - r["power"]) <= 1e-9 * r["power"]
    assert 0 < r["power"] < r["radiation_bound"]
    again = hull_reference(**kw, x0=r["x"])
    assert abs(again["power"] - r["power"]) <= 1e-9 * r["power"]
    assert all(p <= r["power"] * (1 + 1e-9) for p, st, _ in r["powers"]
               if st == "Solve_Succeeded")


def _heave_case(winding=1, height=1.5, nh=10, inert=1e12):
    hyd = toy_hydro()
    pen = Pendulum(500.0, 1.0, 600.0, 20.0)
    wave = Wave.regular(height, 6.0)
    w = wave.omega
    a, b, f = hyd.coefficients(w * np.arange(nh + 1))
    A = np.zeros((nh + 1, 3, 3))
    B = np.zeros_like(A)
    F = np.zeros((nh + 1, 3), dtype=complex)
    A[:, 1, 1], B[:, 1, 1], F[:, 1] = a, b, f
    # surge and pitch inert: huge mass, inertia and pitch stiffness, no coupling; the heave
    # mass of the hull without the pendulum is the buoy's displaced mass less m
    kw = dict(omega=w, amplitudes=wave.amplitudes, winding=winding, hull_harmonics=nh,
              points=256,
              A=A, B=B, F=F, C=np.diag([0.0, hyd.hydrostatic_stiffness, inert]),
              Mh=np.diag([inert, hyd.mass - pen.mass, inert]), m=pen.mass, l=pen.length,
              I=pen.inertia, c=pen.damping_coefficient, g=hyd.g, pivot=(0.0, 0.0))
    return hyd, pen, wave, kw


@pytest.mark.parametrize(("winding", "height"), [(1, 1.5), (2, 3.0)])
def test_heave_only_limit_equals_parapends_heave_optimum(winding, height):
    """Surge and pitch inert, pivot at O: the reference's optimum and its point value at
    parapend's heave-only coupled optimum both equal that optimum's power (1e-6). The
    toy dataset stops at 8 rad/s (B = 0 above: the heave kernel counts 7 harmonics of the
    coupling), below the 10 hull harmonics here; the heave kernel's theta is this phi
    (from the upward vertical, the same pendulum equation)."""
    hyd, pen, wave, kw = _heave_case(winding, height)
    sol = coupled_optimum(hyd, pen, wave, winding=winding, harmonics=2 * winding + 2)
    assert sol.success
    xk = np.asarray(sol.theta_coefficients["x"], dtype=float)
    n = (xk.size - 1) // 2
    assert abs(hull_power(xk, harmonics=n, **kw) - sol.power) <= 1e-6 * sol.power
    st = hull_state(xk, harmonics=n, **kw)
    top = min(kw["hull_harmonics"], sol.heave.size - 1)
    dz = st["Xi"][1:top + 1, 1] - sol.heave[1:top + 1]
    assert np.max(np.abs(dz)) <= 1e-6 * abs(sol.heave[1])
    r = hull_reference(harmonics=n, x0=np.zeros(2 * n + 1), **kw)
    assert r["success"]
    assert abs(r["power"] - sol.power) <= 1e-6 * sol.power


@pytest.mark.slow
@pytest.mark.parametrize(("winding", "height"), [(1, 1.5), (2, 3.0)])
def test_heave_only_limit_global_search(winding, height):
    """As above with the reference's own starts (at K = 2, H = 3 m they find a second
    maximum, 155 W; without the coefficient bounds most starts climb into aliasing, 1e8
    to 1e9 W 'optima' of the grid's power)."""
    hyd, pen, wave, kw = _heave_case(winding, height)
    sol = coupled_optimum(hyd, pen, wave, winding=winding, harmonics=2 * winding + 2)
    n = (len(sol.theta_coefficients["x"]) - 1) // 2
    r = hull_reference(harmonics=n, starts=8, **kw)
    assert r["success"] and r["starts_converged"] >= 4
    assert abs(r["power"] - sol.power) <= 1e-6 * sol.power


@pytest.mark.parametrize("winding", [0, 1])
def test_small_pendulum_tends_to_the_one_way_power(winding):
    """m, I, c scaled by 1e-6 together: the coupled optimum's power tends to the one-way
    optimum's (hull held at its free response); at full size they differ. The difference
    scales with the pendulum (here about 0.09 and 1.3e-7 at K = 0, 6.6e-3 and 7.3e-9 at
    K = 1)."""
    rel = []
    for scale in (1.0, 1e-6):
        kw = box_case(winding=winding, harmonics=8, m=2000.0 * scale, I=2500.0 * scale,
                      c=500.0 * scale)
        cp = hull_reference(**kw, starts=6)
        ow = hull_reference(**kw, starts=6, one_way=True)
        assert cp["success"] and ow["success"]
        rel.append(abs(cp["power"] - ow["power"]) / ow["power"])
    assert rel[1] < 1e-5
    assert rel[0] > 1e4 * rel[1]
