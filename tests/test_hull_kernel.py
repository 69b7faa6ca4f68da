"""The hull kernel (parapend.hydro.hull): its exact derivatives against finite differences,
the energy balance at its optima, the one-way limit, the heave-only reduction."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hull_synthetic import case

from parapend.hydro._hull_kernel import (
    fused_gram,
    grid_motion,
    hull_inverse,
    hull_solve,
    lift,
    phi_gradient,
    pivot_adjoint,
    pivot_grid,
    project,
    spectra_at,
)
from parapend.hydro._trig import spectra
from parapend.hydro.hull import GTOL, HullProblem, hull_search, radiation_bound
from parapend.optimal.fourier import newton_maximize


def _x(n, winding, seed):
    x = 0.3 * np.random.default_rng(seed).standard_normal(2 * n + 1)
    x[0] += math.pi if winding == 0 else 0.0
    return x


@pytest.mark.parametrize("winding", [0, 1, 2])
@pytest.mark.parametrize("coupled", [False, True])
def test_gradient_and_hessian_are_the_derivatives(winding, coupled):
    """Central differences of P (step 1e-5: truncation ~1e-10, rounding ~1e-11 relative)
    agree with the exact gradient and Hessian to 1e-6 of their size."""
    cs = case(winding=winding, harmonics=5)
    pr = HullProblem(cs, coupled=coupled)
    x = _x(cs.harmonics, winding, winding)
    _, g, h = pr.evaluate(x)
    eps = 1e-5
    eye = np.eye(x.size)
    gfd = np.array([(pr.power(x + eps * e) - pr.power(x - eps * e)) / (2 * eps) for e in eye])
    hfd = np.array([(pr.evaluate(x + eps * e)[1] - pr.evaluate(x - eps * e)[1]) / (2 * eps)
                    for e in eye])
    assert np.max(np.abs(g - gfd)) <= 1e-6 * np.max(np.abs(g))
    assert np.max(np.abs(h - hfd)) <= 1e-6 * np.max(np.abs(h))
    assert np.allclose(h, h.T, rtol=0, atol=1e-12 * np.max(np.abs(h)))


def test_hull_equations_hold_at_the_solved_motion():
    """The solved hull harmonics satisfy (H) harmonic by harmonic, rebuilt here from the
    grid's torque and pivot acceleration (not from the kernel's matrices)."""
    cs = case(winding=1, harmonics=6)
    pr = HullProblem(cs)
    x = _x(cs.harmonics, 1, 3)
    st = pr.grid_state(x)
    xi = pr.harmonics_of(st["y"])
    ml, hp, dp = cs.m * cs.l, cs.pivot[1], cs.pivot[0]
    f, f1, f2 = st["phi"], st["phi1"], st["phi2"]
    sin2 = np.cos(f) * f2 - np.sin(f) * f1**2
    cos2 = -np.sin(f) * f2 - np.cos(f) * f1**2
    # the pivot force on the pendulum without m p'' (moved into Z) and the reaction torque
    fx, fz = ml * sin2, ml * cos2
    torque = -st["tau"] + cs.c * st["relative_speed"]
    r = np.array([-fx, -fz, -(hp * fx - dp * fz) + torque])
    fa = cs.wave_force()
    for k in range(1, cs.hull_harmonics + 1):
        rk = 2 * np.mean(r * np.exp(-1j * k * pr.s), axis=1)
        # Z_k without the pendulum's lumped mass, and the m p'' it moves
        lhs = cs.impedance(k) @ xi[k]
        assert np.allclose(lhs, fa[k] + rk, rtol=0, atol=1e-9 * np.max(np.abs(fa[1])))
    assert xi[0, 0] == 0.0  # the mean surge


def _hull_matrix(pr, x):
    """The hull matrix ``S`` at ``x`` formed densely (``Z`` plus the gathered pitch rows) and
    the kernel's arguments for it."""
    cs = pr.case
    _, _, _, _, wz, _, _ = grid_motion(x, pr._geo, pr.s, float(pr.winding), cs.m * cs.l,
                                       cs.I, cs.g)
    gm = fused_gram(spectra(wz).ravel(), *pr._hull_gram.arrays())
    return pr.Z + gm, np.ascontiguousarray(gm[pr._prow])


@pytest.mark.parametrize("winding", [0, 1])
def test_woodbury_inverse_is_the_inverse(winding):
    """``hull_inverse`` (Woodbury on the pitch rows, ``Z`` inverted block by block) equals
    LAPACK's inverse of the dense hull matrix to rounding, the moving rows really being the
    pitch rows only; a wrong ``Z^{-1}`` is caught by ``hull_solve``'s backward-error check,
    which then inverts ``S`` directly."""
    cs = case(winding=winding, harmonics=6)
    pr = HullProblem(cs)
    x = _x(cs.harmonics, winding, 7)
    s, gp = _hull_matrix(pr, x)
    # the hull matrix's spectra by direct sums at the frequencies it reads = the FFT's there
    wz = grid_motion(x, pr._geo, pr.s, float(pr.winding), cs.m * cs.l, cs.I, cs.g)[4]
    assert np.allclose(fused_gram(spectra_at(wz, pr._hull_freqs, pr._hull_cos, pr._hull_sin),
                                  *pr._hull_gram.arrays()),
                       fused_gram(spectra(wz).ravel(), *pr._hull_gram.arrays()),
                       rtol=0, atol=1e-12 * np.max(np.abs(gp)))
    moving = np.flatnonzero(np.any(s != pr.Z, axis=1))
    assert set(moving) <= set(pr._prow) and len(moving) > 0
    direct = np.linalg.inv(s)
    wood = hull_inverse(gp, pr._Zinv, pr._Zp, pr._prow, pr._blocks)
    assert np.max(np.abs(wood - direct)) <= 1e-11 * np.max(np.abs(direct))
    st, sinv = pr._at(x)
    assert np.max(np.abs(sinv - direct)) <= 1e-11 * np.max(np.abs(direct))
    # the check: a Z^{-1} off by 1 % gives a y whose residual is far above rounding
    ml = cs.m * cs.l
    f, f1, f2, r, wz, sn, co = grid_motion(x, pr._geo, pr.s, float(pr.winding), ml, cs.I,
                                           cs.g)
    bad = pr._Zinv * 1.01
    out = hull_solve(spectra(wz).ravel(), *pr._hull_gram.arrays(), pr.Z, bad,
                     np.ascontiguousarray(bad[:, pr._prow]), pr._prow, pr._blocks, pr.fa_real,
                     r, pr._geo, sn, co, f1, f2, cs.I, cs.c, ml, cs.g)
    assert np.max(np.abs(out[0] - direct)) <= 1e-11 * np.max(np.abs(direct))
    assert np.max(np.abs(out[1] - st["y"])) <= 1e-11 * np.max(np.abs(st["y"]))


@pytest.mark.parametrize("winding", [0, 1])
def test_energy_balance_at_the_optimum(winding):
    cs = case(winding=winding, harmonics=12)
    sol = hull_search(lambda s: dataclasses.replace(
        case(winding=winding, harmonics=12 * s, hull_harmonics=(12 + max(1, winding)) * s)))
    assert sol.success, sol.status
    assert sol.energy_balance_residual < 1e-9
    assert sol.refinement_change <= 1e-7 * abs(sol.power)
    assert sol.power > 0
    bound, _ = radiation_bound(sol.case)
    assert 0 < sol.power <= bound
    assert cs.harmonics == 12


def test_light_pendulum_tends_to_the_one_way_answer():
    """m, I, c -> 0 together: the pendulum's reaction vanishes, the coupled power over
    m g l tends to the one-way power over m g l (difference O(m))."""
    gaps = []
    for scale in (1e-2, 1e-4):
        cs = case(winding=1, harmonics=8, m=2000.0 * scale, c=50.0 * scale)
        one = HullProblem(cs, coupled=False)
        r1 = newton_maximize(one, np.zeros(17), "0", gtol=GTOL)
        co = HullProblem(cs)
        r2 = newton_maximize(co, r1.x, "1", gtol=GTOL)
        gaps.append(abs(r2.power - r1.power) / abs(r1.power))
    assert gaps[1] < 1e-3 and gaps[1] < 0.05 * gaps[0]


def test_heave_only_hull_equals_the_heave_kernel():
    """With surge and pitch locked out (no coupling in A, B, F, C, inert in M) and the pivot
    at O, the hull problem is the heaving buoy: its optimum equals
    parapend.hydro.optimum.coupled_optimum's on the same heave data."""
    import hull_synthetic as hs

    from parapend.hydro.bem import Hydro
    from parapend.hydro.coupled import Pendulum, Wave
    from parapend.hydro.optimum import coupled_optimum

    w0 = 2 * math.pi / 5
    n, nh = 16, 18
    cs = case(winding=1, harmonics=n, hull_harmonics=nh, pivot=(0.0, 0.0), c=50.0)
    a, b, f = cs.A.copy(), cs.B.copy(), cs.F.copy()
    for arr in (a, b):
        arr[:, 0, :] = arr[:, :, 0] = arr[:, 2, :] = arr[:, :, 2] = 0.0
    f[:, 0] = f[:, 2] = 0.0
    big = 1e12
    cs = dataclasses.replace(cs, A=a, B=b, F=f, C=np.diag([0.0, hs.stiffness()[1, 1], big]),
                             Mh=np.diag([big, hs.MASS - cs.m, big]))
    pr = HullProblem(cs)
    one = HullProblem(cs, coupled=False)
    r0 = newton_maximize(one, np.zeros(2 * n + 1), "0", gtol=GTOL)
    r = newton_maximize(pr, r0.x, "1", gtol=GTOL)
    wg = w0 * np.arange(1, nh + 1)  # the harmonics themselves: no interpolation
    aa, bb, ff = hs.coefficients(wg)
    hyd = Hydro(omega=wg, added_mass=aa[:, 1, 1], radiation_damping=bb[:, 1, 1],
                excitation=ff[:, 1], hydrostatic_stiffness=hs.stiffness()[1, 1], mass=hs.MASS)
    ref = coupled_optimum(hyd, Pendulum(cs.m, cs.l, cs.I, cs.c), Wave.regular(1.0, 5.0),
                          winding=1, harmonics=n)
    assert ref.success
    # measured 3e-10: the locked DOFs' 1e12 mass and stiffness leave a 1e-10 coupling
    assert r.power == pytest.approx(ref.power, rel=1e-8)


def _dense_maps(pr):
    """The kernel's maps as dense matrices, built here from the discretization's definition
    (tests/hull_reference.py's): ``x -> (phi - K s, phi', phi'')``, ``y -> (p_x'', p_z'',
    beta')`` and the projection ``Pi`` of the hull's equations."""
    cs, m, n, nh = pr.case, pr.points, pr.harmonics, pr.case.hull_harmonics
    w, s = pr.omega, pr.s
    kn, kh = np.arange(1, n + 1), np.arange(1, nh + 1)
    sn, cn = np.sin(np.outer(s, kn)), np.cos(np.outer(s, kn))
    p012 = np.vstack((np.hstack((np.ones((m, 1)), sn, cn)),
                      w * np.hstack((np.zeros((m, 1)), kn * cn, -kn * sn)),
                      -w**2 * np.hstack((np.zeros((m, 1)), kn**2 * sn, kn**2 * cn))))
    j0, ny = len(pr.static), pr.ny
    ch, sh = np.cos(np.outer(s, kh)), np.sin(np.outer(s, kh))
    e1, e2, pi = np.zeros((3, m, ny)), np.zeros((3, m, ny)), np.zeros((3, ny, m))
    for i, d in enumerate(pr.static):
        pi[d, i, :] = 1.0 / m
    for d in range(3):
        re = j0 + 6 * (kh - 1) + d
        im = re + 3
        e1[d][:, re], e1[d][:, im] = -w * kh * sh, -w * kh * ch
        e2[d][:, re], e2[d][:, im] = -(w * kh) ** 2 * ch, (w * kh) ** 2 * sh
        pi[d][re, :], pi[d][im, :] = (2.0 / m) * ch.T, -(2.0 / m) * sh.T
    dp, hp = cs.pivot
    q3 = np.vstack((e2[0] + hp * e2[2], e2[1] - dp * e2[2], e1[2]))
    return p012, q3, np.concatenate(list(pi), axis=1)


@pytest.mark.parametrize("winding", [0, 1])
def test_trigonometric_maps_are_the_dense_maps(winding):
    """The kernel's sums over the cos/sin tables (``grid_motion``, ``phi_gradient``,
    ``pivot_grid``, ``pivot_adjoint``, ``project``, ``lift``) equal the dense matrices of
    the discretization and their transposes, to rounding."""
    cs = case(winding=winding, harmonics=7)
    pr = HullProblem(cs)
    p012, q3, pi = _dense_maps(pr)
    m, rng = pr.points, np.random.default_rng(winding)

    def close(got, ref):
        return np.allclose(got, ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))

    x = _x(cs.harmonics, winding, 11)
    f, f1, f2 = grid_motion(x, pr._geo, pr.s, float(pr.winding), cs.m * cs.l, cs.I, cs.g)[:3]
    assert close(np.concatenate((f - winding * pr.s, f1 - pr.omega * winding, f2)), p012 @ x)
    d1 = rng.standard_normal((6, m))
    assert close(phi_gradient(d1, pr._geo), p012.T @ d1[:3].ravel())
    y = rng.standard_normal(pr.ny)
    assert close(np.concatenate(pivot_grid(y, pr._geo, m)), q3 @ y)
    assert close(pivot_adjoint(d1, pr._geo, pr.ny), q3.T @ d1[3:].ravel())
    r, b0 = rng.standard_normal((3, m)), rng.standard_normal(pr.ny)
    assert close(project(r, pr._geo, b0), b0 + pi @ r.ravel())
    assert close(lift(y, pr._geo, m), (pi.T @ y).reshape(3, m))
