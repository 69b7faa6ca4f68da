"""Globality: the optimum against brute force, its evidence, resolutions checked.

The brute force here shares only the objective with the search under test: it starts a
plain Newton run (no pruning) from every half-turn direction pattern and from many seeded
random coefficient vectors, and polishes the best with SciPy's BFGS; the winner's power is
re-evaluated by the independent quadrature of :func:`parapend.power.mean_power`.
"""

import math

import numpy as np
import pytest
from scipy.optimize import minimize

import parapend
from parapend.model import torque
from parapend.optimal import fourier as fourier_mod
from parapend.optimal.fourier import FourierProblem, newton_maximize, search_fourier
from parapend.optimal.limit import all_patterns, limit, limit_seed, pattern_count
from parapend.power import mean_power
from parapend.trajectory import FourierMotion


def random_excitation(rng, max_harmonic=6):
    """A seeded random Fourier excitation: 1 to 6 harmonics, amplitudes up to 0.5."""
    nh = int(rng.integers(1, max_harmonic + 1))
    ks = np.sort(rng.choice(np.arange(1, max_harmonic + 1), nh, replace=False))
    terms = [(int(k), float(rng.uniform(0.02, 0.5) * rng.choice([-1, 1])),
              float(rng.uniform(0, 2 * np.pi))) for k in ks]
    return parapend.fourier(terms, omega=float(rng.uniform(1, 3)))


def brute_force(exc, harmonics, gamma, starts, seed=0):
    """Best local maximum over every pattern and ``starts`` random starts (no pruning)."""
    rng = np.random.default_rng(seed)
    prob = FourierProblem(exc, harmonics, gamma)
    lim = limit(exc)
    runs = [newton_maximize(prob, limit_seed(lim, harmonics, d).vector, "pattern")
            for d in all_patterns(lim)]
    k = np.concatenate((np.arange(1, harmonics + 1),) * 2)
    for _ in range(starts):
        x = np.empty(2 * harmonics + 1)
        x[0] = rng.uniform(0, 2 * np.pi)
        x[1:] = rng.normal(0, 1, 2 * harmonics) * rng.uniform(0, 2) / k ** rng.uniform(0.5, 1.5)
        runs.append(newton_maximize(prob, x, "random"))
    best = max((r for r in runs if r.status == "converged"), key=lambda r: r.power)

    def neg(x):
        p, g, _ = prob.evaluate(x)
        return -p, -g

    bfgs = minimize(neg, best.x, jac=True, method="BFGS", options={"gtol": 1e-12})
    return max(best.power, -bfgs.fun), best.x


def _check_case(exc, gamma, starts, harmonics=24):
    ref, xref = brute_force(exc, harmonics, gamma, starts)
    r = parapend.optimize(excitation=exc, gamma=gamma, harmonics=harmonics)
    assert r.success
    assert r.power >= ref - 1e-8, (exc.describe(), gamma, ref - r.power)
    # the reported power is the motion's, by an independent quadrature
    assert mean_power(r.motion, exc, gamma, points=8192) == pytest.approx(r.power, abs=1e-11)
    assert r.power <= r.upper_bound + 1e-12 and r.bound_gap >= -1e-12
    return r


# cases with 6 to 12 extrema per period, where a capped set of 8 patterns missed the optimum
FAST_CASES = [
    ([(2, 0.3, 0.4), (3, -0.25, 1.1), (5, 0.1, 2.0)], 1.7),
    ([(1, 0.2, 0.0), (3, 0.15, 0.4), (5, 0.06, 0.0)], 1.8),
    ([(1, -0.35, 0.3), (4, 0.2, 2.5), (6, 0.08, 1.0)], 2.3),
    ([(3, -0.163, 1.75), (4, 0.145, 1.33), (6, -0.258, 1.55)], 2.68),
]


@pytest.mark.parametrize("terms,omega", FAST_CASES)
@pytest.mark.parametrize("gamma", [0.0, 0.01, 0.05])
@pytest.mark.slow
def test_optimum_is_the_best_known_on_many_extrema(terms, omega, gamma):
    exc = parapend.fourier(terms, omega=omega)
    assert exc.extrema.t.size >= 6
    r = _check_case(exc, gamma, starts=20)
    assert r.search == "exhaustive"
    assert r.candidate_patterns == pattern_count(limit(exc)) >= 15
    assert r.patterns_tried == r.candidate_patterns


def test_evidence_in_the_json_of_every_result(capsys):
    import json

    from parapend.cli import main

    code = main(["optimize", "--excitation", "fourier", "--fourier",
                 "1:0.2:0,3:0.15:0.4,5:0.06:0", "--gamma", "0.01", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert code == 0
    for key in ("search", "candidate_patterns", "patterns_tried", "polished", "abandoned",
                "second_power", "upper_bound", "bound_gap"):
        assert key in d
    assert d["candidate_patterns"] == math.comb(6, 2)
    assert d["polished"] + d["abandoned"] <= d["patterns_tried"] + 3
    assert d["upper_bound"] >= d["power"]


def test_second_best_is_a_lower_local_maximum():
    exc = parapend.fourier(FAST_CASES[0][0], omega=FAST_CASES[0][1])
    r = parapend.optimize(excitation=exc, gamma=0.0)
    assert r.second_power is not None and r.second_power < r.power
    assert r.second_power in [pytest.approx(v, abs=1e-11) for v in r.local_maxima]


@pytest.mark.parametrize("gamma", [0.01, 0.05])
def test_dynamic_programme_finds_the_exhaustive_optimum(monkeypatch, gamma):
    """With enumeration switched off, the (t, theta) programme's seeds reach the optimum
    that every one of the 792 patterns gives (12 extrema per period)."""
    exc = parapend.fourier(FAST_CASES[3][0], omega=FAST_CASES[3][1])
    assert pattern_count(limit(exc)) == 792
    full = search_fourier(exc, 24, gamma)
    monkeypatch.setattr(fourier_mod, "ENUMERATE_MAX", 1)
    dp = search_fourier(exc, 24, gamma)
    assert dp.evidence.strategy == "dynamic-programme"
    assert dp.evidence.patterns_tried < 100
    assert dp.best.power >= full.best.power - 1e-8


def test_threshold_covers_the_spectrum():
    """A 40th harmonic that N = 8 and 16 both miss: N starts from the spectrum."""
    r = parapend.threshold(excitation="fourier", fourier="1:0.3,40:0.05")
    assert r.success and r.harmonics >= 64
    assert r.damping_threshold == pytest.approx(0.0860792, abs=1e-6)
    assert r.refinement_change <= 1e-8 * r.damping_threshold


def test_sweeps_report_their_refinement():
    ds = parapend.damping_sweep(points=3)
    # at gamma = 0 the N-harmonic optimum creeps up to the limit like N^-1.9 (docs/limit.md)
    assert ds.attrs["harmonics"] == 32 and 0 < ds.attrs["refinement_change"] < 1e-3
    fine = parapend.optimize(gamma=0.0, harmonics=64).power
    assert ds.attrs["refinement_change"] == pytest.approx(fine - ds.power.values[0], abs=1e-12)
    tab = parapend.harmonic_table(range(2, 5))
    assert tab.attrs["spectrum_harmonics"] == 1 and tab.attrs["refinement_change"] > 0
    assert tab.global_search.values.tolist() == [True, False, True]


def test_harmonic_table_global_rows_are_the_optimum():
    exc = parapend.fourier(FAST_CASES[0][0], omega=FAST_CASES[0][1])
    tab = parapend.harmonic_table(range(6, 10), excitation=exc)
    assert tab.global_search.values.tolist() == [True, False, True, True]
    for n, p, g in zip(tab.harmonics.values, tab.power.values, tab.global_search.values):
        best = parapend.optimize(excitation=exc, harmonics=int(n)).power
        assert p <= best + 1e-12 and (not g or p == pytest.approx(best, abs=1e-10))


@pytest.mark.slow  # several seconds; the default run stays within its budget
def test_bvp_peak_torque_from_its_own_mesh():
    """At gamma = 1e-16 the turns are boundary layers about 1e-5 wide: a fixed grid of 4096
    points misses them (it reported 2.63); the motion's own mesh does not."""
    r = parapend.optimize(method="bvp", gamma=1e-16)
    motion, exc = r.motion, r._excitation
    t = exc.period * np.arange(1 << 21) / (1 << 21)
    dense = np.max(np.abs(torque(motion, exc, 1e-16, t)))
    assert r.peak_torque >= dense * (1 - 1e-6) and r.peak_torque > 1e9


@pytest.mark.slow
def test_brute_force_on_200_random_excitations():
    """Acceptance: 200 seeded excitations (1 to 6 harmonics), three dampings,
    each against all patterns plus 200 random starts: never below by more than 1e-8."""
    rng = np.random.default_rng(2026)
    for _ in range(200):
        exc = random_excitation(rng)
        for gamma in (0.0, 0.01, 0.05):
            _check_case(exc, gamma, starts=200)


def test_motion_of_the_optimum_is_that_of_the_seed_named():
    """found_by names a run whose power is the reported one."""
    exc = parapend.fourier(FAST_CASES[2][0], omega=FAST_CASES[2][1])
    found = search_fourier(exc, 24, 0.01)
    assert any(r.seed == found.best.seed and r.power == found.best.power for r in found.runs)
    m = FourierMotion.from_vector(exc.omega, found.best.x)
    assert m.harmonics == 24


def test_bvp_approaches_the_limit_like_epsilon_to_two_thirds():
    """Boundary layers of width (epsilon/|q''|)^(1/3) cost epsilon^(2/3): the BVP's gap to the
    limit shrinks by 100^(2/3) = 21.5 per factor 100 in gamma, down to gamma = 1e-18 (the
    smallest the API accepts, limits.MIN_BVP_GAMMA). Below about 1e-15 the residual at the
    centre of a layer meets its rounding floor instead of tol in some elements; the result
    says so (residual_floor), and the floor stays far below 1 (here at most ~1e-7)."""
    from parapend.limits import MIN_BVP_GAMMA
    from parapend.optimal.bvp import solve_bvp_optimum

    exc = parapend.harmonic()
    lim = limit(exc).power
    gaps = []
    for g in (1e-10, 1e-12, 1e-14, 1e-16, MIN_BVP_GAMMA):
        s = solve_bvp_optimum(exc, g)
        assert s.success and s.strict_maximum, (g, s.message)
        assert s.max_residual <= max(1e-8, s.residual_floor) and s.residual_floor < 1e-5
        assert (s.residual_floor > 0) == ("rounding floor" in s.message)
        gaps.append(lim - s.power)
    ratios = np.array(gaps[:-1]) / np.array(gaps[1:])
    assert np.all(np.abs(ratios / 100 ** (2 / 3) - 1) < 0.02), ratios


def test_many_extrema_use_the_dynamic_programme_and_report_the_count(capsys):
    """80 extrema per period: C(80, 39) ~ 1e23 patterns, beyond 2^53 (a float in JSON)."""
    import json

    from parapend.cli import main

    code = main(["optimize", "--fourier", "1:0.3,40:0.05", "--gamma", "0.01", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert code == 0 and d["success"] and d["search"] == "dynamic-programme"
    assert d["extrema_per_period"] == 80
    assert d["candidate_patterns"] == float(math.comb(80, 39))
    assert d["patterns_tried"] < 100 and d["power"] >= d["uniform_power"]
    code = main(["optimize", "--fourier", "1:0.3,40:0.05", "--gamma", "0.01"])
    assert "of about 10^23.0 half-turn direction patterns" in capsys.readouterr().out


def test_screening_resolution_policy():
    """gamma > 0: patterns ranked at N = 32 above it; gamma = 0: at the full N while
    count x N^3 stays within the work budget, else at the largest N within it."""
    from parapend.optimal.fourier import ENUMERATE_WORK, _screen_harmonics

    assert _screen_harmonics(792, 24, 0.01) is None
    assert _screen_harmonics(792, 64, 0.01) == 32
    assert _screen_harmonics(792, 96, 0.0) is None
    assert _screen_harmonics(792, 1024, 0.0) == 96
    n = _screen_harmonics(15, 1024, 0.0)
    assert 15 * n**3 <= ENUMERATE_WORK < 15 * (n + 1) ** 3
