"""Buoy answers independent of the call (docs/buoy.md, "One mesh, one grid"): one mesh and one
frequency grid per body, whichever periods a call asks for; the discretization error estimate
from a second, coarser mesh; linear theory's validity warnings; comma lists of periods; a
design optimum on a bound.

The fast tests replace the BEM (``bem._solve``) by an analytic body whose coefficients depend
on the panel size it is asked for, so they check the plumbing (which mesh and which grid
each call asks for, and what is made of them) without Capytaine; the slow ones run the BEM.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro import bem
from parapend.hydro.api import parse_periods
from parapend.hydro.coupled import Wave
from parapend.hydro.design import optimize_design
from parapend.hydro.optimum import coupled_optimum

G = 9.81


def _toy(omega, h, rho=1025.0, g=G):
    """A passive heave model of a body like the default cylinder (M about 400 kg, heave
    resonance near 1.7 s), whose damping grows by ``1 + h`` with the panel radius ``h`` (m):
    a coarser mesh gives a slightly different answer. The excitation is Froude-Krylov-like,
    ``(C - w^2 A) exp(-k d / 2)``, ``F(0) = C`` (a long wave lifts the body with it)."""
    w = np.asarray(omega, dtype=float)
    c = rho * g * math.pi * 0.25
    mass = rho * math.pi * 0.25 * 0.5
    a = 0.4 * mass * np.ones_like(w)
    b = (1 + h) * 0.3 * mass * w**2 / (1 + (w / 3) ** 4) * np.exp(-0.1 * w)
    f = (c - w**2 * a) * np.exp(-0.25 * w**2 / g) + 0.1j * w * b
    return bem.Hydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                     hydrostatic_stiffness=c, mass=mass, rho=rho, g=g,
                     description=f"toy, panel radius {h:.6g} m")


@pytest.fixture()
def fake_bem(monkeypatch):
    """``bem._solve`` replaced by :func:`_toy`; the list of (panel radius, omega) asked."""
    asked = []

    def solve(build, omega, *, rho, g, water_depth, description, cache, key_parts):
        h = float(json.loads(key_parts)["faces_max_radius"])
        asked.append((h, np.array(omega, dtype=float)))
        return _toy(omega, h, rho, g)

    monkeypatch.setattr(bem, "_solve", solve)
    return asked


# --- one mesh and one grid per body ---------------------------------------------------------------
@pytest.mark.slow
def test_one_mesh_and_one_grid_whatever_the_periods(fake_bem):
    """The 1.8 s answer alone, inside FROM:TO:N, inside a comma list and inside a sweep that
    contains 1.8 s: the same to 1e-9, as every call asks for the same two meshes (the body's
    and the error estimate's) on the same grid."""
    alone = parapend.buoy(wave_period=1.8)
    pair = parapend.buoy(wave_period="1.8:2.2:2")
    listed = parapend.buoy(wave_period="2.2,1.8")
    sweep = parapend.buoy(wave_period="1.6:2.0:3")
    assert sweep.period_s[1] == pytest.approx(1.8, rel=1e-15)
    p = alone.power_w
    assert p > 0 and alone.success
    for other in (pair.power_w[0], listed.power_w[1], sweep.power_w[1]):
        assert other == pytest.approx(p, rel=1e-9)
    for other in (pair.mesh_error_w[0], listed.mesh_error_w[1], sweep.mesh_error_w[1]):
        assert other == pytest.approx(alone.mesh_error_w, rel=1e-9, abs=1e-12 * p)
    # the body's mesh (radius and draft 0.5 m: panel radius 0.5 / 12) and the coarse one
    h = 0.5 / bem.GEOMETRY_PANELS
    assert sorted({round(a[0], 12) for a in fake_bem}) == [round(h, 12), round(bem.COARSE * h, 12)]
    grid = bem.body_frequencies(h)
    for _, omega in fake_bem:
        np.testing.assert_array_equal(omega, grid)
    # the grid's definition: 2 pi / 100 s up to the wave of 8 coarse panel radii
    assert grid[0] == pytest.approx(2 * math.pi / bem.LONGEST_PERIOD, rel=1e-14)
    assert 2 * math.pi * G / grid[-1] ** 2 == pytest.approx(8 * bem.COARSE * h, rel=1e-8)
    assert alone.body["frequencies"] == grid.size == bem.BODY_FREQUENCIES


def test_the_mesh_error_is_the_answer_on_the_coarser_mesh(fake_bem):
    """``mesh_error_w = |P - P_c|``, ``P_c`` the same optimum solved by hand on the body's
    coarse mesh (panels 1.5 times larger, same frequencies)."""
    r = parapend.buoy(wave_period=1.8)
    coarse = bem.cylinder(0.5, 0.5, omega="body", refine=1 / bem.COARSE)
    fine = bem.cylinder(0.5, 0.5, omega="body")
    np.testing.assert_array_equal(coarse.omega, fine.omega)
    from parapend.hydro.coupled import Pendulum

    pend = Pendulum(mass=80.0, length=0.3, inertia=80.0 * 0.09, damping_coefficient=1.0)
    pc = coupled_optimum(coarse, pend, Wave.regular(0.2, 1.8)).power
    assert r.mesh_error_w == pytest.approx(abs(r.power_w - pc), rel=1e-9)
    assert r.mesh_error_w > 0
    assert r.mesh_error_relative == pytest.approx(r.mesh_error_w / r.power_w, rel=1e-14)
    # the grid's estimate: the body's coefficients on every other frequency (the last kept)
    w = fine.omega
    half = _toy(np.append(w[::2], w[-1]) if (w.size - 1) % 2 else w[::2],
                0.5 / bem.GEOMETRY_PANELS)
    assert half.omega.size == (w.size + 2) // 2 and half.omega[-1] == w[-1]
    ph = coupled_optimum(half, pend, Wave.regular(0.2, 1.8)).power
    assert r.grid_error_w == pytest.approx(abs(r.power_w - ph), rel=1e-9)
    assert r.grid_error_w > 0


def test_a_mesh_file_or_a_dataset_has_no_second_mesh(fake_bem):
    """A mesh file or a dataset is one mesh, someone else's: no error estimate, no geometry
    to check (and no BEM asked for)."""
    from parapend.hydro.api import _coarse_hydro, _geometry

    for kw in ({"mesh": "hull.gdf", "hydro": None}, {"mesh": None, "hydro": "body.nc"}):
        assert _coarse_hydro("cylinder", None, None, **kw) is None
        assert _geometry("cylinder", None, None, **kw) is None
    assert not fake_bem
    assert _geometry("sphere", 0.7, None, None, None) == {"draft_m": 0.7, "freeboard_m": 0.7}


# --- validity of linear theory --------------------------------------------------------------------
def test_linear_theory_warnings(fake_bem, capsys):
    """H = 0.72 m at 1.8 s (just within breaking, H / lambda = 1/7.03, lambda = g T^2 / 2 pi
    in deep water): heave above the 0.5 m draft and freeboard, the bottom out of the water;
    the default wave: none; H = 1.5 m (past breaking) refused before the BEM."""
    ok = parapend.buoy(wave_period=1.8)
    assert ok.validity_warnings == []
    assert ok.body["draft_m"] == 0.5 and ok.body["freeboard_m"] == 0.5
    assert main(["buoy", "--wave-height", "1.5", "--wave-period", "1.8"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.splitlines() == [err] and "past breaking (1/7)" in err
    assert f"at most {1.8**2 * 9.81 / (14 * math.pi):.4g} m" in err
    big = parapend.buoy(wave_period=1.8, wave_height=0.72)
    s = big.samples(800)
    heave = 0.5 * (s["z"].max() - s["z"].min())
    assert heave > 0.5 and heave == pytest.approx(big.heave_amplitude_m, rel=1e-3)
    text = "\n".join(big.validity_warnings)
    assert "exceeds the body's draft 0.5 m" in text and "freeboard 0.5 m" in text
    assert "bottom leaves the water" in text
    assert "breaking limit" not in text
    # the motion relative to the wave, eta = H/2 cos(2 pi t / T), from the samples
    rel = s["z"] - 0.36 * np.cos(2 * math.pi * s["t"] / 1.8)
    assert f"relative to the wave reaches {rel.max():.3g} m" in text
    assert main(["buoy", "--wave-height", "0.72"]) == 0
    out = capsys.readouterr().out
    assert out.count("warning: linear theory") == len(big.validity_warnings) >= 4


def test_relative_motion_is_against_the_wave(fake_bem):
    """A long wave lifts a light-loaded buoy with it: heave above the draft (warned), yet
    the motion relative to the wave stays small, so the bottom stays in the water (the
    wave's phase is the heave's)."""
    r = parapend.buoy(wave_period=20.0, wave_height=1.5, mass=1.0)
    text = "\n".join(r.validity_warnings)
    assert "exceeds the body's draft" in text
    assert "bottom leaves" not in text and "top goes under" not in text
    assert "breaking" not in text


# --- comma lists ------------------------------------------------------------------------------
def test_comma_lists_of_periods():
    np.testing.assert_array_equal(parse_periods("1.8,2.2"), [1.8, 2.2])
    np.testing.assert_array_equal(parse_periods(" 3, 1.5 ,2"), [3.0, 1.5, 2.0])
    assert parse_periods("1.8") is None
    for bad in ("1.8,x", "1.8,,2", "1.8,-2", "1.8,500"):
        with pytest.raises(ParameterError, match="wave-period"):
            parse_periods(bad)
    with pytest.raises(ParameterError, match="wave-period"):
        parse_periods(",".join(["2"] * 201))


def test_cli_takes_a_comma_list(fake_bem, capsys):
    assert main(["buoy", "--wave-period", "1.8,2.2"]) == 0
    out = capsys.readouterr().out
    assert "mesh err (W)" in out
    r = parapend.buoy(wave_period="1.8,2.2")
    rows = [ln.split() for ln in out.splitlines()
            if ln.strip().startswith(("1.8 ", "2.2 "))]
    assert [float(x[0]) for x in rows] == [1.8, 2.2]
    for row, p, e in zip(rows, r.power_w, r.mesh_error_w):
        assert float(row[1]) == pytest.approx(p, rel=1e-5)
        assert float(row[7]) == pytest.approx(e, rel=1e-5)  # the mesh err (W) column
    for row, e in zip(rows, r.grid_error_w):
        assert float(row[8]) == pytest.approx(e, rel=1e-5)  # the grid err (W) column
    # the single run prints the same estimate, the difference of the two meshes' answers
    assert main(["buoy", "--wave-period", "1.8"]) == 0
    out = capsys.readouterr().out.splitlines()
    line = next(ln for ln in out if "mesh error" in ln)
    assert float(line.split()[-2]) == pytest.approx(r.mesh_error_w[0], rel=1e-5)
    line = next(ln for ln in out if "grid error" in ln)
    assert float(line.split()[-2]) == pytest.approx(r.grid_error_w[0], rel=1e-5)


# --- a design on its bound --------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class _Pend:
    mass: float
    length: float
    inertia: float
    damping_coefficient: float = 0.0


@dataclasses.dataclass(frozen=True)
class _Sol:
    power: float
    success: bool = True


def test_a_design_on_its_bound_says_so():
    up = optimize_design(lambda p: _Sol(p.mass), _Pend(2.0, 0.5, 0.5), ["mass"],
                         {"mass": (1.0, 5.0)})
    assert up.best["mass_kg"] == pytest.approx(5.0, rel=1e-3)
    assert up.at_bound == {"mass": "upper"}
    two = optimize_design(lambda p: _Sol(10 - p.length - (p.mass - 3.0) ** 2),
                          _Pend(2.0, 0.5, 0.5), ["mass", "length"],
                          {"mass": (1.0, 5.0), "length": (0.2, 1.0)})
    assert two.at_bound == {"length": "lower"}
    inside = optimize_design(lambda p: _Sol(1 - (p.mass - 3.3) ** 2), _Pend(2.0, 0.5, 0.5),
                             ["mass"], {"mass": (1.0, 5.0)})
    assert inside.at_bound == {}


def test_the_printed_result_names_the_bound(fake_bem):
    from parapend.cli.buoy import _text_result

    r = parapend.buoy(wave_period=1.8)
    d = {"variables": ["mass", "length"], "bounds": {"mass": [20.0, 320.0],
                                                     "length": [0.075, 1.2]},
         "method": "grid", "evaluations": 3, "at_bound": {"mass": "upper"}}
    text = "\n".join(_text_result(dataclasses.replace(r, design=d)))
    assert "design: mass lies on its upper bound 320" in text
    assert "--mass-bounds" in text and "length lies" not in text


# --- the BEM itself ----------------------------------------------------------------------------
@pytest.mark.slow
def test_a_coarse_real_body_same_alone_and_in_sweeps(monkeypatch, tmp_path):
    """A coarse real cylinder (Capytaine; 4 panels across the draft, 16 frequencies): the
    answer alone and in sweeps agrees to 1e-9, and the error estimate comes from two real
    meshes of different panel counts."""
    monkeypatch.setenv("PARAPEND_CACHE", str(tmp_path))
    monkeypatch.setattr(bem, "GEOMETRY_PANELS", 4)
    monkeypatch.setattr(bem, "BODY_FREQUENCIES", 16)
    alone = parapend.buoy(wave_period=1.8, harmonics=8)
    pair = parapend.buoy(wave_period="1.8,2.2", harmonics=8)
    assert pair.power_w[0] == pytest.approx(alone.power_w, rel=1e-9)
    fine = bem.cylinder(0.5, 0.5, omega="body")
    coarse = bem.cylinder(0.5, 0.5, omega="body", refine=1 / bem.COARSE)
    nf, nc = (int(h.description.split(", ")[-1].split()[0]) for h in (fine, coarse))
    assert nc < nf
    from parapend.hydro.coupled import Pendulum

    pend = Pendulum(mass=80.0, length=0.3, inertia=7.2, damping_coefficient=1.0)
    wave = Wave.regular(0.2, 1.8)
    pf = coupled_optimum(fine, pend, wave, harmonics=8).power
    pc = coupled_optimum(coarse, pend, wave, harmonics=8).power
    assert alone.power_w == pytest.approx(pf, rel=1e-9)
    assert alone.mesh_error_w == pytest.approx(abs(pf - pc), rel=1e-9)
    assert alone.mesh_error_w > 0


@pytest.mark.slow
def test_the_default_buoy_same_alone_and_in_sweeps():
    """The default design at 1.8 s (docs/buoy.md): alone, inside 1.8:2.2:2, inside 1.8,2.2
    and inside the docs' 1.2:3:10 sweep, the same power to 1e-9, on one 1026-panel mesh;
    the mesh error estimate is small (below 1 %) but not zero."""
    alone = parapend.buoy()
    assert alone.wave["period_s"] == 1.8
    for text in ("1.8:2.2:2", "1.8,2.2", "1.2:3:10"):
        s = parapend.buoy(wave_period=text)
        i = int(np.argmin(np.abs(s.period_s - 1.8)))
        assert s.power_w[i] == pytest.approx(alone.power_w, rel=1e-9), text
        assert s.body == alone.body
    assert alone.body["description"].endswith("1026 panels")
    assert 1e-5 * alone.power_w < alone.mesh_error_w < 1e-2 * alone.power_w
    assert 1e-5 * alone.power_w < alone.grid_error_w < 3e-2 * alone.power_w
    assert alone.validity_warnings == []
