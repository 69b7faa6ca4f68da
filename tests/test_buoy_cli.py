"""``parapend buoy`` and ``parapend.buoy``: the command, its input checks, its derived numbers
(capture width, bound fraction) against closed forms, the design search on a known objective,
and the figures.

The hydrodynamics of the fast tests come from a small Capytaine dataset (a coarse floating
sphere, 8 frequencies, written the standard way) brought in with ``--hydro``: a few seconds
of BEM, once per session. The embedded default design (its own BEM) is a slow test.
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
from parapend.hydro.api import parse_periods
from parapend.hydro.design import optimize_design
from parapend.hydro.waves import energy_flux, group_velocity

# the small sphere's design: resonance near 1.3 s
PERIOD = 1.3
PEND = ["--mass", "20", "--length", "0.3", "--damping-coefficient", "0.5", "--harmonics", "8"]


def _capytaine_dataset(path, *, dofs=("Heave",), hydrostatics=True):
    """A coarse floating sphere (radius 0.5 m, centre at the free surface) solved by
    Capytaine over 1..8 rad/s, written with ``save_dataset_as_netcdf``."""
    import capytaine as cpt
    import xarray as xr
    from capytaine.io.xarray import save_dataset_as_netcdf

    mesh = cpt.mesh_sphere(radius=0.5, center=(0, 0, 0), resolution=(8, 8))
    full = cpt.FloatingBody(mesh=mesh, dofs=cpt.rigid_body_dofs(rotation_center=(0, 0, 0)),
                            center_of_mass=(0, 0, 0)).immersed_part()
    # floating at its draft: the mass is the displacement (the immersed mesh is open at
    # the waterline, where the mesh's own volume differs from the displaced one)
    body = cpt.FloatingBody(mesh=full.mesh, dofs={d: full.dofs[d] for d in dofs},
                            center_of_mass=(0, 0, 0), mass=full.disp_mass(rho=1025.0))
    body.inertia_matrix = body.compute_rigid_body_inertia()
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness()
    test = xr.Dataset(coords={"omega": np.linspace(1.0, 8.0, 8), "wave_direction": [0.0],
                              "radiating_dof": list(dofs), "water_depth": [np.inf],
                              "rho": [1025.0]})
    ds = cpt.BEMSolver().fill_dataset(test, body, hydrostatics=hydrostatics)
    if not hydrostatics:
        ds = ds.drop_vars([v for v in ("hydrostatic_stiffness", "inertia_matrix")
                           if v in ds.variables])
    save_dataset_as_netcdf(str(path), ds)
    return str(path)


@pytest.fixture(scope="module")
def solved(sphere_nc):
    return parapend.buoy(hydro=sphere_nc, wave_period=PERIOD, mass=20.0, length=0.3,
                         damping_coefficient=0.5, harmonics=8)


def _fail(argv, capsys, tmp_path, match):
    """One line on stderr naming the problem, exit 2, nothing written."""
    before = set(tmp_path.iterdir())
    assert main(["buoy", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    assert match in err, err
    assert set(tmp_path.iterdir()) == before
    return err


# --- closed forms -----------------------------------------------------------------------------
def test_energy_flux_of_a_regular_wave_in_deep_water():
    rho, g, h, t = 1025.0, 9.81, 1.5, 6.0
    j = energy_flux(2 * math.pi / t, [h / 2], rho, g)
    assert math.isclose(j, rho * g**2 * h**2 * t / (32 * math.pi), rel_tol=1e-13)


def test_group_velocity_deep_and_shallow_limits():
    g = 9.81
    w = 2.0
    assert math.isclose(group_velocity(w, math.inf, g), g / (2 * w), rel_tol=1e-14)
    # deep water reached at finite depth: tanh(kh) = 1 to double precision
    assert math.isclose(group_velocity(w, 1e3, g), g / (2 * w), rel_tol=1e-12)
    # shallow water: c_g -> sqrt(g h)
    h = 1e-3
    assert math.isclose(group_velocity(0.05, h, g), math.sqrt(g * h), rel_tol=1e-5)
    # an intermediate depth against the dispersion relation solved by fixed-point iteration
    h, w = 5.0, 1.2
    k = w * w / g
    for _ in range(500):
        k = w * w / (g * math.tanh(k * h))
    cg = 0.5 * (w / k) * (1 + 2 * k * h / math.sinh(2 * k * h))
    assert math.isclose(group_velocity(w, h, g), cg, rel_tol=1e-10)


def test_period_ranges():
    assert parse_periods(2.0) is None and parse_periods("2") is None
    np.testing.assert_allclose(parse_periods("1:3:5"), [1, 1.5, 2, 2.5, 3])
    for bad in ("1:2", "3:1:4", "1:2:1", "a:b:3", "1:2:3:4"):
        with pytest.raises(ParameterError, match="wave-period"):
            parse_periods(bad)


def test_the_command_is_a_plain_function_beside_its_subpackage():
    """``parapend.buoy`` is commands.buoy, a function like every command, and stays so after
    the subpackage that answers it (``parapend.hydro``) and its modules are imported."""
    import importlib
    import inspect

    from parapend import commands

    importlib.import_module("parapend.hydro.bem")
    importlib.import_module("parapend.hydro.api")
    importlib.import_module("parapend.hydro.design")
    assert parapend.buoy is commands.buoy and inspect.isfunction(parapend.buoy)
    assert parapend.hydro.api.buoy is not None and inspect.ismodule(parapend.hydro)
    assert "buoy" in parapend._COMMANDS


# --- the design search ------------------------------------------------------------------------
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


def test_design_search_finds_a_known_maximum():
    # P(l, I) = 10 - (l - 0.7)^2 - (I - 1.3 m l^2)^2 has its maximum inside the box
    def solve(p):
        return _Sol(10 - (p.length - 0.7) ** 2 - (p.inertia - 1.3 * p.mass * p.length**2) ** 2)

    found = optimize_design(solve, _Pend(2.0, 0.5, 0.5), ["length", "inertia"],
                            {"length": (0.2, 1.5), "inertia": (0.05, 3.0)})
    assert math.isclose(found.best["length_m"], 0.7, abs_tol=2e-3)
    assert math.isclose(found.best["inertia_kg_m2"], 1.3 * 2 * 0.49, abs_tol=5e-3)
    assert found.power_w >= found.grid_best_w and found.power_w > 10 - 1e-5
    one = optimize_design(lambda p: _Sol(1 - (p.mass - 3.3) ** 2), _Pend(2.0, 0.5, 0.5),
                          ["mass"], {"mass": (1.0, 5.0)})
    assert math.isclose(one.best["mass_kg"], 3.3, abs_tol=1e-3)
    # the pendulum keeps its shape (I / m l^2) when only the mass changes
    assert math.isclose(one.best["inertia_kg_m2"] / (3.3 * 0.25), 0.5 / (2 * 0.25), rel_tol=1e-3)


def test_design_search_respects_the_physical_pendulum():
    # the objective wants I small: the design ends at the point mass, I = m l^2
    found = optimize_design(lambda p: _Sol(5 - p.inertia), _Pend(2.0, 1.0, 2.0), ["inertia"],
                            {"inertia": (0.1, 4.0)})
    assert math.isclose(found.best["inertia_kg_m2"], 2.0, rel_tol=1e-12)
    with pytest.raises(ParameterError, match="no design"):
        optimize_design(lambda p: _Sol(-1.0), _Pend(2.0, 1.0, 2.0), ["mass"],
                        {"mass": (1.0, 3.0)})


# --- end to end through --hydro -----------------------------------------------------------------
def test_result_numbers_against_their_definitions(solved):
    r = solved
    assert r.success and r.power_w > 0
    assert r.energy_balance_residual < 1e-9
    assert 0 < r.power_w <= r.radiation_bound_w * (1 + 1e-9)
    assert r.power_w <= r.limit_w * (1 + 1e-9)
    assert math.isclose(r.bound_fraction, r.power_w / r.radiation_bound_w, rel_tol=1e-14)
    height = r.wave["height_m"]
    j = 1025.0 * 9.81**2 * height**2 * PERIOD / (32 * math.pi)
    assert math.isclose(r.energy_flux_w_per_m, j, rel_tol=1e-9)
    assert math.isclose(r.capture_width_m * j, r.power_w, rel_tol=1e-9)
    assert r.capture_width_ratio is None  # a dataset: the width is not known
    assert r.one_way_power_w is not None and r.one_way_power_w > 0
    # the free buoy's heave against its closed form |F a / D|
    h = r._hydro
    w = 2 * math.pi / PERIOD
    assert math.isclose(r.free_heave_amplitude_m, abs(h.free_response(w)) * height / 2,
                        rel_tol=1e-4)
    s = r.samples(256)
    assert math.isclose(np.mean(s["power"][:-1]), r.power_w, rel_tol=1e-6,
                        abs_tol=1e-9 * r.radiation_bound_w)
    assert math.isclose(r.peak_torque_nm, np.max(np.abs(s["tau"])), rel_tol=1e-2)


@pytest.mark.slow
def test_cli_json_plot_and_save(sphere_nc, tmp_path, capsys, solved):
    import xarray as xr
    from figure_checks import all_problems

    out = tmp_path / "figs"
    nc = tmp_path / "motion.nc"
    argv = ["buoy", "--hydro", sphere_nc, "--wave-period", str(PERIOD), *PEND,
            "--plot", str(out), "--save", str(nc), "--json"]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    for key in ("power_w", "heave_amplitude_m", "peak_torque_nm", "radiation_bound_w",
                "bound_fraction", "capture_width_m", "capture_width_ratio", "one_way_power_w",
                "free_heave_amplitude_m", "limit_w", "energy_balance_residual", "harmonics",
                "success", "status"):
        assert key in d, key
    # the command is the function: the same computation, the same fields
    from parapend.results import to_jsonable

    assert d == json.loads(json.dumps(to_jsonable(solved.to_dict())))
    assert sorted(p.name for p in out.iterdir()) == ["buoy_motion.png", "buoy_motion.svg"]
    with xr.open_dataset(nc) as ds:
        assert set(ds.data_vars) >= {"theta", "heave_m", "torque_nm", "power_w",
                                     "free_heave_m"}
        assert math.isclose(float(ds["power_w"]), solved.power_w, rel_tol=1e-12)
    from parapend.hydro.figures import plot_motion

    assert not all_problems(plot_motion(solved), si=True)
    assert main(["buoy", "--hydro", sphere_nc, "--wave-period", str(PERIOD), *PEND]) == 0
    text = capsys.readouterr().out
    assert "coupled optimum: power" in text and "radiation bound" in text


@pytest.mark.slow
def test_power_against_wave_period(sphere_nc, tmp_path, capsys):
    from figure_checks import all_problems

    from parapend.hydro.figures import plot_sweep

    r = parapend.buoy(hydro=sphere_nc, wave_period="1.1:1.5:3", mass=20.0, length=0.3,
                      damping_coefficient=0.5, harmonics=8)
    assert r.period_s.shape == r.power_w.shape == r.radiation_bound_w.shape == (3,)
    assert np.all(r.power_w <= r.radiation_bound_w * (1 + 1e-9))
    assert np.all(r.energy_balance_residual < 1e-9)
    assert not all_problems(plot_sweep(r), si=True)
    assert main(["buoy", "--hydro", sphere_nc, "--wave-period", "1.1:1.5:3", *PEND,
                 "--save", str(tmp_path / "sweep.nc")]) == 0
    assert "one-way (W)" in capsys.readouterr().out


# --- input checks: one line, exit 2, nothing written ------------------------------------------
@pytest.mark.parametrize("argv, match", [
    (["--mass", "-1"], "mass"),
    (["--mass", "20", "--length", "0.3", "--inertia", "1.0"], "inertia: expected at least"),
    (["--wave-period", "1:2"], "wave-period"),
    (["--wave-period", "0.1"], "wave-period: the waves are too short for the body's mesh"),
    (["--optimize-design", "colour"], "optimize-design"),
    (["--length-bounds", "0.2:2"], "only used with --optimize-design"),
    (["--hs", "0.5", "--wave-height", "1"], "not both"),
])
def test_bad_pendulum_and_options(argv, match, capsys, tmp_path):
    _fail([*argv, "--save", str(tmp_path / "x.nc"), "--plot", str(tmp_path / "figs")],
          capsys, tmp_path, match)


def test_bad_input_with_a_dataset(sphere_nc, capsys, tmp_path):
    save = ["--save", str(tmp_path / "x.nc"), "--plot", str(tmp_path / "figs")]
    # a wave outside the dataset's frequencies (1 to 8 rad/s), low enough not to break
    _fail(["--hydro", sphere_nc, "--wave-period", "0.5", "--wave-height", "0.01", *PEND,
           *save], capsys, tmp_path, "wave-period")
    # a pendulum heavier than the floating body
    _fail(["--hydro", sphere_nc, "--wave-period", str(PERIOD), "--mass", "1000", *save],
          capsys, tmp_path, "floating mass")
    # damping that takes more than the wave gives: the pendulum cannot rotate
    err = _fail(["--hydro", sphere_nc, "--wave-period", str(PERIOD), "--mass", "20",
                 "--length", "0.3", "--damping-coefficient", "5000", *save], capsys, tmp_path,
                "cannot rotate")
    assert err.startswith("parapend buoy: error: damping-coefficient")
    _fail(["--hydro", sphere_nc, "--radius", "1", *save], capsys, tmp_path, "radius")
    # an efficiency outside (0, 1]: one line says so
    _fail(["--hydro", sphere_nc, "--wave-period", str(PERIOD), *PEND, "--efficiency", "1.1",
           *save], capsys, tmp_path, "efficiency")
    # the design search needs a design variable for its bounds, and one wave period
    _fail(["--hydro", sphere_nc, "--wave-period", "1.1:1.5:3", "--optimize-design", "length",
           *save], capsys, tmp_path, "one wave period")


def test_datasets_without_heave_or_hydrostatics(tmp_path_factory, capsys, tmp_path):
    d = tmp_path_factory.mktemp("bad")
    surge = _capytaine_dataset(d / "surge.nc", dofs=("Surge",))
    _fail(["--hydro", surge, "--wave-period", str(PERIOD), *PEND], capsys, tmp_path, "heave")
    bare = _capytaine_dataset(d / "bare.nc", hydrostatics=False)
    _fail(["--hydro", bare, "--wave-period", str(PERIOD), *PEND], capsys, tmp_path, "hydro")


def _gdf(path, quads):
    """A WAMIT .gdf mesh file of the given quadrilaterals."""
    lines = ["open surface", "1.0 9.81", "0 0", str(len(quads))]
    for q in quads:
        lines += [" ".join(f"{c:g}" for c in v) for v in q]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_meshes_not_closed_or_not_immersed(tmp_path_factory, capsys, tmp_path):
    d = tmp_path_factory.mktemp("mesh")
    # a flat square under the surface: no volume, not closed
    flat = _gdf(d / "flat.gdf", [[(-0.5, -0.5, -0.5), (0.5, -0.5, -0.5), (0.5, 0.5, -0.5),
                                   (-0.5, 0.5, -0.5)]])
    _fail(["--mesh", flat, "--wave-period", "2"], capsys, tmp_path, "mesh")
    # a closed box entirely above the water
    z0, z1 = 1.0, 2.0
    c = [(x, y, z) for z in (z0, z1) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    box = _gdf(d / "box.gdf", [[c[i] for i in f] for f in faces])
    _fail(["--mesh", box, "--wave-period", "2"], capsys, tmp_path, "mesh")


# --- the embedded default ---------------------------------------------------------------------
@pytest.mark.slow
def test_the_default_design_says_something(capsys):
    """``parapend buoy`` with no options: the coupling matters (one-way and coupled differ by
    more than 10 %), the optimum is positive, resolved and below the bound."""
    r = parapend.buoy()
    assert r.success and r.power_w > 0
    assert r.energy_balance_residual < 1e-9
    assert r.power_w <= r.radiation_bound_w
    assert abs(r.one_way_power_w / r.power_w - 1) > 0.10
    assert r.capture_width_ratio is not None and r.capture_width_ratio > 0
    assert main(["buoy"]) == 0
    assert "coupled optimum: power" in capsys.readouterr().out


@pytest.mark.slow
def test_an_irregular_record(sphere_nc):
    """A periodic JONSWAP record of four waves, the pendulum turning once per wave."""
    r = parapend.buoy(hydro=sphere_nc, hs=0.1, tp=1.5, repeat_period=6.0, cutoff=1.8,
                      winding=4, mass=20.0, length=0.3, damping_coefficient=0.1, harmonics=32)
    assert r.wave["kind"] == "irregular" and r.winding == 4
    assert r.success and r.power_w > 0
    assert r.energy_balance_residual < 1e-9
    assert r.power_w <= r.limit_w * (1 + 1e-9) <= r.radiation_bound_w * (1 + 1e-9)
    assert math.isclose(r.capture_width_m * r.energy_flux_w_per_m, r.power_w, rel_tol=1e-12)
