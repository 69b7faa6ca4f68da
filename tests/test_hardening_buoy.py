"""The buoy, hardened: every bad input ends in one line naming the option
(exit 2; ``ParameterError`` from Python), datasets are checked as physics, and the sizes
that ran for minutes or past 2 GB are refused before any work."""

from __future__ import annotations

import os
from decimal import Decimal

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro import bem
from tests.buoy_synthetic import toy_hydro


def _refused(capsys, *args, names):
    code = main(["buoy", *args])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "\n" not in err and "Traceback" not in err
    assert any(f"error: {n}:" in err for n in names), err
    return err


@pytest.mark.parametrize("args, names", [
    (["--torque-limit", "5e-324"], ["torque-limit"]),
    (["--torque-limit", "1e-300"], ["torque-limit"]),
    (["--torque-limit", "1e-6"], ["torque-limit"]),
    (["--radius", "5e-324"], ["radius"]),
    (["--radius", "1e-300"], ["radius"]),
    (["--radius", "1e300"], ["radius"]),
    (["--draft", "5e-324"], ["draft"]),
    (["--draft", "1e-300"], ["draft"]),
    (["--draft", "1e300"], ["draft"]),
    (["--draft", "100"], ["draft"]),
    (["--draft", "1000"], ["draft"]),
    (["--efficiency", "5e-324"], ["efficiency"]),
    (["--efficiency", "0.9,1e-310"], ["efficiency"]),
    (["--efficiency", "1e-300"], ["efficiency"]),
    (["--mass", "5e-324"], ["mass"]),
    (["--mass", "1e-300"], ["mass"]),
    (["--length", "1e300"], ["length"]),
    (["--length", "5e-324"], ["length"]),
    (["--horizon", "2"], ["horizon"]),
    (["--update-interval", "0.2"], ["update-interval"]),
    (["--forecast", "ar"], ["forecast"]),
    (["--controller", "one-way-mpc", "--hs", "0.5", "--tp", "2.5", "--forecast", "ar"],
     ["forecast"]),
    (["--taper", "0.2"], ["taper"]),
    (["--spectrum", "jonswap"], ["spectrum"]),
    (["--gamma-peak", "2"], ["gamma-peak"]),
    (["--cutoff", "2"], ["cutoff"]),
    (["--wave-direction", "1"], ["wave-direction"]),
    (["--hydro", "/dev/zero"], ["hydro"]),
    (["--hydro", "/"], ["hydro"]),
    (["--mesh", "/dev/zero"], ["mesh"]),
    (["--mesh", "/"], ["mesh"]),
    (["--wave-period", "1.2:3:200", "--harmonics", "40960"], ["harmonics"]),
])
def test_refused_in_one_line(capsys, args, names):
    _refused(capsys, *args, names=names)


def test_messages_name_the_option_given(capsys):
    assert "inertia" not in _refused(capsys, "--mass", "5e-324", names=["mass"])
    assert "gamma:" not in _refused(capsys, "--mass", "1e-300", names=["mass"])
    err = _refused(capsys, "--draft", "100", names=["draft"])
    assert "NaN" not in err and "at most" in err


def test_fifo_refused_without_blocking(tmp_path, capsys):
    fifo = tmp_path / "pipe.nc"
    os.mkfifo(fifo)
    assert "FIFO" in _refused(capsys, "--hydro", str(fifo), names=["hydro"])
    assert "FIFO" in _refused(capsys, "--mesh", str(fifo), names=["mesh"])


def test_sparse_file_refused_before_reading(tmp_path, capsys):
    big = tmp_path / "big.stl"
    with open(big, "wb") as fh:
        fh.truncate(3 << 30)
    assert "MiB" in _refused(capsys, "--mesh", str(big), names=["mesh"])


def test_body_with_hydro_refused(tmp_path, capsys):
    path = tmp_path / "toy.nc"
    path.write_bytes(b"x")
    _refused(capsys, "--body", "sphere", "--hydro", str(path), names=["body"])
    with pytest.raises(ParameterError, match="^body:"):
        parapend.buoy(body="sphere", hydro=toy_hydro().to_dataset())


# --- datasets as physics -------------------------------------------------------------------
def _ds(**change):
    ds = toy_hydro(radius=1.0).to_dataset()
    for k, v in change.items():
        ds[k] = v(ds[k])
    return ds


def test_dataset_accepted_as_xarray():
    r = parapend.buoy(hydro=_ds(), damping_coefficient=0.0)
    assert r.status.startswith("coupled optimum: converged")
    assert 0 < r.power_w <= r.radiation_bound_w * (1 + 1e-9)


@pytest.mark.parametrize("change, match", [
    (lambda b: -b, "nowhere positive"),
    (lambda b: 0 * b, "nowhere positive"),
])
def test_negated_or_zero_damping_refused(change, match):
    with pytest.raises(ParameterError, match=f"^hydro: .*{match}"):
        parapend.buoy(hydro=_ds(radiation_damping=change))


def test_damping_negative_beyond_noise_refused():
    def dip(b):
        b = b.copy()
        b[10] = -0.5 * float(b.max())
        return b
    with pytest.raises(ParameterError, match="^hydro: .*negative at 1 of"):
        bem.load(_ds(radiation_damping=dip))


def test_slightly_negative_damping_zeroed_and_named():
    ds = _ds()
    w = ds["omega"].values
    b = ds["radiation_damping"].values.copy()
    b[0] = -1e-6 * b.max()  # the lowest frequency: B -> 0 there, noise
    ds["radiation_damping"] = (ds["radiation_damping"].dims, b)
    h = bem.load(ds)
    assert h.omega.size == w.size and h.radiation_damping[0] == 0.0
    assert any("set to 0 at 1 frequencies" in n and f"{w[0]:.4g}" in n for n in h.notes)


def test_string_mass_refused():
    ds = _ds()
    ds["inertia_matrix"] = ds["inertia_matrix"].astype(str)
    with pytest.raises(ParameterError, match="^hydro: .*inertia_matrix is not numeric"):
        bem.load(ds)


def _multi(directions=(0.0, np.pi / 2), dofs=("Heave", "Pitch"), asym=0.0):
    """A two-DOF, two-direction dataset whose heave part is the toy's."""
    import xarray as xr

    h = toy_hydro(radius=1.0)
    n = h.omega.size
    a = np.zeros((n, 2, 2))
    b = np.zeros((n, 2, 2))
    a[:, 0, 0], b[:, 0, 0] = h.added_mass, h.radiation_damping
    a[:, 1, 1], b[:, 1, 1] = 2 * h.added_mass, 2 * h.radiation_damping
    a[:, 0, 1] = a[:, 1, 0] = 0.1 * h.added_mass
    b[:, 0, 1] = b[:, 1, 0] = 0.1 * h.radiation_damping
    a[:, 0, 1] *= 1 + asym
    f = np.zeros((n, len(directions), 2), complex)
    for j, _ in enumerate(directions):
        f[:, j, 0] = np.conj(h.excitation) * (1 + j)
    return xr.Dataset(
        {"added_mass": (("omega", "radiating_dof", "influenced_dof"), a),
         "radiation_damping": (("omega", "radiating_dof", "influenced_dof"), b),
         "excitation_force": (("omega", "wave_direction", "influenced_dof"), f),
         "hydrostatic_stiffness": (("influenced_dof", "radiating_dof"),
                                   [[h.hydrostatic_stiffness, 0], [0, 1.0]]),
         "inertia_matrix": (("influenced_dof", "radiating_dof"), [[h.mass, 0], [0, 1.0]])},
        coords={"omega": h.omega, "radiating_dof": list(dofs), "influenced_dof": list(dofs),
                "wave_direction": list(directions), "rho": 1025.0, "g": 9.81,
                "water_depth": np.inf})


def test_wave_direction_chosen():
    h0 = toy_hydro(radius=1.0)
    h = bem.load(_multi())
    np.testing.assert_allclose(h.excitation, h0.excitation, rtol=1e-12)
    h2 = bem.load(_multi(), wave_direction=np.pi / 2)
    np.testing.assert_allclose(h2.excitation, 2 * h0.excitation, rtol=1e-12)
    with pytest.raises(ParameterError, match="^wave-direction: .*choose one of"):
        bem.load(_multi(), wave_direction=1.0)


def test_asymmetry_symmetrised_or_refused():
    h = bem.load(_multi(asym=1e-4))
    assert any("symmetrised" in n for n in h.notes)
    r = parapend.buoy(hydro=_multi(asym=1e-4))
    assert any("symmetrised" in n for n in r.warnings)
    with pytest.raises(ParameterError, match="^hydro: .*not symmetric"):
        bem.load(_multi(asym=0.5))


def test_hydro_of_wrong_type_refused():
    with pytest.raises(ParameterError, match="^hydro:"):
        bem.load(42)


@pytest.mark.parametrize("value", [Decimal("0.9"), np.float32(0.9), 0.9])
def test_decimal_efficiency_accepted(value):
    from parapend.hydro.pto import efficiency_pair

    assert efficiency_pair(value) == pytest.approx((0.9, 0.9))


def test_negative_heaving_mass_refused():
    ds = _ds()
    m = float(ds["inertia_matrix"].values.ravel()[0])
    ds["added_mass"] = ds["added_mass"] * 0 - 2 * m
    with pytest.raises(ParameterError, match=r"^hydro: .*M \+ A <= 0"):
        bem.load(ds)


@pytest.mark.slow  # a real solve of the default body: about 9 s
def test_zero_excitation_blames_the_wave_not_the_damping(capsys, tmp_path):
    ds = _ds(excitation_force=lambda f: 0 * f)
    path = tmp_path / "calm.nc"
    from capytaine.io.xarray import save_dataset_as_netcdf

    save_dataset_as_netcdf(path, ds)
    err = _refused(capsys, "--hydro", str(path), "--damping-coefficient", "0",
                   names=["wave"])
    assert "damping" not in err.split(":")[0]


def test_low_torque_limit_blames_the_limit():
    from parapend.hydro.result import _message

    class _P:
        mass, length, damping_coefficient = 80.0, 0.3, 1.0

    msg = _message(None, -1.0, _P(), bound=10.0, torque_limit=1e-3)
    assert msg.startswith("torque-limit:")


@pytest.mark.parametrize("args, names", [
    (["--harmonics", "4096"], ["harmonics"]),
    (["--harmonics", "4096", "--efficiency", "0.9"], ["harmonics"]),
    (["--harmonics", "1024"], ["harmonics"]),
    (["--harmonics", "48", "--torque-limit", "10"], ["harmonics"]),
    (["--winding", "64"], ["winding"]),
    (["--winding", "2", "--efficiency", "0.9"], ["winding"]),
    (["--wave-period", "1.2:3:200", "--harmonics", "4096"], ["harmonics"]),
    (["--wave-period", "1.2:3:200", "--harmonics", "512"], ["wave-period"]),
    (["--wave-period", "1.2:3:200", "--harmonics", "409"], ["wave-period"]),
    (["--wave-period", "1.2:3:200"], ["wave-period"]),
    (["--wave-period", "1.2:3:4", "--efficiency", "0.9"], ["wave-period"]),
    (["--wave-period", "1.2:3:4", "--torque-limit", "100"], ["wave-period"]),
    (["--wave-period", "1.2:3:4", "--harmonics", "512"], ["wave-period"]),
])
def test_sizes_refused_before_work(capsys, args, names):
    err = _refused(capsys, *args, names=names)
    assert "at most" in err


def test_sweep_estimate():
    """The sweep's estimate: the periods times one period's time, within
    BUOY_MAX_SWEEP_SECONDS; the message names the most periods that fit, and that many
    pass."""
    import re

    from parapend.hydro.api import _check_sweep

    for harmonics, pto in ((None, False), (128, False), (512, False), (None, True)):
        with pytest.raises(ParameterError, match=r"^wave-period: 200 periods") as got:
            _check_sweep(200, harmonics, 1, pto)
        assert "\n" not in str(got.value)
        most = re.search(r"at most (\d+) periods", str(got.value))
        if most is None:  # one period at a time
            assert "one period at a time" in str(got.value)
            continue
        _check_sweep(int(most.group(1)), harmonics, 1, pto)
        with pytest.raises(ParameterError):
            _check_sweep(int(most.group(1)) + 1, harmonics, 1, pto)
    _check_sweep(10, None, 1, False)  # docs/buoy.md's 1.2:3:10


def test_long_mpc_record_refused_before_work(capsys):
    err = _refused(capsys, "--hs", "2", "--tp", "5", "--repeat-period", "1000", "--controller",
                   "mpc", names=["repeat-period"])
    assert "at most" in err


@pytest.mark.parametrize("args, names", [
    (["--hs", "2", "--tp", "8", "--repeat-period", "1000", "--winding", "64", "--efficiency",
      "0.9"], ["repeat-period", "winding"]),
    (["--hs", "2", "--tp", "8", "--repeat-period", "256", "--efficiency", "0.9"],
     ["repeat-period"]),
    (["--hs", "2", "--tp", "8", "--repeat-period", "40", "--efficiency", "0.9", "--harmonics",
      "512"], ["harmonics"]),
    # without a take-off: 7904 and 5056 harmonics by default (the 250 s default record's
    # 1976 took 79 s, a 1000 s record ran past 150 s)
    (["--hs", "0.5", "--tp", "2.5", "--repeat-period", "1000"], ["repeat-period"]),
    (["--hs", "0.5", "--tp", "2.5", "--repeat-period", "640"], ["repeat-period"]),
])
def test_record_with_take_off_refused_before_work(capsys, args, names):
    assert "at most" in _refused(capsys, *args, names=names)


@pytest.mark.slow  # about 7 s: meshing and reading 6400 panels
def test_mesh_of_too_many_panels_refused_before_the_bem(tmp_path):
    import capytaine as cpt

    from tests.test_buoy_hydro import _gdf

    # 2 x 40 x 40 = 3200 panels below the waterline, more than the cap (limits.py)
    mesh = cpt.mesh_vertical_cylinder(length=1.0, radius=0.5, center=(0, 0, 0),
                                      resolution=(20, 80, 40))
    with pytest.raises(ParameterError, match=r"^mesh: .* immersed panels; .* at most 1500"):
        bem.from_mesh(_gdf(tmp_path / "fine.gdf", mesh), omega="body")


@pytest.mark.parametrize("kw, name", [
    (dict(hydro=42), "hydro"), (dict(mass="x"), "mass"), (dict(horizon=2), "horizon"),
    (dict(efficiency=[0.9, "a"]), "efficiency"), (dict(torque_limit="1"), "torque-limit"),
    (dict(radius=[1]), "radius"), (dict(efficiency=Decimal("0.9"), harmonics=100),
                                   "harmonics"),
    # a bare ValueError or TypeError before
    (dict(body=np.array([1.0, 2.0])), "body"), (dict(controller=np.array([1.0])), "controller"),
    (dict(dofs=1.0), "dofs"), (dict(optimize_design=0), "optimize-design"),
    (dict(mesh=1.0), "mesh"), (dict(mesh=["a.gdf"]), "mesh"),
    (dict(wave_period="1.2:3:200", harmonics=512), "wave-period"),
])
def test_api_raises_parameter_error(kw, name):
    with pytest.raises(ParameterError, match=f"^{name}:"):
        parapend.buoy(**kw)


def test_out_of_memory_names_options_of_buoy(monkeypatch, capsys):
    import parapend.cli.buoy as cb

    def boom(a, **kw):
        raise MemoryError

    monkeypatch.setattr(cb, "_run", boom)
    assert main(["buoy"]) == 1
    err = capsys.readouterr().err.strip()
    assert "out of memory" in err and "--points" not in err and "\n" not in err


def test_small_torque_limit_is_the_constant_brake():
    """A limit far below the ideal peak torque (1 N m against 279 N m; ``buoy
    --torque-limit 1`` stalled for minutes at 3.434 W): the rotation under ``T = -T_max``,
    whose torque on a dense grid is ``-T_max`` at every instant and which never turns back,
    so its power is the bound ``T_max K omega`` of every such rotation (closed form; the
    power itself is computed from the motion's torque on the fine grid)."""
    import math

    from parapend.hydro.coupled import Pendulum, Wave
    from parapend.hydro.optimum import (
        BALANCE_TOL,
        _grid_motion,
        _heave_and_balance,
        coupled_optimum,
    )

    h = toy_hydro(radius=0.5)
    p = Pendulum(80.0, 0.3, 7.2, 1.0)
    wave = Wave.regular(0.2, 1.8)
    lim = 1.0
    r = coupled_optimum(h, p, wave, torque_limit=lim)
    assert r.success and "constant brake" in r.status, r.status
    # the closed form: the brake extracts T_max <theta'> = T_max K omega exactly
    assert r.power == pytest.approx(lim * 2 * math.pi / 1.8, rel=1e-9)
    assert r.power < coupled_optimum(h, p, wave).power
    x = r.theta_coefficients["x"]
    m = 8192
    _, _, _, tau = _heave_and_balance(h, p, wave, x, 1, m, True, torque=True)
    assert np.max(np.abs(tau + lim)) <= 1e-6 * lim
    assert np.min(_grid_motion(x, 1, m)[1]) > 0
    assert r.energy_balance_residual <= BALANCE_TOL


@pytest.mark.slow  # the default body's BEM and four solves: about 10 s
def test_torque_limit_one_newton_metre_takes_seconds(capsys):
    """``buoy --torque-limit 1`` at the defaults: the constant brake, converged, its power
    ``2 pi / 1.8`` W (T_max K omega)."""
    import json
    import math

    assert main(["buoy", "--torque-limit", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["success"], out["status"]
    assert out["power_w"] == pytest.approx(2 * math.pi / 1.8, rel=1e-9)


@pytest.mark.parametrize("change, match", [
    (lambda d: d.assign_coords(rho=1e-300), "expected rho in"),
    (lambda d: d.assign_coords(rho=1e300), "expected rho in"),
    (lambda d: d.assign_coords(rho=1e-3), "expected rho in"),
    (lambda d: d.assign_coords(g=1e-300), "expected g in"),
    (lambda d: d.assign_coords(water_depth=1e-300), "water_depth"),
    (lambda d: d.assign_coords(water_depth=1e-3), "water_depth"),
    (lambda d: d.assign(excitation_force=d["excitation_force"] * 1e300), "excitation_force "
                                                                           "reaches"),
    (lambda d: d.assign(radiation_damping=d["radiation_damping"] * 1e300), "radiation_damping "
                                                                            "reaches"),
    (lambda d: d.assign(inertia_matrix=d["inertia_matrix"] * 1e300), "mass reaches"),
])
def test_dataset_scales_out_of_reach_refused(change, match):
    """A dataset's rho of 1e-300 gave a capture width of -1e302 m, a depth of 1e-300 one of
    -5e148 m, a g of 1e-300 blamed ``gamma``, an excitation of 1e300 N/m an infinite
    radiation bound: each is refused in one line naming the dataset's variable."""
    with pytest.raises(ParameterError, match=f"^hydro: .*{match}") as got:
        bem.load(change(_ds()))
    assert "\n" not in str(got.value)


def test_dataset_scales_in_reach_accepted():
    d = _ds().assign_coords(rho=1000.0, g=9.8, water_depth=0.5)
    h = bem.load(d)
    assert (h.rho, h.g, h.water_depth) == (1000.0, 9.8, 0.5)


@pytest.mark.parametrize("args", [
    ["--optimize-design", "mass,length", "--efficiency", "0.9"],
    ["--optimize-design", "mass,length,inertia,damping-coefficient", "--torque-limit", "100"],
])
def test_design_search_refused_before_work(capsys, args):
    """A design search whose solves cannot finish in two minutes without a time limit (one
    variable with an efficiency: about 5 minutes, four about 40) is refused before any
    solve, naming what fits and --time-limit (docs/limits-of-input.md)."""
    err = _refused(capsys, *args, names=["optimize-design"])
    assert "drop --efficiency and --torque-limit from the search" in err
    assert "--time-limit SECONDS" in err


@pytest.mark.parametrize("names", [["length"], ["mass", "length", "inertia",
                                                 "damping_coefficient"]])
def test_design_search_reports_progress(names):
    """The search calls ``progress(done, total)`` after each solve, never past its estimate
    (design_solves, what buoy checks), and ends at ``(total, total)``."""
    from types import SimpleNamespace

    from parapend.hydro.coupled import Pendulum
    from parapend.hydro.design import design_solves, optimize_design

    def solve(p):  # a smooth power with one maximum inside the box
        power = 10 - (p.length - 0.4) ** 2 - (p.mass - 90) ** 2 / 1e3
        return SimpleNamespace(power=power, success=True, electrical_power=None)

    calls = []
    pend = Pendulum(80.0, 0.3, 7.2, 1.0)
    bounds = {"mass": (40.0, 160.0), "length": (0.1, 0.8), "inertia": (7.2, 20.0),
              "damping_coefficient": (0.0, 5.0)}
    found = optimize_design(solve, pend, names, {n: bounds[n] for n in names},
                            progress=lambda d, t: calls.append((d, t)))
    total = design_solves(len(names))
    assert calls[-1] == (total, total)
    assert all(t == total and 0 <= d <= total for d, t in calls)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert found.evaluations <= total
    assert found.best["length_m"] == pytest.approx(0.4, abs=1e-2)


def test_large_gdf_mesh_refused_before_capytaine_reads_it(tmp_path, monkeypatch):
    """A GDF mesh whose panels wholly below the waterline exceed the cap is refused from its
    own numbers (Capytaine's reader took 25 s for 40 000 panels): Capytaine is not called."""
    from parapend import limits

    n = limits.BUOY_MAX_MESH_PANELS + 1
    quad = np.array([[0, 0, -1], [1, 0, -1], [1, 1, -1], [0, 1, -1]], dtype=float)
    rows = "\n".join(" ".join(f"{x:g}" for x in v) for _ in range(n) for v in quad)
    path = tmp_path / "many.gdf"
    path.write_text(f"test\n1.0 9.81\n0 0\n{n}\n{rows}\n")

    def unread(*a, **k):
        raise AssertionError("Capytaine read the mesh")

    monkeypatch.setattr(bem, "_quiet_capytaine", unread)
    with pytest.raises(ParameterError, match=rf"^mesh: .* at least {n} immersed panels; .* "
                                             rf"at most {n - 1}") as got:
        bem.from_mesh(path, omega="body")
    assert "\n" not in str(got.value)
    # panels above the waterline do not count; a count the numbers contradict is left to
    # Capytaine
    for text in (f"test\n1.0 9.81\n0 0\n{n}\n{rows.replace('-1', '1')}\n",
                 f"test\n1.0 9.81\n0 0\n{n + 5}\n{rows}\n"):
        path.write_text(text)
        with pytest.raises(AssertionError, match="Capytaine read"):
            bem.from_mesh(path, omega="body")


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs /proc")
def test_plot_into_proc_refused_before_the_work(capsys):
    """``--plot /proc/x``: /proc passes access() for root but takes no new directory: the
    probe refuses it in one line before any solve (it failed with exit 1 after the work)."""
    assert main(["buoy", "--plot", "/proc/x", "--torque-limit", "10"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "plot:" in err[0]


def test_a_long_design_search_announces_its_estimate(caplog):
    """Three variables fit the cap but take over a minute, four run under a time limit: the
    estimate is logged first (the CLI prints the logger ``parapend.hydro`` on stderr), where
    a short search stays silent."""
    import logging

    from parapend.hydro.api import _check_design

    with caplog.at_level(logging.INFO, logger="parapend.hydro"):
        _check_design(1, False)
        assert not caplog.records
        _check_design(3, False)
        _check_design(4, False, time_limit=60.0)
    assert len(caplog.records) == 2
    assert "optimize-design over 3 variables" in caplog.records[0].getMessage()
    assert "stopped after the time limit 60 s" in caplog.records[1].getMessage()
