"""The sense of the pendulum's turn in a hull that surges, heaves and pitches.

A hull's surge and pitch make the two senses different problems (a heaving buoy's are
mirror images). The mirror ``x -> -x`` maps one onto the other: the hull's coefficients
become ``S A S``, ``S B S``, ``S C S`` and the excitation ``S F`` with ``S = diag(-1, 1, -1)``
(the wave arriving from the other side), the pivot's offset changes sign, and the motion
``phi -> -phi``, ``x -> -x``, ``beta -> -beta`` keeps the power. So turning against the sense
of a positive pitch (winding ``-K``) in one hull is turning with it (``+K``) in the mirrored
hull: an invariant the solver does not use (it solves ``-K`` directly)."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from hull_timedomain import RHO_V, synthetic_hull
from test_hull_optimum_timedomain import _case as _forward_case

import parapend
from parapend.hydro.bem import HullHydro
from parapend.hydro.hull import hull_search
from parapend.performance.resource import repeat_period

S = np.diag([-1.0, 1.0, -1.0])
HULL = synthetic_hull()
PEND = {"mass": 4000.0, "length": 1.0, "inertia": 5000.0, "damping_coefficient": 50.0,
        "pivot_height": 1.5, "pivot_offset": 1.0}


def _case(winding, scale, mirrored):
    """The synthetic hull (or its mirror image) at the harmonics of the replay tests'
    regular wave (tests/test_hull_optimum_timedomain.py)."""
    cs = _forward_case(winding, scale)
    if not mirrored:
        return cs
    return dataclasses.replace(cs, A=S @ cs.A @ S, B=S @ cs.B @ S, F=cs.F @ S,
                               C=S @ cs.C @ S, pivot=(-cs.pivot[0], cs.pivot[1]))


@pytest.mark.parametrize("winding", [1, 2])
def test_a_reversed_turn_is_the_mirrored_hulls_forward_turn(winding):
    """Winding ``-K`` in the hull is winding ``K`` in its mirror image: the same power to
    rounding and the motion mirrored (``phi -> -phi``); the two senses differ."""
    back = hull_search(lambda s: _case(-winding, s, False), refine=False)
    mirror = hull_search(lambda s: _case(winding, s, True), refine=False)
    fwd = hull_search(lambda s: _case(winding, s, False), refine=False)
    assert back.success and mirror.success and fwd.success
    assert back.power == pytest.approx(mirror.power, rel=1e-9)
    x, y = np.asarray(back.x), -np.asarray(mirror.x)
    x0 = math.remainder(x[0] - y[0], 2 * math.pi)
    assert abs(x0) < 1e-6 and np.max(np.abs(x[1:] - y[1:])) < 1e-6 * np.max(np.abs(x[1:]))
    assert abs(back.power - fwd.power) > 1e-3 * abs(fwd.power)


@pytest.fixture(scope="module")
def datasets(tmp_path_factory):
    """The synthetic hull and its mirror image as Capytaine datasets."""
    from capytaine.io.xarray import save_dataset_as_netcdf

    out = {}
    for name, t in (("hull", np.eye(3)), ("mirror", S)):
        hull = HullHydro(omega=HULL["omega_data"], added_mass=t @ HULL["A"] @ t,
                         radiation_damping=t @ HULL["B"] @ t, excitation=HULL["F"] @ t,
                         hydrostatic_stiffness=t @ HULL["C"] @ t, mass=RHO_V,
                         pitch_inertia=float(HULL["Mh"][2, 2]), description=name)
        path = tmp_path_factory.mktemp(name) / f"{name}.nc"
        save_dataset_as_netcdf(path, hull.to_dataset())
        out[name] = str(path)
    return out


def test_the_answer_turns_whichever_way_is_better(datasets):
    """A 2-wave record (Hs 1 m, Tp 6 s, seed 3) where the reversed turns beat swinging and
    the forward rotation: the default answer solves both senses, and the record's other
    turns in the better one, and is the best; its reversed rotation is the mirrored hull's
    forward one (to 1e-9), whose own default answer is the same power turning forward."""
    rec = {"dofs": "surge,heave,pitch", "hs": 1.0, "tp": 6.0, "seed": 3,
           "repeat_period": repeat_period(2.0, 6.0)}
    mirror_pend = dict(PEND, pivot_offset=-PEND["pivot_offset"])
    r = parapend.buoy(hydro=datasets["hull"], **rec, **PEND)
    labels = [s.split(":")[0] for s in r.status.split("; ")]
    assert labels[:3] == ["rotation", "rotation, reversed", "swinging"]
    powers = {m["winding"]: m["power_w"] for m in r.modes if m["mode"] != "rest"}
    # the record's other turns are searched in the better sense: the reversed one
    assert {2, -2, 0, -1, -3} <= set(powers) and all(k <= 0 for k in set(powers) - {2})
    assert all(m["searched"] for m in r.modes if m["winding"] not in (2, -2, 0, None))
    assert r.winding < 0 and r.power_w == max(powers.values())
    best = next(m for m in r.modes if m["winding"] == r.winding)
    k = abs(r.winding)
    assert parapend.hydro.result.best_label(r) == (
        f"rotation, {k} turn{'s' if k > 1 else ''}, reversed" if best.get("searched")
        else "rotation, reversed")
    assert r.power_w > 1.01 * max(powers[2], powers[0])
    m = parapend.buoy(hydro=datasets["mirror"], winding=-r.winding, **rec, **mirror_pend)
    assert m.power_w == pytest.approx(r.power_w, rel=1e-9)
    m = parapend.buoy(hydro=datasets["mirror"], **rec, **mirror_pend)
    assert m.winding == -r.winding and m.power_w == pytest.approx(r.power_w, rel=1e-9)


def test_a_sweep_says_which_way_its_rotation_turns(datasets):
    """A period sweep's ``rotation_winding`` is the winding of the better rotation of each
    period's answer; in the mirrored hull the same rotation turns the other way with the
    same power (to 1e-9). The saved sweep carries it, and the text names the best mode with
    its sense."""
    from parapend.cli.buoy import _hull_sweep_text

    mirror_pend = dict(PEND, pivot_offset=-PEND["pivot_offset"])
    r = parapend.buoy(dofs="surge,heave,pitch", hydro=datasets["hull"], wave_period="4,5",
                      **PEND)
    m = parapend.buoy(dofs="surge,heave,pitch", hydro=datasets["mirror"], wave_period="4,5",
                      **mirror_pend)
    assert r.rotation_winding == [-1, 1]  # at 4 s the better turn is the reversed one
    for res, k, p in zip(r.results, r.rotation_winding, r.rotation_power_w):
        rot = [x for x in res.modes if x["mode"] == "rotation"]
        assert {x["winding"] for x in rot} == {1, -1}
        best = max(rot, key=lambda x: x["power_w"])
        assert (k, p) == (best["winding"], best["power_w"])
    assert [-k for k in m.rotation_winding] == r.rotation_winding
    assert np.allclose(m.rotation_power_w, r.rotation_power_w, rtol=1e-9, atol=0)
    ds = r.to_dataset()
    assert ds["rotation_winding"].values.tolist() == r.rotation_winding
    rows = {c[0]: c for c in (re.split(r"\s{2,}", line.strip())
                              for line in "\n".join(_hull_sweep_text(r)).splitlines())
            if c[0] in ("4", "5")}
    for t, res, k in zip(("4", "5"), r.results, r.rotation_winding):
        label = parapend.hydro.result.mode_label({"mode": res.mode, "winding": res.winding})
        assert (rows[t][3], rows[t][5]) == (f"{k:+d}", label)


@pytest.mark.slow
def test_no_winding_beats_the_climbed_answer(datasets):
    """Brute force: on the 2-wave record, each winding from -5 to 3 solved alone (swinging
    at 0) is at most the default answer's power (its search tried both senses' rotation,
    swinging, and the better sense's other turns), and one of them is it."""
    rec = {"dofs": "surge,heave,pitch", "hs": 1.0, "tp": 6.0, "seed": 3,
           "repeat_period": repeat_period(2.0, 6.0)}
    r = parapend.buoy(hydro=datasets["hull"], **rec, **PEND)
    each = {k: parapend.buoy(hydro=datasets["hull"], winding=k, **rec, **PEND).power_w
            for k in range(-5, 4)}
    assert max(each.values()) <= r.power_w * (1 + 1e-9)
    assert each[r.winding] == pytest.approx(r.power_w, rel=1e-9)
