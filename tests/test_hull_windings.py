"""The hull's record optimum over windings: the search between swinging and rotation on a
long record (rule, stores, and one bin of the causal matrix against its causal run)."""

import json
import math

import pytest

from parapend.hydro import result as res
from parapend.hydro.hull_control import start_mode


def _mode(k, power, success=True, mean=180.0, amp=200.0):
    return {"mode": "swinging" if k == 0 else "rotation", "winding": k, "power_w": power,
            "success": success, "status": "converged" if success else "stalled",
            "mean_angle_deg": mean if k == 0 else None,
            "swing_amplitude_deg": amp if k == 0 else None}


def _search(powers, top=50, swing=(180.0, 200.0), failed=(), screened=()):
    """Run the search with a fake solve giving ``powers[k]`` (W) at winding ``k``: the
    windings tried, and the modes. Each mode's refinement history is its power at 100
    harmonics only (``screened``: the windings whose answer is entered unrefined)."""
    modes = [_mode(top, 0.5), _mode(0, powers[0], mean=swing[0], amp=swing[1])]
    for m in modes:
        m["refinement_history"] = [[100, m["power_w"]]]
    tried = []

    def solve(k, screen):
        assert isinstance(screen, res._Screen)
        tried.append(k)
        m = _mode(k, powers.get(k, 0.0), success=k not in failed)
        m["refinement_history"] = [[100, m["power_w"]]]
        if k in screened:
            m["_screened"] = True
        return m

    res._search_windings(modes, solve, top)
    return tried, modes


@pytest.mark.parametrize("mean, amp, through", [
    (180.0, 170.0, False), (180.0, 180.0, True), (180.0, 200.0, True),
    (-30.0, 20.0, False), (-30.0, 31.0, True), (540.0, 170.0, False), (540.0, 181.0, True)])
def test_a_swing_passes_the_upright_where_a_multiple_of_360_degrees_lies_within_it(
        mean, amp, through):
    assert res.through_upright(mean, amp) is through
    assert start_mode(0, mean, amp) == ("rotate" if through else "swing")


def test_the_search_goes_on_while_a_winding_beats_the_best_and_stops_after_two_misses():
    # the measured landscape of the Hs 1.5 m, Te 7 s bin (W): 1 misses, 2 and 3 beat
    tried, modes = _search({0: 852.5, 1: 849.0, 2: 853.8, 3: 856.3, 4: 855.0, 5: 850.0,
                            6: 900.0})
    # 6 would beat, but two misses in a row stop it; then the other sense (0 W here)
    assert tried == [1, 2, 3, 4, 5, -1, -2]
    assert [m["mode"] for m in modes[2:]] == ["swinging"] * 7
    assert all(m["searched"] for m in modes[2:])
    # Hs 1 m, Te 7 s: one net turn best, then two misses
    tried, _ = _search({0: 453.8, 1: 464.7, 2: 458.7, 3: 459.8, 4: 456.5})
    assert tried == [1, 2, 3, -1, -2]


def test_the_search_stays_below_rotation_and_skips_a_swing_short_of_the_upright():
    tried, _ = _search({0: 1.0, **{k: 1.0 + k for k in range(1, 10)},
                        **{-k: 5.0 + k for k in range(1, 10)}}, top=4)
    assert tried == [1, 2, 3, -1, -2, -3]
    tried, modes = _search({0: 1.0, 1: 5.0}, swing=(180.0, 120.0))
    assert tried == [] and len(modes) == 2
    tried, _ = _search({0: 0.4, 1: 5.0})  # rotation (0.5 W) beats the swing
    assert tried == []


def test_a_failed_winding_is_a_miss_not_the_best():
    tried, modes = _search({0: 1.0, 1: 9.0, 2: 0.5, 3: 0.5}, failed=(1,))
    assert tried == [1, 2, -1, -2]
    assert not modes[2]["success"]


def test_a_screened_winding_is_a_miss_and_never_the_lead():
    # screened with a power above the best (cannot happen; the flag rules): still a miss
    tried, modes = _search({0: 1.0, 1: 9.0, 2: 0.5, 3: 0.5}, screened=(1,))
    assert tried == [1, 2, -1, -2] and modes[2]["_screened"]


class _Case:
    def __init__(self, harmonics):
        self.harmonics = harmonics


class _Sol:
    def __init__(self, power, harmonics=2808):
        self.power, self.case = power, _Case(harmonics)


def test_the_screen_compares_at_the_same_harmonics_with_a_margin():
    # the Hs 1 m, Te 7 s bin: one net turn's answer (refined 464.769 -> 464.739 W)
    best = {"power_w": 464.739, "refinement_history": [[2808, 464.769], [5616, 464.739]]}
    screen = res._Screen(best)
    assert screen.unrefined(_Sol(456.754)) == 464.769  # 3 net turns: 1.7 % below, a miss
    assert screen.unrefined(_Sol(461.0)) is None  # within 1e-2: refined
    assert screen.unrefined(_Sol(460.0)) == 464.769  # just past 1e-2
    assert screen.unrefined(_Sol(400.0, harmonics=1404)) is None  # other harmonics
    assert screen.unrefined(_Sol(float("nan"))) is None
    # a best whose refinement moved it by 1e-2: the margin is four times that
    moved = res._Screen({"power_w": 1010.0,
                         "refinement_history": [[2808, 1000.0], [5616, 1010.0]]})
    assert moved.margin(1000.0) == pytest.approx(4e-2)
    assert moved.unrefined(_Sol(970.0)) is None
    assert moved.unrefined(_Sol(955.0)) == 1000.0


def test_the_screen_compares_on_the_continuations_levels_with_the_bests_change_there():
    """The 200-wave barge record's swinging (the best) on the levels 702 and 1404 and its
    refinement: the margin on a level is four times its change from there to its refined
    answer (13.7 % at 702, where the rotation's 1309.34 W is 17 % below; 1e-2 at 1404)."""
    from types import SimpleNamespace

    best = {"power_w": 1633.996, "refinement_history": [[2808, 1634.883], [5616, 1633.996]],
            "_solution": SimpleNamespace(level_history=((175, 62.99), (702, 1579.894),
                                                        (1404, 1633.800)))}
    screen = res._Screen(best)
    assert screen.margin(1579.894) == pytest.approx(4 * (1633.996 - 1579.894) / 1579.894)
    assert screen.unrefined(_Sol(1309.34, harmonics=702)) == 1579.894
    assert screen.unrefined(_Sol(1400.0, harmonics=702)) is None  # 11 % below: climbed on
    assert screen.unrefined(_Sol(10.0, harmonics=175)) is None  # the margin 100 there
    assert screen.margin(1633.8) == res.SCREEN_MARGIN
    assert screen.unrefined(_Sol(1592.59, harmonics=1404)) == 1633.8  # 1 net turn
    assert screen.unrefined(_Sol(1625.86, harmonics=1404)) is None  # 2 net turns
    assert screen.unrefined(_Sol(1600.0)) == 1634.883  # the record's own harmonics


def test_a_screen_that_keeps_the_answer_changes_nothing_and_one_that_drops_it_stops_early():
    """The search's answer with a screen that keeps it is the one without (bit for bit);
    a screen that drops it returns the unrefined answer."""
    from parapend.hydro.api import hull_problem
    from parapend.hydro.declared import default_of
    from parapend.hydro.hull import hull_search, make_case
    from parapend.hydro.inputs import _irregular_wave
    from parapend.units import Units

    p = hull_problem()
    pend = p["pendulum"]
    wave, _ = _irregular_wave(1.0, 6.0, "jonswap", 3.3, 12.0, 0, default_of("cutoff", None),
                              None, default_of("taper", None),
                              Units(pend.length, pend.mass, 9.81, pend.inertia))

    def make(scale):
        base = make_case(p["hull"], pend, wave, winding=0, pivot=p["pivot"])
        if scale == 1:
            return base
        return make_case(p["hull"], pend, wave, winding=0, harmonics=scale * base.harmonics,
                         hull_harmonics=scale * base.hull_harmonics, pivot=p["pivot"])
    plain = hull_search(make)
    seen = []
    kept = hull_search(make, screen=lambda sol: seen.append(sol.power) or True)
    assert plain.success and len(plain.refinement_history) >= 2
    assert kept.power == plain.power and kept.refinement_history == plain.refinement_history
    assert seen == [plain.refinement_history[0][1]]
    dropped = hull_search(make, screen=lambda sol: False)
    assert dropped.screened and not kept.screened
    assert dropped.refinement_history == () and dropped.power == seen[0]
    assert dropped.case.harmonics == plain.refinement_history[0][0]


def test_a_searched_answer_solves_the_swinging_first_and_screens_the_rotation(monkeypatch):
    """With the search the swinging is solved first, unscreened, and the rotation then
    with a screen against it; the modes keep the order asked for."""
    from parapend.hydro.api import hull_problem
    from parapend.hydro.declared import default_of
    from parapend.hydro.inputs import _irregular_wave
    from parapend.units import Units

    p = hull_problem()
    pend = p["pendulum"]
    wave, _ = _irregular_wave(1.0, 6.0, "jonswap", 3.3, 12.0, 0, default_of("cutoff", None),
                              None, default_of("taper", None),
                              Units(pend.length, pend.mass, 9.81, pend.inertia))
    calls = []
    solve_mode = res._solve_mode

    def spy(*a, **kw):
        screen = a[8] if len(a) > 8 else kw.get("screen")
        calls.append((a[3], screen is not None))
        return solve_mode(*a, **kw)
    monkeypatch.setattr(res, "_solve_mode", spy)
    kw = dict(pivot=p["pivot"], windings=(2, 0), pitch_inertia=p["pitch_inertia"])
    searched = res.hull_answer(p["hull"], pend, wave, search=True, **kw)
    assert calls[:2] == [(0, False), (2, True)]
    assert [m["winding"] for m in searched.modes][:2] == [2, 0]
    calls.clear()
    plain = res.hull_answer(p["hull"], pend, wave, **kw)
    assert calls == [(2, False), (0, False)]
    # on this 2-wave record the swinging beats the rotation (1049 W); the rotation, 18 %
    # below it on the record's harmonics, is entered unrefined, and the swinging is the
    # same answer as without the search
    assert plain.winding == 0
    assert searched.modes[1]["power_w"] == plain.power_w
    assert "not refined" in searched.modes[0]["status"]
    assert "not refined" not in plain.modes[0]["status"]
    # the search (net turns either way below the rotation's 2) finds one reversed net turn
    # better (1136 W), and that best alone, checked once all modes are in, carries the
    # checks; the swinging below it says its check was left out
    tried = [m["winding"] for m in searched.modes[2:] if m["mode"] != "rest"]
    assert tried == [1, -1]
    assert searched.winding == -1 and searched.power_w > 1.05 * plain.power_w
    best = searched.modes[3]
    for key in ("gradient_max_w_per_rad", "hessian_scaled_largest_eigenvalue"):
        assert best[key] is not None
    assert searched.modes[1]["status"].endswith("below the best: its optimality not checked")


def test_a_searched_records_best_mode_alone_is_checked(monkeypatch):
    """The modes of a searched record are solved unchecked; once all are in, the best gets
    its optimality check and the others say theirs was left out (a screened one keeps its
    own status)."""
    seen = []
    monkeypatch.setattr(res, "_optimality", lambda sol: seen.append(sol) or {
        "gradient_max_w_per_rad": 1e-9, "hessian_scaled_largest_eigenvalue": -1e-3})
    modes = [dict(_mode(k, p), _solution=k, _unchecked=True)
             for k, p in ((0, 1634.0), (1, 1640.0), (2, 1625.0))]
    modes.append(dict(_mode(3, 1500.0), _solution=3, _screened=True))
    modes[-1]["status"] = "converged at 702 harmonics, ...; not refined"
    res._check_best(modes, modes[1])
    assert seen == [1] and modes[1]["gradient_max_w_per_rad"] == 1e-9
    assert modes[1]["status"] == "converged"
    for m in (modes[0], modes[2]):
        assert m["status"] == "converged; below the best: its optimality not checked"
        assert "gradient_max_w_per_rad" not in m
    assert modes[3]["status"].endswith("not refined")
    assert not any("_unchecked" in m for m in modes)


def test_a_searched_winding_is_labelled_by_its_net_turns():
    m = dict(_mode(3, 1.0), mode="swinging")
    assert res.mode_label(m) == "swinging, 3 net turns"
    assert res.mode_label(dict(_mode(1, 1.0), mode="swinging")) == "swinging, 1 net turn"
    assert res.mode_label(dict(_mode(-1, 1.0), mode="swinging")) == "swinging, -1 net turn"
    assert res.mode_label(dict(_mode(-2, 1.0), mode="swinging")) == "swinging, -2 net turns"
    assert res.mode_label(_mode(2, 1.0)) == "rotation"
    assert res.mode_label(_mode(-2, 1.0)) == "rotation, reversed"
    assert res.mode_label(_mode(0, 1.0)) == "swinging"


def test_the_search_turns_the_other_way_where_that_sense_wins():
    # forward net turns miss twice; the reversed ones beat the swing until two misses
    tried, modes = _search({0: 1.0, 1: 0.9, 2: 0.8, -1: 1.5, -2: 2.0, -3: 1.9, -4: 1.8,
                            -5: 3.0})
    assert tried == [1, 2, -1, -2, -3, -4]
    best = max(modes, key=res._power_of)
    assert best["winding"] == -2 and best["mode"] == "swinging"
    assert start_mode(-2) == "rotate-reversed" == start_mode(-5, 180.0, 10.0)
    assert start_mode(3) == "rotate"


def test_a_hull_store_records_its_record_optimum_and_an_older_one_is_refused(
        tmp_path, monkeypatch):
    from parapend.errors import ParameterError
    from parapend.performance import matrix_spec
    from parapend.performance.spec import RECORD_OPTIMUM, MatrixSpec

    spec = matrix_spec(hs="1,2", te="6,7", realizations=1, device="buoy",
                       dofs="surge,heave,pitch")
    d = json.loads(spec.to_json())
    assert d["record_optimum"] == RECORD_OPTIMUM
    assert MatrixSpec.from_json(spec.to_json()) == spec
    heave = matrix_spec(hs="1,2", te="6,7", realizations=1, device="buoy")
    assert "record_optimum" not in json.loads(heave.to_json())
    # a store written before: the same sweep without the marker
    from parapend.maps import store

    old = dict(d)
    old.pop("record_optimum")
    monkeypatch.setattr(store, "_identify",
                        lambda path: ("store", json.dumps(old, sort_keys=True)))
    tmp_path.joinpath("m").mkdir()
    with pytest.raises(ParameterError, match="hull's record optimum of an earlier version"):
        store._prepare(tmp_path / "m", spec, None, False)
    # ... and one whose record optimum turned the forward sense alone, or did not climb a
    # short record's turns
    for before in ("rotation, swinging and the windings searched",
                   "rotation both ways, swinging and the windings searched both ways"):
        old["record_optimum"] = before  # the forward sense; the short records' turns
        with pytest.raises(ParameterError,
                           match="hull's record optimum of an earlier version"):
            store._prepare(tmp_path / "m", spec, None, False)
    monkeypatch.setattr(store, "_identify", lambda path: ("store", spec.to_json()))
    store._prepare(tmp_path / "m", spec, None, False)  # the same sweep resumes


@pytest.mark.slow
def test_the_matrix_bins_optimum_turns_both_ways_and_is_above_its_causal_run():
    """Hs 1 m, Te 7 s of the 4 x 4 causal matrix (234 waves): the forward rotation and the
    swinging give 318.7 (screened) and 453.8 W, and the stored perfect-forecast closed loop,
    a motion the plant realized (another method: time domain, causal), 459.54 W, above both
    (with one net turn of swinging, searched when the forward sense alone was solved,
    464.74 W); the reversed rotation, 535.63 W, is the answer and above it, so the
    windings between are not searched."""
    from parapend.hydro.api import solve_record
    from parapend.performance import matrix_spec
    from parapend.performance.buoy_device import wave_of
    from parapend.performance.hull_device import problem

    spec = matrix_spec(hs="0.5,1,1.5,2", te="5,6,7,8", realizations=1, device="buoy",
                       dofs="surge,heave,pitch", controller="mpc", forecast="perfect,ar")
    wave, info = wave_of(spec, 1, 2, 0)
    r = solve_record(problem(spec), wave, info)
    assert r.success and r.headline_reason is None
    tried = [m["winding"] for m in r.modes if m["mode"] != "rest"]
    assert tried == [234, -234, 0]
    # the forward rotation (318.66 W on the 702-harmonic level, the swinging's 433.62 W
    # there) is solved after the swinging and screened on that level of its continuation
    rot = r.modes[0]
    assert "not refined" in rot["status"] and rot["harmonics"] < r.harmonics
    assert rot["power_w"] < 0.8 * r.power_w
    assert r.winding == -234 and r.mode == "rotation"
    assert r.modes[2]["power_w"] == pytest.approx(453.756, rel=1e-4)
    # the causal run (docs/performance.md) below it
    assert r.power_w > 459.537 * 1.1
    assert math.isclose(r.power_w, 535.627, rel_tol=2e-3)
    assert "rotation, reversed: converged" in r.status


def _climb(powers, start=(5, -5), top=12, failed=()):
    """Run the short record's climb with a fake solve giving ``powers[k]`` (W) at winding
    ``k``, after the windings ``start`` and swinging: the windings tried, and the modes."""
    modes = [_mode(k, powers[k]) for k in start] + [_mode(0, powers.get(0, 0.0))]
    for m in modes:
        m["refinement_history"] = [[60, m["power_w"]]]
    tried = []

    def solve(k, screen, checks):
        assert isinstance(screen, res._Screen) and checks is False
        tried.append(k)
        m = _mode(k, powers.get(k, 0.0), success=k not in failed)
        m["refinement_history"] = [[60, m["power_w"]]]
        return m

    res._climb_windings(modes, solve, top)
    return tried, modes


def test_a_short_records_rotation_climbs_its_turns_in_the_better_sense():
    # the default sea's seed 0 (W, reversed turns): not monotone; 2 turns best, found
    # past one miss; away from zero two misses at once
    seed0 = {-5: 988.1, -4: 989.8, -3: 956.9, -2: 1000.8, -1: 961.2, -6: 941.4,
             -7: 887.9, 5: 703.1, 0: 947.1}
    tried, modes = _climb(seed0)
    assert tried == [-4, -3, -2, -1, -6, -7]
    best = max(modes, key=lambda m: m["power_w"])
    assert best["winding"] == -2 and all(m["searched"] for m in modes[3:])
    assert res.mode_label(best) == "rotation, 2 turns, reversed"
    # seed 3: the record's own 5 turns best, two misses each way
    seed3 = {-5: 1144.0, -4: 1119.2, -3: 1096.6, -6: 1102.3, -7: 1019.1, 5: 768.8}
    assert _climb(seed3)[0] == [-4, -3, -6, -7]
    # the forward sense when it is the better; stopped at one turn and at ``top``; a
    # failed winding is a miss
    fwd = {5: 900.0, -5: 800.0, 4: 910.0, 3: 920.0, 2: 930.0, 1: 940.0, 6: 901.0, 7: 950.0}
    assert _climb(fwd, top=6)[0] == [4, 3, 2, 1, 6]
    assert _climb(fwd, failed=(4,))[0] == [4, 3, 2, 1, 6, 7, 8, 9]
    # no rotation solved: nothing to climb
    assert _climb({5: -math.inf, -5: -math.inf})[0] == []


@pytest.mark.parametrize("pto, climb", [({}, 30), ({"efficiency": 0.9}, 0),
                                        ({"torque_limit": 30e3}, 0)])
def test_a_short_record_climbs_through_an_ideal_take_off_only(pto, climb, monkeypatch):
    """``solve_record`` asks the short record's climb, up to the record's harmonics cap in
    turns (an ideal take-off's: 360 harmonics, 12 a turn), and not through a lossy one
    (its solves unscreened: too slow); a long record searches instead."""
    from parapend.hydro import api
    from parapend.hydro.coupled import Wave

    seen = {}

    def fake(*args, **kw):
        seen.update(kw)

    monkeypatch.setattr(api, "optimum", fake)
    p = api.hull_problem(dofs="surge,heave,pitch", **pto)
    wave = Wave.from_spectrum(hs=1.0, tp=6.0, repeat_period=24.0, seed=0)
    api.solve_record({**p, "max_harmonics": 360}, wave, {})
    assert seen["winding_climb"] == climb and seen["winding_search"] is False
    assert seen["winding"] == (5, -5, 0)
