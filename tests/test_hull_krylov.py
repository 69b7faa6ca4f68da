"""The hull's matrix-free solver (parapend.hydro._hull_krylov) against the dense one
(parapend.hydro.hull.HullProblem, a second implementation of the same discretization: its
matrices formed, S inverted by Woodbury's identity): the same state, power, gradient and
Hessian, the same optima; and a record's optimum the same number from the command line, the
API and a power-matrix bin."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from hull_synthetic import case

import parapend
from parapend.cli import main
from parapend.hydro import hull as hull_mod
from parapend.hydro._hull_krylov import KrylovHullProblem, coarsened, gmres
from parapend.hydro.hull import GTOL, HullProblem, hull_search, ideal_problem
from parapend.optimal.fourier import newton_maximize


def _x(n, winding, seed):
    x = 0.3 * np.random.default_rng(seed).standard_normal(2 * n + 1)
    x[0] += math.pi if winding == 0 else 0.0
    return x


def _record(harmonics=24, winding=2, waves=3, seed=1):
    """The synthetic hull in a record-like wave: ``waves`` harmonics of random phase."""
    rng = np.random.default_rng(seed)
    amps = 0.3 * np.exp(2j * math.pi * rng.random(waves)) / np.arange(1, waves + 1)
    return case(winding=winding, harmonics=harmonics, omega=2 * math.pi / 12,
                amplitudes=amps)


@pytest.mark.parametrize("winding", [0, 1, 2])
@pytest.mark.parametrize("coupled", [False, True])
def test_state_power_gradient_hessian_are_the_dense_ones(winding, coupled):
    """At a random motion: the hull's unknowns and the power to 1e-11 (rounding of the
    torque's cancellation in ``<tau v>``), the gradient to 1e-10, the Hessian's columns
    (operator products; the sensitivities solved to 1e-8) to 1e-6, of their size."""
    cs = case(winding=winding, harmonics=8)
    d, k = HullProblem(cs, coupled=coupled), KrylovHullProblem(cs, coupled=coupled)
    x = _x(cs.harmonics, winding, 7 + winding)
    pd, gd, hd = d.evaluate(x)
    pk, gk, op = k.evaluate(x)
    yd, yk = d.solve_hull(x), k.solve_hull(x)
    assert np.max(np.abs(yk - yd)) <= 1e-11 * np.max(np.abs(yd))
    assert pk == pytest.approx(pd, rel=1e-11)
    assert np.max(np.abs(gk - gd)) <= 1e-10 * np.max(np.abs(gd))
    hk = np.column_stack([op.matvec(e) for e in np.eye(x.size)])
    assert np.max(np.abs(hk - hd)) <= 1e-6 * np.max(np.abs(hd))
    np.testing.assert_allclose(k.harmonics_of(yk), d.harmonics_of(yd), rtol=0,
                               atol=1e-11 * np.max(np.abs(yd)))
    if not coupled:  # L_xx alone: the preconditioner's diagonal is -H's exactly
        np.testing.assert_allclose(op.diagonal, -np.diag(hd), rtol=0,
                                   atol=1e-10 * np.max(np.abs(hd)))


def test_energy_balance_is_the_dense_check():
    cs = _record()
    x = _x(cs.harmonics, cs.winding, 3) * 0.1
    d, k = HullProblem(cs).balance(x), KrylovHullProblem(cs).balance(x)
    assert d[0] == pytest.approx(k[0], rel=1e-11)
    assert d[1] == pytest.approx(k[1], rel=1e-11)
    assert d[2] == pytest.approx(k[2], rel=1e-6, abs=1e-13)


@pytest.mark.parametrize("winding", [0, 2])
def test_newton_reaches_the_dense_maximum(winding):
    """Newton's operator path (truncated CG on the matrix-free Hessian) from the dense
    optimum's neighbourhood climbs to the dense optimum: power to 1e-10, motion to 1e-6."""
    cs = _record(winding=winding)
    dense = HullProblem(cs)
    starts = hull_mod._starts(cs.harmonics, winding)
    best = max((newton_maximize(dense, x0, n, gtol=GTOL) for n, x0 in starts[:4]),
               key=lambda r: r.power if r.status == "converged" else -math.inf)
    assert best.status == "converged"
    x0 = best.x + 1e-3 * np.random.default_rng(0).standard_normal(best.x.size)
    r = newton_maximize(KrylovHullProblem(cs), x0, "near", gtol=GTOL)
    assert r.status == "converged"
    assert r.power == pytest.approx(best.power, rel=1e-10)
    assert np.max(np.abs(r.x - best.x)) <= 1e-6


def test_the_search_answers_are_maxima_of_both_solvers(monkeypatch):
    """The whole search (every start, one-way and coupled, no refinement) on a record, once
    dense and once with every problem matrix-free: each answer is a maximum of the other
    solver too (its Newton, started there, stays at the same power to 1e-10), the best of
    the two is the better of both searches' maxima, and both balance the energy. (The
    two searches can end on different maxima: their steps differ away from one.)"""
    cs = _record(harmonics=24, winding=2)
    dense = hull_search(lambda s: cs, refine=False)
    monkeypatch.setattr(hull_mod, "KRYLOV_HARMONICS", 0)
    assert isinstance(ideal_problem(cs), KrylovHullProblem)
    krylov = hull_search(lambda s: cs, refine=False)
    assert dense.success and krylov.success
    for sol, other in ((dense, KrylovHullProblem(cs)), (krylov, HullProblem(cs))):
        r = newton_maximize(other, sol.x, "again", gtol=GTOL)
        assert r.status == "converged"
        assert r.power == pytest.approx(sol.power, rel=1e-10)
        assert sol.energy_balance_residual <= 1e-9
    assert max(krylov.maxima_powers) == pytest.approx(krylov.power, rel=1e-12)
    assert krylov.one_way_power == pytest.approx(dense.one_way_power, rel=1e-8)


def test_continued_search_reaches_the_direct_one(monkeypatch):
    """The continuation (the starts on half the harmonics, then Newton from the padded
    answer) ends at the maximum the direct search finds on the full harmonics."""
    cs = _record(harmonics=32, winding=2)
    direct = hull_search(lambda s: cs, refine=False)
    monkeypatch.setattr(hull_mod, "LONG_RECORD_HARMONICS", 30)
    cont = hull_search(lambda s: cs, refine=False)
    assert "continued from 16 harmonics" in cont.found_by
    assert cont.success and cont.case.harmonics == 32
    assert cont.power == pytest.approx(direct.power, rel=1e-8)


def test_continuation_stops_on_phis_harmonics(monkeypatch):
    """A rotation of more turns than the continuation's threshold (the hull's harmonics
    N + K never fall below it) is continued down to fewer harmonics of phi than the
    threshold, then climbs back: 24 from 12 from 6."""
    cs = _record(harmonics=24, winding=12)
    monkeypatch.setattr(hull_mod, "LONG_RECORD_HARMONICS", 10)
    sol = hull_search(lambda s: cs, refine=False)
    assert sol.case.harmonics == 24
    assert "continued from 12 harmonics" in sol.found_by
    assert "continued from 6 harmonics" in sol.found_by
    assert math.isfinite(sol.power)


def test_a_screen_sees_each_level_and_stops_the_continuation_where_it_says(monkeypatch):
    """A long record's continuation (24 harmonics from 12 from 6) keeps each level's power;
    a screen is shown each level above the coarsest search and the answer before its
    refinement. One that keeps them all changes nothing (bit for bit); one that drops the
    12-harmonic level ends the climb there, unrefined."""
    monkeypatch.setattr(hull_mod, "LONG_RECORD_HARMONICS", 10)

    def make(scale):
        return _record(harmonics=24 * scale, winding=2)
    plain = hull_search(make)
    assert plain.success and [n for n, _ in plain.level_history] == [6, 12]
    assert plain.refinement_history[0][0] == 24 and not plain.screened
    seen = []
    kept = hull_search(make, screen=lambda s: seen.append((s.case.harmonics, s.power)) or True)
    assert kept.power == plain.power and kept.refinement_history == plain.refinement_history
    assert kept.level_history == plain.level_history
    assert seen == [plain.level_history[1], plain.refinement_history[0]]
    dropped = hull_search(make, screen=lambda s: s.case.harmonics != 12)
    assert dropped.screened and dropped.case.harmonics == 12
    assert dropped.power == plain.level_history[1][1] and dropped.refinement_history == ()
    assert dropped.level_history == plain.level_history[:1]


@pytest.mark.parametrize("restart", [40, 3])
def test_gmres_is_the_dense_solution(restart):
    """The state's GMRES (right-preconditioned by an approximate inverse) against LAPACK's
    solve of the same nonsymmetric system: to its tolerance, from zero and from a start,
    through restarts (``restart=3``: the true residual recomputed between cycles); a zero
    right side is zero without a product; too few cycles say so."""
    rng = np.random.default_rng(4)
    n = 60
    a = np.diag(np.linspace(1.0, 30.0, n)) + 0.4 * rng.standard_normal((n, n))
    pre = np.diag(1.0 / np.diag(a))
    b = rng.standard_normal(n)
    exact = np.linalg.solve(a, b)
    products = []

    def apply_a(v):
        products.append(1)
        return a @ v

    for x0 in (None, exact + 1e-3 * rng.standard_normal(n)):
        x, ok, its = gmres(apply_a, lambda v: pre @ v, b, rtol=1e-12, x0=x0,
                           restart=restart)
        assert ok and its > 0
        assert np.linalg.norm(a @ x - b) <= 1e-11 * np.linalg.norm(b)
        assert np.allclose(x, exact, rtol=0, atol=1e-9 * np.abs(exact).max())
    products.clear()
    x, ok, its = gmres(apply_a, lambda v: pre @ v, np.zeros(n), rtol=1e-12)
    assert ok and its == 0 and not products and not x.any()
    x, ok, its = gmres(apply_a, lambda v: pre @ v, b, rtol=1e-12, restart=2, max_restarts=2)
    assert not ok and its == 4
    # NaN in the right side or from the operator: NaN at once, not the cycles' budget
    x, ok, its = gmres(apply_a, lambda v: pre @ v, np.full(n, np.nan), rtol=1e-12)
    assert not ok and its == 0 and np.isnan(x).all()
    x, ok, its = gmres(lambda v: np.full(n, np.nan), lambda v: v, b, rtol=1e-12)
    assert not ok and its == 1 and np.isnan(x).all()


def test_coarsened_case_is_the_case_with_fewer_harmonics():
    """:func:`coarsened` keeps the data at the harmonics it keeps: its hull matrix blocks are
    the full case's first ones."""
    cs = _record(harmonics=24, winding=2)
    co = coarsened(cs, 12)
    assert (co.harmonics, co.hull_harmonics) == (12, 14)
    for kk in range(1, 15):
        np.testing.assert_array_equal(co.impedance(kk), cs.impedance(kk))
    np.testing.assert_array_equal(co.wave_force(), cs.wave_force()[:15])
    assert co.points == 2 * hull_mod.hull_points(12, 14, 2, 3)


def test_aliased_motion_has_no_power():
    """A motion whose coupled state breaks the energy balance (the grid's products alias)
    is no candidate: its power is NaN, so a line search steps back from it."""
    cs = case(winding=1, harmonics=8)
    k = KrylovHullProblem(cs)
    x = _x(cs.harmonics, 1, 1) * 40.0
    _, _, resid = HullProblem(cs).balance(x)
    assert resid > 1e-4
    assert math.isnan(k.power(x))


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    from hull_timedomain import synthetic_hull_netcdf

    return synthetic_hull_netcdf(tmp_path_factory.mktemp("hull") / "hull.nc")


PEND = {"mass": 4000.0, "length": 1.0, "inertia": 5000.0, "damping_coefficient": 50.0,
        "pivot_height": 1.5, "pivot_offset": 1.0}


def _same_record_three_ways(hydro_opts, capsys, waves, tp, extra=()):
    """The record's optimum from the API, the command line and a power-matrix bin."""
    from parapend.performance import power_matrix
    from parapend.performance.resource import repeat_period

    api = parapend.buoy(dofs="surge,heave,pitch", hs=1.0, tp=tp,
                        repeat_period=repeat_period(waves, tp), seed=0, **hydro_opts)
    assert api.success
    flags = [x for k, v in hydro_opts.items() for x in (f"--{k.replace('_', '-')}", str(v))]
    assert main(["buoy", "--dofs", "surge,heave,pitch", "--hs", "1", "--tp", repr(tp),
                 "--repeat-period", repr(repeat_period(waves, tp)), "--seed", "0",
                 "--json", *flags, *extra]) == 0
    cli = json.loads(capsys.readouterr().out)
    # the smallest matrix (two bins a side): its first bin is the record
    ds, _, _, _ = power_matrix(device="buoy", dofs="surge,heave,pitch", hs="1,1.01",
                               tp=f"{tp!r},{tp + 0.01!r}",
                               waves=waves, seed=0, realizations=1, workers=1, time_limit=3600,
                               **hydro_opts)
    return api, cli["power_w"], float(ds["power"].values[0, 0, 0])


@pytest.mark.slow
def test_record_optimum_is_one_number_from_cli_api_and_power_matrix(dataset, capsys):
    """A record (2 peak periods, the synthetic hull; its search dense, its refinement
    matrix-free) is the same number from ``parapend.buoy``, ``parapend buoy`` and a
    ``power-matrix`` bin of the same record and seed, to 1e-9."""
    api, cli, pm = _same_record_three_ways({"hydro": dataset, **PEND}, capsys, 2.0, 6.0)
    assert api.harmonics >= hull_mod.KRYLOV_HARMONICS  # its refinement matrix-free
    assert cli == pytest.approx(api.power_w, rel=1e-9)
    assert pm == pytest.approx(api.power_w, rel=1e-9)


@pytest.mark.slow
def test_default_sea_is_one_number_from_cli_api_and_power_matrix(capsys):
    """The embedded barge's default sea (Hs 1 m, Tp 6 s, 4 peak periods, seed 0): the API,
    the command line and a power-matrix bin agree to 1e-9."""
    api, cli, pm = _same_record_three_ways({}, capsys, 4.0, 6.0)
    assert cli == pytest.approx(api.power_w, rel=1e-9)
    assert pm == pytest.approx(api.power_w, rel=1e-9)


@pytest.mark.slow
def test_barge_ten_wave_record_matrix_free_is_the_dense_answer():
    """The embedded barge's 10-wave record (144 harmonics): Newton on the matrix-free
    problem from near the dense solver's maximum reaches it to 1e-8 (same harmonics)."""
    from parapend.hydro.api import hull_problem
    from parapend.hydro.coupled import Wave
    from parapend.hydro.hull import make_case, waves_in

    p = hull_problem(dofs="surge,heave,pitch")
    wave = Wave.from_spectrum(hs=1.5, tp=6.0, repeat_period=60.0, seed=0)
    cs = make_case(p["hull"], p["pendulum"], wave, winding=waves_in(wave), pivot=p["pivot"])
    one = KrylovHullProblem(cs, coupled=False)
    x1 = newton_maximize(one, hull_mod._starts(cs.harmonics, cs.winding)[0][1], "s",
                         gtol=GTOL).x
    k = newton_maximize(KrylovHullProblem(cs), x1, "k", gtol=GTOL)
    assert k.status == "converged"
    d = newton_maximize(HullProblem(cs), k.x + 1e-4 * np.sin(np.arange(k.x.size)), "d",
                        gtol=GTOL)
    assert d.status == "converged"
    assert k.power == pytest.approx(d.power, rel=1e-8)
    assert dataclasses.is_dataclass(cs)


def test_optimality_checks_agree_between_solvers():
    """At a maximum: the gradient vanishes (below GTOL m g l w, or at its rounding floor,
    1e-7 of it: Newton's own rule where no step raises the power; on one processor's BLAS
    the best of the four converged starts stopped at 3.7 GTOL) and the Hessian is negative
    definite. The operator's scaled eigenvalue (Lanczos on ``D^-1/2 H D^-1/2``, ``D`` its
    diagonal estimate) equals LAPACK's on the same scaled matrix built column by column
    from the operator's products (to Lanczos's tolerance), and its sign is that of the
    dense Hessian's largest eigenvalue (Sylvester's law of inertia)."""
    from parapend.hydro._hull_krylov import LANCZOS_TOL, _scaled, optimality

    cs = _record(winding=0)
    d = HullProblem(cs)
    r = max((newton_maximize(d, x0, n, gtol=GTOL) for n, x0 in
             hull_mod._starts(cs.harmonics, 0)[:4]), key=lambda r: r.power)
    gd, td, sd = optimality(d, r.x)
    kp = KrylovHullProblem(cs)
    gk, tk, sk = optimality(kp, r.x)
    scale = float(d.w[0])
    assert gd <= 1e-7 * scale and gk <= 1e-7 * scale
    assert td < 0 and sd < 0 and tk is None and sk is not None and sk < 0
    _, _, h = kp.evaluate(r.x)
    s = _scaled(h.diagonal)
    cols = np.column_stack([s * h.matvec(s * e) for e in np.eye(r.x.size)])
    top = float(np.linalg.eigvalsh(0.5 * (cols + cols.T))[-1])
    assert sk == pytest.approx(top, rel=10 * LANCZOS_TOL)


@pytest.mark.parametrize("power", [1, 2, 3])
def test_lanczos_finds_a_crowded_top_of_the_spectrum(power):
    """The second-order check's Lanczos on a spectrum crowded at its top, as the scaled
    Hessian of a long rotation's record is (-0.0146 over a span of 1.5, 5617 unknowns: the
    100-wave record's size): it converges within its budget to the known largest eigenvalue
    (a diagonal operator), to its tolerance."""
    from scipy.sparse.linalg import LinearOperator

    from parapend.hydro._hull_krylov import LANCZOS_TOL, largest_eigenvalue

    n = 5617
    lam = -(0.0146 + 1.5 * (np.arange(n) / n) ** power)
    rng = np.random.default_rng(power)
    lam = lam[rng.permutation(n)]
    op = LinearOperator((n, n), matvec=lambda v: lam * np.ravel(v), dtype=float)
    top = largest_eigenvalue(op)
    assert top is not None and top == pytest.approx(-0.0146, rel=LANCZOS_TOL)


@pytest.mark.parametrize("pto", [{}, pytest.param({"efficiency": "0.9,0.85"},
                                                   marks=pytest.mark.slow)])
def test_each_mode_carries_its_optimality(dataset, pto):
    """A hull answer's modes carry the gradient's largest entry and the Hessian's largest
    eigenvalue at their maxima (negative: strict maxima); the gradient below Newton's
    stopping rule at rounding (1e-7 of m g l w). With an efficiency they are the smoothed
    objective's at the width of the answer's climb, which the mode states; there they say
    what the climb left (this wave's swinging answer at 48 harmonics: the dense trust region
    stopped short of the smallest width's maximum, its gradient 6.2e3 W/rad, its Hessian's
    largest eigenvalue positive; the rotation's 2.5e-3 and negative): checked against
    independent computations in tests/test_hull_pto.py."""
    r = parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, wave_height=1.0,
                      wave_period=2 * math.pi / 1.2, **PEND, **pto)
    for m in r.modes[:-1]:
        assert (m["optimality_smoothing_width_w"] is None) == (not pto)
        if pto:
            assert m["optimality_smoothing_width_w"] > 0
            assert math.isfinite(m["gradient_max_w_per_rad"])
            assert math.isfinite(m["hessian_largest_eigenvalue_w_per_rad2"])
            continue
        assert m["gradient_max_w_per_rad"] <= 1e-7 * PEND["mass"] * 9.81 * 1.2
        assert m["hessian_largest_eigenvalue_w_per_rad2"] < 0
        assert m["hessian_scaled_largest_eigenvalue"] < 0


def test_records_past_what_fits_are_refused_in_one_line(dataset):
    """An ideal take-off's record is refused past ``HULL_MAX_RECORD_HARMONICS`` (about 300
    waves), a real take-off's past ``HULL_MAX_PTO_RECORD_HARMONICS`` (about 30), before any
    solve; a 20-wave record is no longer refused, with a take-off or without."""
    from parapend import limits
    from parapend.errors import ParameterError
    from parapend.hydro.api import _check_hull_size, hull_problem
    from parapend.hydro.coupled import Wave
    from parapend.hydro.hull import HullPTO, waves_in

    with pytest.raises(ParameterError, match=r"^repeat-period: .*matrix-free") as err:
        parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, hs=1.0, tp=6.0,
                      repeat_period=6.0 * 320, **PEND)
    assert "\n" not in str(err.value)
    wave = Wave.from_spectrum(hs=1.0, tp=6.0, repeat_period=6.0 * 20, seed=0)
    k = waves_in(wave)
    _check_hull_size(wave, (k, 0), None)  # no refusal
    assert 12 * k > limits.HULL_MAX_HARMONICS
    _check_hull_size(wave, (k, 0), None, HullPTO(torque_limit=1e4))  # nor with a limit
    long = Wave.from_spectrum(hs=1.0, tp=6.0, repeat_period=6.0 * 60, seed=0)
    assert 12 * waves_in(long) > limits.HULL_MAX_PTO_RECORD_HARMONICS
    with pytest.raises(ParameterError, match=r"^repeat-period: .*with a power take-off"):
        _check_hull_size(long, (waves_in(long), 0), None, HullPTO(torque_limit=1e4))
    p = hull_problem(dofs="surge,heave,pitch", hydro=dataset, **PEND)
    assert p.get("max_harmonics") is None


@pytest.mark.slow
def test_an_ideal_record_refines_past_the_dense_cap():
    """A barge 10 x 6 x 2 m with a 4 t pendulum at 1.5 m, the pivot 1 m up, Hs 2.5 m, Te 9 s
    (a site's bin, cutoff 2.2): its 4-wave record still moved by 7 W (2e-3) when refined to
    192 harmonics, the dense refinement's cap, and the power matrix left the bin out; an ideal
    take-off's refinement goes on matrix-free and resolves it; the harmonics the user may
    ask for follow the same cap."""
    from parapend import limits
    from parapend.errors import ParameterError

    tp = 9 / 0.903296
    kw = dict(dofs="surge,heave,pitch", body="barge", barge_length=10, barge_beam=6,
              barge_draft=2, mass=4000, length=1.5, pivot_height=1, hs=2.5, tp=tp,
              repeat_period=4 * tp, cutoff=2.2, seed=0)
    r = parapend.buoy(**kw)
    assert r.success and r.harmonics > limits.HULL_MAX_REFINED_HARMONICS
    assert r.discretization_error_estimate_w < 1e-6 * r.power_w
    with pytest.raises(ParameterError, match="^harmonics:"):
        parapend.buoy(**kw, harmonics=limits.HULL_MAX_RECORD_HARMONICS + 1)


@pytest.mark.parametrize("kw", [{"eta": (0.9, 0.8)}, {"copper_loss": 1e-3},
                                {"eta": (0.9, 0.8), "copper_loss": 1e-3}])
def test_a_take_offs_objective_is_the_dense_ones(kw):
    """An efficiency (its kink smoothed), a copper loss and a torque limit's penalty: the
    matrix-free problem's value, gradient and Hessian are the dense problem's (the same
    pointwise terms through the operator's products), and so is the unsmoothed power."""
    cs = case(winding=1, harmonics=8)
    x = _x(cs.harmonics, 1, 7)
    d, k = HullProblem(cs, **kw), KrylovHullProblem(cs, **kw)
    lim = 0.5 * float(np.max(np.abs(d.state(x)["tau"])))
    for p in (d, k):
        p.width = 0.01
        p.set_limit(lim, 1e-6)
    pd, gd, hd = d.evaluate(x)
    pk, gk, op = k.evaluate(x)
    assert pk == pytest.approx(pd, rel=1e-11)
    assert np.max(np.abs(gk - gd)) <= 1e-10 * np.max(np.abs(gd))
    hk = np.column_stack([op.matvec(e) for e in np.eye(x.size)])
    assert np.max(np.abs(hk - hd)) <= 1e-6 * np.max(np.abs(hd))
    assert k.exact(x) == pytest.approx(d.exact(x), rel=1e-11)


@pytest.mark.parametrize("eta,share", [(None, 0.6), ((0.9, 0.85), None),
                                       ((0.9, 0.85), 0.6)])
def test_a_take_offs_matrix_free_optimum_is_the_dense_ones(eta, share):
    """A torque limit (``share`` of the ideal optimum's peak torque), an efficiency (one
    smoothing width), and both, on a record: the matrix-free driver (Newton with truncated
    conjugate gradients, the limit's inexact augmented Lagrangian) and the dense one
    (trust-exact, :func:`parapend.hydro.pto.maximize`), from the ideal optimum, end on the
    same maximum: its exact power to 1e-8 (under the limit, which each holds to
    ``LIMIT_TOL`` of it, to that: the power moves with the grid's torques at the limit's
    order), the limit held on the grid to ``LIMIT_TOL``."""
    from parapend.hydro._hull_krylov import pto_maximize
    from parapend.hydro.pto import LIMIT_TOL, maximize

    cs = _record(harmonics=24, winding=0)
    ideal = hull_search(lambda s: cs, refine=False)
    assert ideal.success
    tau = np.max(np.abs(HullProblem(cs).grid_state(ideal.x)["tau"]))
    limit = None if share is None else share * float(tau)
    widths = (1.0,) if eta is None else (1e-2,)
    out = []
    for prob, climb in ((HullProblem(cs, eta=eta), maximize),
                        (KrylovHullProblem(cs, eta=eta), pto_maximize)):
        x, ex, runs = climb(prob, ideal.x, widths, limit)
        assert runs[-1][2] == "converged", runs
        if limit is not None:
            over = np.max(np.abs(prob.grid_state(x)["tau"])) - limit
            assert over <= LIMIT_TOL * limit
        out.append(ex)
    assert out[1] == pytest.approx(out[0], rel=1e-8 if limit is None else LIMIT_TOL)
    if limit is not None:  # the limit binds: the power is below the ideal's
        assert out[0] < ideal.power * (1 - 1e-6)


@pytest.mark.slow
def test_barge_ten_wave_record_under_a_limit_matrix_free_is_the_dense_answer():
    """The embedded barge's 10-wave record (144 harmonics, swinging) under a torque limit of
    60 kN m (about two thirds of the ideal optimum's peak torque): the matrix-free driver
    from the ideal optimum (the limit's inexact augmented Lagrangian on Newton with truncated
    conjugate gradients) ends where the dense one (trust-exact), started there, stays: the
    same exact power to 1e-8, both within the limit on the grid."""
    from parapend.hydro._hull_krylov import pto_maximize
    from parapend.hydro.api import hull_problem
    from parapend.hydro.coupled import Wave
    from parapend.hydro.hull import make_case
    from parapend.hydro.pto import LIMIT_TOL, maximize

    p = hull_problem(dofs="surge,heave,pitch")
    wave = Wave.from_spectrum(hs=1.5, tp=6.0, repeat_period=60.0, seed=0)
    cs = make_case(p["hull"], p["pendulum"], wave, winding=0, pivot=p["pivot"])
    assert cs.harmonics == 144
    ideal = hull_search(lambda s: cs, refine=False)
    limit = 6e4
    assert np.max(np.abs(HullProblem(cs).grid_state(ideal.x)["tau"])) > 1.5 * limit
    k = KrylovHullProblem(cs)
    xk, exk, runs = pto_maximize(k, ideal.x, (1.0,), limit)
    assert runs[-1][2] == "converged"
    xd, exd, runs = maximize(HullProblem(cs), xk, (1.0,), limit)
    assert runs[-1][2] == "converged"
    assert exk == pytest.approx(exd, rel=1e-8)
    for x in (xk, xd):
        assert np.max(np.abs(HullProblem(cs).grid_state(x)["tau"])) <= limit * (1 + LIMIT_TOL)
    assert exk < ideal.power


def test_a_matrix_free_least_torque_start_takes_few_newton_steps(monkeypatch):
    """The least-torque motion only starts a take-off's search: matrix-free it is climbed by
    at most ``FREE_MAX_NEWTON`` Newton steps (unbounded, the barge's 10-wave rotations ran
    200 steps, 9 to 13 s each, without converging), and its motion is finite and closer to
    the least torque than the start's."""
    from parapend.hydro import hull
    from parapend.optimal import fourier

    calls = []
    real = fourier.newton_maximize

    def spy(*args, **kw):
        r = real(*args, **kw)
        calls.append((kw.get("maxiter"), r.iterations))
        return r

    monkeypatch.setattr(hull, "newton_maximize", spy)
    monkeypatch.setattr(hull, "KRYLOV_HARMONICS", 4)
    cs = case(winding=1, harmonics=12)
    out = hull._free_motion(cs, 1)
    assert out and calls
    assert all(cap == hull.FREE_MAX_NEWTON and its <= cap for cap, its in calls)
    pr = hull._lossy_problem(cs, copper_loss=1.0)
    pr.a = 0.0
    assert isinstance(pr, KrylovHullProblem)
    for (_name, x), (_, x0) in zip(out, hull._starts(12, 1)[::2]):
        assert np.all(np.isfinite(x))
        assert pr.exact(x) > pr.exact(x0)


@pytest.mark.parametrize("kw,first", [({"eta": (0.9, 0.85)}, "KINK_KRYLOV_HARMONICS"),
                                      ({"copper_loss": 1e-3}, "KRYLOV_HARMONICS"),
                                      ({"eta": (1.0, 1.0)}, "KRYLOV_HARMONICS")])
def test_an_efficiencys_problem_stays_dense_below_its_own_threshold(monkeypatch, kw, first):
    """A take-off's problem is matrix-free from ``KRYLOV_HARMONICS`` on, an efficiency's
    (its kink, whose curvature makes the conjugate gradients' steps dear) only from
    ``KINK_KRYLOV_HARMONICS``: the two thresholds set apart here, each side of each."""
    from parapend import limits
    from parapend.hydro import hull

    # an efficiency's record (refused past HULL_MAX_HARMONICS) and its refinement (to
    # HULL_MAX_REFINED_HARMONICS) are dense throughout
    assert hull.KINK_KRYLOV_HARMONICS > limits.HULL_MAX_REFINED_HARMONICS
    monkeypatch.setattr(hull, "KRYLOV_HARMONICS", 8)
    monkeypatch.setattr(hull, "KINK_KRYLOV_HARMONICS", 16)
    at = getattr(hull, first)
    for n, free in ((at - 4, False), (at, True), (at + 4, True)):
        pr = hull._lossy_problem(case(winding=1, harmonics=n), **kw)
        assert isinstance(pr, KrylovHullProblem) == free, (n, kw)


@pytest.mark.slow
def test_barge_ten_wave_record_with_an_efficiency_matrix_free_is_the_dense_answer():
    """The embedded barge's 10-wave record (144 harmonics, swinging) with the efficiency
    0.9, 0.85: the matrix-free continuation from the ideal optimum down to 1e-6 of the
    largest ``|p|`` (Newton with truncated conjugate gradients, preconditioned by the kink's
    low-rank part at the last width) ends on a maximum that the dense driver (trust-exact,
    the same width) climbs back to from the answer perturbed (by 1e-5 rad per coefficient:
    its power about 1e-4 lower): the same exact power to 1e-8; and that power is the exact
    electrical mean power of the motion's mechanical power
    (:func:`parapend.hydro.pto.electrical_power`, the kink integrated, no smoothing).

    Newton's own status there is "converged" or "stalled" at the rounding of the power:
    at 1e-6 of ``|p|`` the kink's curvature shrinks the conjugate gradients' step until its
    predicted increase is 1e-17 of the power (no line search can measure it) while the
    gradient is still 2e-7 to 9e-7 of the excitation scale, above or below Newton's 1e-7
    as the path's rounding falls (starts moved by 1e-14, another machine's kernels): both
    are accepted with the gradient 1e-5 of that scale (four orders below where the width's
    climb starts), and the dense driver's climb back is what shows the maximum. One BLAS
    thread, as every record solve runs (:func:`parapend.hydro.result.hull_answer`)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1, user_api="blas"):
        _efficiency_record_is_the_dense_answer()


def _efficiency_record_is_the_dense_answer():
    from parapend.hydro._hull_krylov import pto_maximize
    from parapend.hydro.api import hull_problem
    from parapend.hydro.coupled import Wave
    from parapend.hydro.hull import make_case
    from parapend.hydro.pto import WIDTHS, electrical_power, maximize

    eta = (0.9, 0.85)
    p = hull_problem(dofs="surge,heave,pitch")
    wave = Wave.from_spectrum(hs=1.5, tp=6.0, repeat_period=60.0, seed=0)
    cs = make_case(p["hull"], p["pendulum"], wave, winding=0, pivot=p["pivot"])
    assert cs.harmonics == 144
    ideal = hull_search(lambda s: cs, refine=False)
    k = KrylovHullProblem(cs, eta=eta)
    p0 = float(np.max(np.abs(k.state(ideal.x)["p"])))
    x1, _, _ = pto_maximize(k, ideal.x, WIDTHS[:WIDTHS.index(1e-5) + 1])
    k.width = 1e-6 * p0
    r = newton_maximize(k, x1, "width", gtol=GTOL, maxiter=200, saddle=False)
    assert r.status in ("converged", "stalled")
    assert r.gradient_norm <= 1e-5 * float(np.max(np.abs(k.w)))
    assert k.evaluate(r.x)[2].low_rank() is not None  # the kink's preconditioner in use
    d = HullProblem(cs, eta=eta)
    xs = r.x + 1e-5 * np.sin(np.arange(r.x.size))
    exk = k.exact(r.x)
    assert d.exact(xs) < exk * (1 - 1e-5)
    pd = float(np.max(np.abs(d.state(xs)["p"])))
    xd, _, runs = maximize(d, xs, (k.width / pd,))
    assert runs[-1][1] == pytest.approx(exk, rel=1e-8)  # where the dense climb ended
    assert np.max(np.abs(xd - r.x)) < 1e-6
    assert exk == pytest.approx(electrical_power(d.state(r.x)["p"], eta)[0], rel=1e-12)
    assert exk < ideal.power


def test_a_screened_start_goes_on_as_its_whole_continuation():
    """A matrix-free efficiency's search screens its starts down to ``WIDTHS[PTO_SCREEN -
    1]`` and continues only the best over the last widths, relative to the screening's
    ``|p|`` scale (here the start's own; :func:`parapend.hydro.hull._finish_screened`),
    from the screened iterate's exact power: the same widths, climbs and stop as the whole
    continuation from that start, so the same answer (the exact power to 1e-6). Its
    screened status is its last climb's, and the problem reports the objective of the
    climb that gave the answer (its width one of the last ones)."""
    from parapend.hydro.hull import PTO_SCREEN, HullPTO, _finish_screened, _pto_maximize
    from parapend.hydro.pto import WIDTHS

    cs = _record(harmonics=24, winding=0)
    ideal = hull_search(lambda s: cs, refine=False)
    pto = HullPTO(efficiency=(0.9, 0.85))
    k = KrylovHullProblem(cs, eta=pto.efficiency)
    whole = _pto_maximize(k, ideal.x, pto, True)
    p0 = float(np.max(np.abs(k.state(ideal.x)["p"])))
    xs, exs, status, _ = _pto_maximize(k, ideal.x, pto, True, WIDTHS[:PTO_SCREEN], scale=p0)
    assert status == "converged"
    x, ex, _, _ = _finish_screened(k, pto, xs, p0, WIDTHS[PTO_SCREEN:], start=exs)
    assert ex == pytest.approx(whole[1], rel=1e-6)
    assert any(k.answer[0] == pytest.approx(w * p0) for w in WIDTHS[PTO_SCREEN:]) or \
        ex == exs


def test_an_efficiencys_continuation_stops_once_settled():
    """A matrix-free efficiency's continuation stops at the first width at or below
    ``settle`` whose exact power has settled from the width before (moved by at most
    ``PTO_SETTLED`` of the power scale, or fell): the widths it climbed are the whole
    continuation's (the same exact powers to 1e-9: from there the same climbs, to GTOL),
    the power it keeps is the largest of them and none of the widths it left out has more
    than ``PTO_SETTLED`` of the scale more; the stop is where the independent rule (the
    whole continuation's exact powers, compared pairwise) puts it."""
    from parapend.hydro._hull_krylov import LEVEL_GTOL, pto_maximize
    from parapend.hydro.hull import PTO_SETTLE_WIDTH, PTO_SETTLED
    from parapend.hydro.pto import WIDTHS

    cs = _record(harmonics=24, winding=0)
    ideal = hull_search(lambda s: cs, refine=False)
    eta = (0.9, 0.85)
    k = KrylovHullProblem(cs, eta=eta)
    p0 = float(np.max(np.abs(k.state(ideal.x)["p"])))
    settle = PTO_SETTLE_WIDTH * p0
    # the whole continuation, climbed here width by width (the path's widths to LEVEL_GTOL,
    # those at or below ``settle`` to GTOL)
    whole, xw = [], ideal.x
    for rel in WIDTHS:
        k.width = rel * p0
        r = newton_maximize(k, xw, "width", maxiter=200, saddle=False,
                            gtol=GTOL if k.width <= settle else LEVEL_GTOL)
        xw = r.x
        whole.append((k.width, k.exact(xw)))
    x, ex, runs = pto_maximize(KrylovHullProblem(cs, eta=eta), ideal.x, WIDTHS,
                               settle=settle)
    size = float(k.w[0])
    exs = [r[1] for r in whole]
    stop = next(i for i in range(1, len(exs)) if WIDTHS[i] * p0 <= settle and (
        exs[i] < exs[i - 1] or abs(exs[i] - exs[i - 1]) <= PTO_SETTLED * size))
    assert len(runs) == stop + 1 < len(whole)
    for a, b in zip(runs, whole):
        assert a[0] == b[0] and a[1] == pytest.approx(b[1], rel=1e-9, abs=1e-9 * size)
    assert ex == max(r[1] for r in runs)
    assert max(exs) <= ex + PTO_SETTLED * size
    assert KrylovHullProblem(cs, eta=eta).exact(x) == pytest.approx(ex, rel=1e-12)


def test_a_refinement_starts_at_its_answers_width():
    """A matrix-free efficiency's refinement (a finer level, a held limit) starts its
    continuation at the smoothing width of the answer it refines (``WIDTHS_WARM``, relative
    to it) and stops once settled: fewer climbs than ``WIDTHS_REFINE``'s four, to a
    maximum that the dense driver (trust-exact) at the same width, from the answer
    perturbed, climbs back to (the exact power to 1e-8); its status "converged" says
    the kept power is within ``PTO_SETTLED`` of a neighbouring width's."""
    from parapend.hydro.hull import HullPTO, _pto_maximize
    from parapend.hydro.pto import maximize
    from parapend.optimal.fourier import _pad

    cs = _record(harmonics=24, winding=0)
    pto = HullPTO(efficiency=(0.9, 0.85))
    sol = hull_search(lambda s: cs, refine=False, pto=pto)
    fine = _record(harmonics=48, winding=0)
    k = KrylovHullProblem(fine, eta=pto.efficiency)
    x0 = _pad(sol.x, 48)
    x, ex, status, _ = _pto_maximize(k, x0, pto, False, width=sol.pto_state[0])
    assert status == "converged"
    width = k.answer[0]
    assert any(width == pytest.approx(f * sol.pto_state[0]) for f in hull_mod.WIDTHS_WARM)
    d = HullProblem(fine, eta=pto.efficiency)
    xs = x + 1e-5 * np.sin(np.arange(x.size))
    assert d.exact(xs) < ex - 1e-9 * abs(ex)
    pd = float(np.max(np.abs(d.state(xs)["p"])))
    _, exd, runs = maximize(d, xs, (width / pd,))
    assert runs[-1][1] == pytest.approx(ex, rel=1e-8)
