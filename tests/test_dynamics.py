"""Uncontrolled dynamics (paper Eq. 1, Figs. 1-2): integrators, attractors, basins, shooting.

Independent references: SciPy's DOP853 against the fixed-step RK4 map; the project model
(``parapend.model.rhs``) against Eq. 1's right-hand side; energy conservation (gamma = p = 0);
``expm`` for the monodromy of the linear unforced pendulum; Liouville's formula
``det M = exp(-gamma*T)``; the exact (phi, phi') -> (-phi, -phi') symmetry of Eq. 1.
"""

import json
import math

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import parapend.dynamics.attractors as attractors_mod
from parapend.dynamics import (
    basin_map,
    classify,
    continue_rotation,
    energy,
    fast_sin,
    find_attractors,
    floquet,
    grid,
    periodic_orbit,
    phi_to_theta,
    rhs,
    stroboscopic,
    theta_to_phi,
    trajectory,
)
from parapend.dynamics.figures import COEXISTENCE_CASE, plot_basins, plot_coexistence
from parapend.errors import ParameterError, SolverError
from parapend.excitation import fourier
from parapend.model import rhs as model_rhs

COEX = (0.1, 0.8, 2.1)      # paper Section 1: P2 oscillation coexists with P1 rotation
FIG2 = (0.1, 0.5, 1.8)      # paper Fig. 2 right (gamma = 0.1 assumed, see docs/dynamics.md)


# --- fast sine and conventions -------------------------------------------------------------
def test_fast_sin_matches_numpy_and_is_odd():
    rng = np.random.default_rng(0)
    x = np.concatenate((rng.uniform(-60, 60, 200_000), rng.uniform(-1e-3, 1e-3, 1000),
                        np.arange(-20, 21) * math.pi / 2, [0.0, -0.0, 1e-300]))
    s = fast_sin(x)
    # the reference is not numpy.sin, whose float64 loop depends on the processor (SIMD
    # dispatch, up to a few ulp on some): the extended-precision sine where long double has
    # it (x86-64 Linux), else the C library's, both within half an ulp here
    if np.finfo(np.longdouble).eps < 1e-18:
        ref = np.sin(x.astype(np.longdouble)).astype(float)
    else:
        ref = np.array([math.sin(v) for v in x])
    assert np.max(np.abs(s - ref)) < 4e-16   # measured 2.2e-16
    small = np.abs(x) < 1e-3
    assert np.all(np.abs(s[small] - ref[small]) <= np.spacing(np.abs(ref[small])))  # 1 ulp
    np.testing.assert_array_equal(fast_sin(-x), -s)   # bitwise odd: basis of the symmetry


def test_conventions_match_project_model():
    """Eq. 1 in phi is the project model in theta = phi + pi with q = p cos(omega t)."""
    gamma, p, omega = 0.13, 0.7, 1.9
    exc = fourier([(1, p, math.pi / 2)], omega)      # p sin(omega t + pi/2) = p cos(omega t)
    f_model = model_rhs(exc, gamma)
    f_eq1 = rhs(gamma, p, omega)
    rng = np.random.default_rng(1)
    for t, phi, dphi in rng.uniform(-4, 4, (20, 3)):
        direct = -gamma * dphi - (1 + p * math.cos(omega * t)) * math.sin(phi)   # Eq. 1
        np.testing.assert_allclose(f_eq1(t, [phi, dphi]), [dphi, direct], atol=1e-14)
        np.testing.assert_allclose(f_model(t, [phi + math.pi, dphi]), [dphi, direct],
                                   atol=1e-14)
    assert phi_to_theta(0.0) == pytest.approx(math.pi)
    assert theta_to_phi(math.pi) == pytest.approx(0.0)


# --- integrators ------------------------------------------------------------------------------
def test_rk4_map_matches_dop853_with_fourth_order_convergence():
    gamma, p, omega = COEX
    phi0 = np.array([0.5, 0.0, -2.0, 3.0])      # the last passes near the upright (sensitive)
    dphi0 = np.array([0.0, 2.5, 1.0, -1.5])
    period = 2 * math.pi / omega
    errs = {}
    for steps in (64, 128, 256):
        s = stroboscopic(phi0, dphi0, gamma, p, omega, 10, steps_per_period=steps)
        err = np.zeros(phi0.size)
        for i in range(phi0.size):
            ref = trajectory(phi0[i], dphi0[i], gamma, p, omega, 10 * period,
                           t_eval=s.t, rtol=1e-13, atol=1e-13)
            err[i] = max(np.max(np.abs(s.phi[:, i] - ref.phi)),
                         np.max(np.abs(s.dphi[:, i] - ref.dphi)))
        errs[steps] = err
    assert np.all(errs[256][:3] < 1e-8) and errs[256][3] < 1e-6
    regular = [0, 1, 3]     # (-2, 1) is pre-asymptotic at 64 steps (ratios 48 then 50)
    for a, b in ((64, 128), (128, 256)):
        ratio = errs[a][regular] / errs[b][regular]
        assert np.all((12 < ratio) & (ratio < 20))   # ~ 2**4: fourth order
    assert s.phi.shape == (11, 4) and s.t[-1] == pytest.approx(10 * period)


def test_stroboscopic_shapes_and_unwrapped_angle():
    gamma, p, omega = COEX
    s = stroboscopic(np.zeros((2, 3)), 2.5, gamma, p, omega, 40)
    assert s.phi.shape == (41, 2, 3) and s.dphi.shape == (41, 2, 3)
    np.testing.assert_array_equal(s.phi[0], 0.0)
    # the P1 rotation (+) reached from (0, 2.5): 40 periods later, about 40 turns (unwrapped)
    assert np.all(np.abs(s.turns[-1] - s.turns[-2] - 1) == 0)


def test_energy_conserved_without_damping_and_forcing():
    phi0, dphi0 = np.array([0.3, 2.0, -1.0]), np.array([0.0, 0.5, 2.5])   # swing, rotation
    s = stroboscopic(phi0, dphi0, 0.0, 0.0, 2.0, 50, steps_per_period=256)
    e = energy(s.phi, s.dphi)
    assert np.max(np.abs(e - e[0])) < 1e-8     # RK4 is not symplectic: slow drift
    tr = trajectory(2.0, 0.5, 0.0, 0.0, 2.0, 100.0, rtol=1e-12, atol=1e-12)
    e = energy(tr.phi, tr.dphi)
    assert np.max(np.abs(e - e[0])) < 1e-10 and tr.success


def test_damped_energy_decays_monotonically_without_forcing():
    tr = trajectory(2.5, 0.0, 0.2, 0.0, 1.0, 60.0)
    e = energy(tr.phi, tr.dphi)
    assert np.all(np.diff(e) <= 1e-12) and e[-1] < 1e-3 * e[0]


# --- classification ---------------------------------------------------------------------------
def _sequence(points, winding, periods, k):
    phi = np.array([points[m % k][0] + 2 * math.pi * winding * (m // k) for m in range(periods)])
    dphi = np.array([points[m % k][1] for m in range(periods)])
    return phi, dphi


def test_classify_synthetic_sequences():
    c = classify(*_sequence([(0.4, 0.1), (-0.4, -0.1)], 0, 20, 2))
    assert (c.name, c.kind, c.period, c.winding) == ("P2 oscillation", "oscillation", 2, 0)
    c = classify(*_sequence([(0.7, 2.6)], 1, 20, 1))
    assert (c.name, c.direction) == ("P1 rotation (+)", "anticlockwise")
    c = classify(*_sequence([(-0.7, -2.6)], -1, 20, 1))
    assert (c.name, c.direction) == ("P1 rotation (-)", "clockwise")
    c = classify(*_sequence([(0.5, 1.0), (1.5, 2.0)], 1, 20, 2))
    assert c.name == "P2 rotation (+) (1 turns/2 periods)" and c.winding == 1
    assert classify(*_sequence([(0.0, 0.0)], 0, 10, 1)).kind == "rest"
    rng = np.random.default_rng(2)
    assert classify(rng.uniform(-3, 3, 50), rng.uniform(-3, 3, 50)).name == "other"


def test_classify_focus_turning_by_third_of_a_turn_is_period_one():
    """A spiral with multiplier 0.3 exp(2 pi i/3) repeats at lag 3 long before lag 1."""
    lam = 0.3 * np.exp(2j * np.pi / 3)
    z = 1e-3 * lam ** np.arange(40)
    c = classify(1.0 + z.real, z.imag, tol=1e-9)
    assert c.period == 1 and c.kind == "oscillation"


# --- the paper's coexistence cases ------------------------------------------------------------
@pytest.mark.parametrize("name", ["P2 oscillation", "P1 rotation (+)", "P1 rotation (-)"])
def test_coexistence_initial_conditions_dop853(name):
    """Paper Section 1: each recorded initial condition reaches its attractor (DOP853)."""
    gamma, p, omega = COEX
    assert (COEXISTENCE_CASE["gamma"], COEXISTENCE_CASE["p"], COEXISTENCE_CASE["omega"]) == COEX
    phi0, dphi0 = COEXISTENCE_CASE["initial_conditions"][name]
    period = 2 * math.pi / omega
    tr = trajectory(phi0, dphi0, gamma, p, omega, 150 * period, t_eval=period * np.arange(151),
                  rtol=1e-11, atol=1e-11)
    assert classify(tr.phi, tr.dphi, tol=1e-6).name == name


@pytest.mark.slow  # several seconds; the default run stays within its budget
def test_coexistence_neighbourhoods_with_engine():
    """Every point of a 7 x 7 neighbourhood (half-width 0.03) of each recorded initial
    condition reaches the same attractor: the choices are not on basin boundaries."""
    gamma, p, omega = COEX
    d = np.linspace(-0.03, 0.03, 7)
    for name, (a, b) in COEXISTENCE_CASE["initial_conditions"].items():
        P, V = np.meshgrid(a + d, b + d)
        r = find_attractors(P, V, gamma, p, omega)
        assert {r.legend[int(c)] for c in np.unique(r.labels)} == {name}


@pytest.mark.slow
def test_fig2_case_attractors_and_stable_rotation():
    """Paper Fig. 2 right (p = 0.5, omega = 1.8; gamma = 0.1): a stable period-1 rotation
    (both directions) coexists with a period-2 oscillation; nothing else from 4000 random
    initial conditions (seeded) in [-pi, pi) x [-4, 4]."""
    gamma, p, omega = FIG2
    rng = np.random.default_rng(3)
    r = find_attractors(rng.uniform(-math.pi, math.pi, 4000), rng.uniform(-4, 4, 4000),
                        gamma, p, omega)
    assert [a.name for a in r.attractors] == ["P2 oscillation", "P1 rotation (+)",
                                              "P1 rotation (-)"]
    assert np.all(r.labels > 0)
    orbit = periodic_orbit(gamma, p, omega, winding=1)
    assert orbit.success and orbit.stable
    rot = r.attractors[1]
    assert rot.phi[0] == pytest.approx(orbit.phi0, abs=1e-5)
    assert rot.dphi[0] == pytest.approx(orbit.dphi0, abs=1e-5)


def test_fig2_basins_four_attractors_with_phases():
    """Counting the two phases of the period-2 oscillation separately (attractors of the
    2T map, as basin pictures at a fixed phase distinguish them) gives the paper's four."""
    ds = basin_map(*FIG2, n_phi=48, n_dphi=48, split_phases=True)
    names = list(ds["name"].values[1:])
    assert names == ["P2 oscillation [phase 0]", "P2 oscillation [phase 1]",
                     "P1 rotation (+)", "P1 rotation (-)"]
    frac = ds["basin_fraction"].values
    assert frac[0] == 0 and frac[1] == frac[2] and frac[3] == frac[4] and frac[3] > 0.03
    assert ds["poincare_phi"].values[2, 0] == pytest.approx(-ds["poincare_phi"].values[1, 0],
                                                            abs=1e-5)


# --- basins -----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def small_basin():
    return basin_map(*COEX, n_phi=40, n_dphi=40, symmetric=False, capture_radius=0.0,
                  pilot=False)


def test_basin_dataset_structure(small_basin):
    ds = small_basin
    assert ds["attractor"].dims == ("dphi", "phi") and ds["attractor"].shape == (40, 40)
    legend = json.loads(ds.attrs["legend"])
    assert legend["0"] == "other"
    assert set(legend.values()) == {"other", "P2 oscillation", "P1 rotation (+)",
                                    "P1 rotation (-)"}
    assert list(ds["name"].values) == [legend[str(c)] for c in ds["code"].values]
    assert ds["basin_fraction"].sum() == pytest.approx(1.0)
    phi, dphi = grid(40, 40)
    np.testing.assert_array_equal(ds["phi"].values, phi)
    assert phi[0] == -math.pi and phi[-1] < math.pi and dphi[0] == -3 and dphi[-1] == 3
    np.testing.assert_array_equal(dphi, -dphi[::-1])
    assert "phi from the hanging position" in ds.attrs["convention"]


def test_basin_symmetry_and_capture_do_not_change_labels(small_basin):
    """Mirror half + capture (the fast path) give exactly the labels of a full
    tol-converged run; the two rotations' basins are mirror images."""
    fast = basin_map(*COEX, n_phi=40, n_dphi=40)
    assert fast.attrs["symmetric_used"] == 1
    np.testing.assert_array_equal(fast["attractor"].values, small_basin["attractor"].values)
    lab = small_basin["attractor"].values
    plus, minus = (int(small_basin["code"][small_basin["name"] == n][0])
                   for n in ("P1 rotation (+)", "P1 rotation (-)"))
    mirror = lab[::-1, (40 - np.arange(40)) % 40]
    np.testing.assert_array_equal(lab == plus, mirror == minus)


def test_basins_netcdf_roundtrip(small_basin, tmp_path):
    path = tmp_path / "b.nc"
    small_basin.to_netcdf(path)
    with xr.open_dataset(path) as back:
        np.testing.assert_array_equal(back["attractor"].values, small_basin["attractor"].values)
        assert json.loads(back.attrs["legend"]) == json.loads(small_basin.attrs["legend"])


def test_threads_give_identical_results(monkeypatch):
    monkeypatch.setattr(attractors_mod, "_THREAD_MIN", 16)
    rng = np.random.default_rng(4)
    phi, dphi = rng.uniform(-3, 3, 300), rng.uniform(-3, 3, 300)
    one = find_attractors(phi, dphi, *COEX, workers=1)
    two = find_attractors(phi, dphi, *COEX, workers=2)
    np.testing.assert_array_equal(one.labels, two.labels)
    np.testing.assert_array_equal(one.periods_used, two.periods_used)


# --- shooting, Floquet, continuation ----------------------------------------------------------
@pytest.mark.parametrize("case", [COEX, FIG2])
def test_period_one_rotation_by_shooting(case):
    gamma, p, omega = case
    orb = periodic_orbit(gamma, p, omega, winding=1)
    assert orb.success and orb.status == "converged" and orb.residual < 1e-10
    period = 2 * math.pi / omega
    # independent check: DOP853 over one period advances phi by exactly 2 pi
    tr = trajectory(orb.phi0, orb.dphi0, gamma, p, omega, period, t_eval=[0.0, period],
                  rtol=1e-12, atol=1e-12)
    assert tr.phi[-1] - tr.phi[0] == pytest.approx(2 * math.pi, abs=1e-9)
    assert tr.dphi[-1] == pytest.approx(tr.dphi[0], abs=1e-9)
    # Liouville: product of the multipliers = det M = exp(-gamma T)
    assert np.prod(orb.multipliers).real == pytest.approx(math.exp(-gamma * period), abs=1e-9)
    assert orb.liouville_error < 1e-9
    assert orb.stable and np.max(np.abs(orb.multipliers)) < 1
    # the clockwise rotation is the mirror image
    mirror = periodic_orbit(gamma, p, omega, winding=-1)
    assert mirror.phi0 == pytest.approx(-orb.phi0, abs=1e-9)
    assert mirror.dphi0 == pytest.approx(-orb.dphi0, abs=1e-9)


@pytest.mark.slow
def test_period_two_oscillation_by_shooting_matches_engine():
    gamma, p, omega = COEX
    r = find_attractors(0.5, 0.0, gamma, p, omega)
    a = r.attractors[0]
    assert a.name == "P2 oscillation"
    orb = periodic_orbit(gamma, p, omega, phi0=a.phi[0], dphi0=a.dphi[0], period=2,
                         winding=0)
    assert orb.success and orb.stable
    assert orb.phi0 == pytest.approx(a.phi[0], abs=1e-5)
    assert orb.liouville_error < 1e-9


def test_monodromy_of_unforced_linear_pendulum_is_expm():
    """p = 0, hanging rest: the variational equations are x'' + gamma x' + x = 0."""
    gamma, omega = 0.3, 1.7
    mult, mono = floquet(0.0, 0.0, gamma, 0.0, omega)
    ref = expm(np.array([[0.0, 1.0], [-1.0, -gamma]]) * 2 * math.pi / omega)
    np.testing.assert_allclose(mono, ref, atol=1e-10)
    # the upright rest is a saddle: one multiplier outside the unit circle
    mult_up, _ = floquet(math.pi, 0.0, gamma, 0.0, omega)
    assert abs(mult_up[0]) > 1 > abs(mult_up[1])


def test_continuation_finds_fold_J_and_period_doubling_G():
    """At omega = 1.8 the stable rotation at p = 0.5 lies between its birth (fold, curve J)
    and its loss of stability (period doubling, curve G), as in paper Fig. 2 left."""
    gamma, _, omega = FIG2
    down = continue_rotation(gamma, omega, 0.5, direction=-1)
    assert down.status == "fold"
    (fold,) = [b for b in down.bifurcations if b.label == "J"]
    up = continue_rotation(gamma, omega, 0.5, direction=1, p_max=1.2)
    (pd,) = [b for b in up.bifurcations if b.label == "G"]
    assert 0.2 < fold.p < 0.5 < pd.p < 1.2
    mult, _ = floquet(fold.phi0, fold.dphi0, gamma, fold.p, omega)
    assert np.max(mult.real) == pytest.approx(1.0, abs=1e-4)
    mult, _ = floquet(pd.phi0, pd.dphi0, gamma, pd.p, omega)
    assert np.min(mult.real) == pytest.approx(-1.0, abs=1e-4)
    assert bool(up.data["stable"][0]) and not bool(up.data["stable"][-1])


# --- figures ----------------------------------------------------------------------------------
def test_figures(small_basin, tmp_path):
    from matplotlib.figure import Figure

    fig = plot_coexistence(path=tmp_path / "coex.png", periods=3)
    assert isinstance(fig, Figure) and (tmp_path / "coex.png").stat().st_size > 10_000
    fig = plot_basins(small_basin)
    assert isinstance(fig, Figure) and not list(tmp_path.glob("*basin*"))
    plot_basins(small_basin, path=tmp_path / "basins.svg")
    assert (tmp_path / "basins.svg").read_text().startswith("<?xml")


# --- argument errors --------------------------------------------------------------------------
def test_argument_errors():
    with pytest.raises(ParameterError, match="omega: expected a number > 0"):
        stroboscopic(0.0, 0.0, 0.1, 0.5, 0.0, 10)
    with pytest.raises(ParameterError, match="gamma: expected a number >= 0"):
        trajectory(0.0, 0.0, -0.1, 0.5, 1.8, 10.0)
    with pytest.raises(ParameterError, match="t_end: expected a time after t0"):
        trajectory(0.0, 0.0, 0.1, 0.5, 1.8, -1.0)
    with pytest.raises(ParameterError, match="steps_per_period: expected an integer >= 8"):
        stroboscopic(0.0, 0.0, 0.1, 0.5, 1.8, 10, steps_per_period=4)
    with pytest.raises(ParameterError, match="finite initial conditions"):
        find_attractors(np.nan, 0.0, 0.1, 0.5, 1.8)
    with pytest.raises(ParameterError, match="capture_radius: expected 0 or a radius above"):
        find_attractors(0.0, 0.0, 0.1, 0.5, 1.8, capture_radius=1e-5)
    with pytest.raises(ParameterError, match="dphi_range: expected low < high"):
        basin_map(0.1, 0.5, 1.8, n_phi=4, n_dphi=4, dphi_range=(3, -3))
    with pytest.raises(ParameterError, match="an initial guess is needed for an oscillation"):
        periodic_orbit(0.1, 0.5, 1.8, winding=0)
    with pytest.raises(ParameterError, match="equal length"):
        classify(np.zeros(5), np.zeros(4))
    with pytest.raises(SolverError, match="shooting"):
        periodic_orbit(0.1, 0.5, 1.8, phi0=0.0, dphi0=0.0, winding=1, maxiter=1, throw=True)


# --- slow: full-size runs ---------------------------------------------------------------------
@pytest.mark.slow
def test_full_grid_200x200_labels_agree_with_dop853_sample():
    """200 x 200 grid, 300-period budget; 60 seeded grid points re-classified by DOP853
    (all 60 in one system, tests/dop853_labels.py: 0.6 s of CPU against 37 s one by one,
    with the same 60 labels)."""
    from dop853_labels import dop853_labels

    gamma, p, omega = COEX
    ds = basin_map(gamma, p, omega)
    assert ds["attractor"].shape == (200, 200)
    rng = np.random.default_rng(5)
    idx = rng.integers(0, 200, (60, 2))
    ref = dop853_labels(ds["phi"].values[idx[:, 1]], ds["dphi"].values[idx[:, 0]], gamma, p,
                        omega, periods=300)
    mine = [str(ds["name"].values[int(ds["attractor"][j, i])]) for j, i in idx]
    agree = sum(str(a) == b for a, b in zip(ref, mine))
    assert agree >= 57      # points on fractal basin boundaries may differ


@pytest.mark.slow
def test_rotation_boundaries_ordering():
    from parapend.dynamics import rotation_boundaries

    ds = rotation_boundaries(0.1, [1.6, 1.8, 2.0], p_max=3.0)
    pj, pg = ds["p_J"].values, ds["p_G"].values
    assert np.all(np.isfinite(pj)) and np.all(pj < pg)


def test_solve_ivp_is_the_reference_used():
    """``trajectory`` is DOP853 at the given tolerances (same numbers as a direct call)."""
    gamma, p, omega = FIG2
    tr = trajectory(0.3, 0.2, gamma, p, omega, 5.0, t_eval=[5.0], rtol=1e-10, atol=1e-10)
    ref = solve_ivp(rhs(gamma, p, omega), (0, 5.0), [0.3, 0.2], method="DOP853",
                    t_eval=[5.0], rtol=1e-10, atol=1e-10)
    assert tr.phi[-1] == ref.y[0, -1] and tr.dphi[-1] == ref.y[1, -1]
