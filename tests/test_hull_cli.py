"""``parapend buoy --dofs surge,heave,pitch`` (and ``parapend.buoy(dofs=...)``) on a
hydrodynamic dataset: the reference invocation's JSON keys and numbers, rotation against
swinging, ``--dofs heave`` unchanged, and bad input in one line (exit 2)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hull_timedomain import RHO_V, synthetic_hull

from parapend.cli import main
from parapend.hydro.bem import HullHydro, load_hull
from parapend.hydro.hull import hull_search, make_case, radiation_bound

PERIOD = 2 * math.pi / 1.2
PEND = ["--mass", "4000", "--length", "1", "--inertia", "5000", "--damping-coefficient",
        "50", "--pivot-height", "1.5", "--pivot-offset", "1"]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    """The helper's causal synthetic hull (tests/hull_timedomain.py) as a Capytaine NetCDF
    dataset with surge, heave and pitch."""
    from capytaine.io.xarray import save_dataset_as_netcdf

    h = synthetic_hull()
    hull = HullHydro(omega=h["omega_data"], added_mass=h["A"], radiation_damping=h["B"],
                     excitation=h["F"], hydrostatic_stiffness=h["C"], mass=RHO_V,
                     pitch_inertia=float(h["Mh"][2, 2]), description="synthetic hull")
    path = tmp_path_factory.mktemp("hull") / "hull.nc"
    save_dataset_as_netcdf(path, hull.to_dataset())
    return str(path)


def _json(capsys, args):
    assert main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_reference_invocation(dataset, capsys):
    """The invocation the issue's independent reference uses: its keys, and the power
    equal to the kernel's optimum on the dataset read back (the CLI adds nothing), with the
    energy balance closed and the power below the radiation bound."""
    out = _json(capsys, ["buoy", "--dofs", "surge,heave,pitch", "--hydro", dataset, *PEND,
                         "--wave-height", "1", "--wave-period", repr(PERIOD), "--winding",
                         "1", "--json"])
    for key in ("power_w", "one_way_power_w", "energy_balance_residual"):
        assert isinstance(out[key], float), key
    assert out["mode"] == "rotation" and out["winding"] == 1
    assert out["energy_balance_residual"] < 1e-9
    assert 0 < out["power_w"] <= out["radiation_bound_w"]
    from parapend.hydro.coupled import Pendulum, Wave

    hull = load_hull(dataset)
    pend = Pendulum(4000.0, 1.0, 5000.0, 50.0)
    wave = Wave.regular(1.0, PERIOD)

    def make(scale):
        base = make_case(hull, pend, wave, winding=1, pivot=(1.0, 1.5))
        return base if scale == 1 else make_case(
            hull, pend, wave, winding=1, harmonics=scale * base.harmonics,
            hull_harmonics=scale * base.hull_harmonics, pivot=(1.0, 1.5))
    sol = hull_search(make)
    assert out["power_w"] == pytest.approx(sol.power, rel=1e-12)
    assert out["radiation_bound_w"] == pytest.approx(radiation_bound(sol.case)[0], rel=1e-12)


@pytest.mark.slow
def test_modes_side_by_side(dataset, capsys):
    """Without --winding: rotation both ways, swinging and rest, the best named; the text
    names them."""
    out = _json(capsys, ["buoy", "--dofs", "surge,heave,pitch", "--hydro", dataset, *PEND,
                         "--wave-period", repr(PERIOD), "--json"])
    modes = {(m["mode"], m["winding"]): m for m in out["modes"]}
    assert set(modes) == {("rotation", 1), ("rotation", -1), ("swinging", 0), ("rest", None)}
    assert modes["rest", None]["power_w"] == 0.0
    best = max(modes.values(), key=lambda m: m["power_w"])
    assert out["mode"] == best["mode"] and out["power_w"] == best["power_w"]
    assert out["winding"] == best["winding"]
    assert 0.0 <= modes["swinging", 0]["mean_angle_deg"] < 360.0
    assert main(["buoy", "--dofs", "surge,heave,pitch", "--hydro", dataset, *PEND,
                 "--wave-period", repr(PERIOD)]) == 0
    text = capsys.readouterr().out
    assert "rotation, reversed" in text and "swinging" in text and "best mode" in text


def test_dofs_heave_is_the_heaving_buoy(dataset):
    """``dofs="heave"`` is today's command, bit for bit (the same code path)."""
    import parapend

    a = parapend.buoy(hydro=dataset, wave_period=PERIOD, mass=400.0, length=0.5)
    b = parapend.buoy(hydro=dataset, wave_period=PERIOD, mass=400.0, length=0.5,
                      dofs="heave")
    assert a.to_dict() == b.to_dict()


def test_result_protocol(dataset, tmp_path):
    """The hull's result saves as JSON, CSV (with units), NetCDF and a figure."""
    import xarray as xr

    import parapend

    r = parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, wave_period=PERIOD,
                      mass=4000.0, length=1.0, inertia=5000.0, damping_coefficient=50.0,
                      pivot_height=1.5, pivot_offset=1.0, winding=0)
    assert r.mode == "swinging" and "power_w" in repr(r)
    ds = r.to_dataset()
    for name in ds.variables:
        assert ds[name].attrs.get("units") is not None, name
    r.save(tmp_path / "r.nc")
    back = xr.load_dataset(tmp_path / "r.nc")
    assert float(back["power_w"]) == r.power_w
    r.save(tmp_path / "r.csv")
    assert (tmp_path / "r.csv").read_text().splitlines()[1].startswith("s,")
    r.save(tmp_path / "r.png")
    assert (tmp_path / "r.png").stat().st_size > 1000


@pytest.mark.parametrize("args, name", [
    (["--pivot-height", "nan"], "pivot-height"),
    (["--winding", "-17"], "winding"),
    (["--mass", "1e9"], "mass"),
    (["--dofs", "surge,pitch"], "dofs"),
    (["--efficiency", "1.5"], "efficiency"),
    (["--torque-limit", "-1"], "torque-limit"),
    (["--copper-loss", "-1"], "copper-loss"),
    (["--optimize-design", "mass"], "optimize-design"),
    (["--controller", "mpc"], "controller"),
    (["--pivot-height", "40", "--mass", "40000"], "pivot-height"),  # unstable in pitch
])
def test_bad_input_one_line(dataset, capsys, args, name):
    base = ["buoy", "--hydro", dataset, "--wave-period", repr(PERIOD)]
    dofs = [] if "--dofs" in args else ["--dofs", "surge,heave,pitch"]
    assert main(base + dofs + args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "error:" in err and f"{name}:" in err, err


def test_dataset_without_pitch_one_line(tmp_path, capsys):
    from capytaine.io.xarray import save_dataset_as_netcdf

    from parapend.hydro.bem import Hydro

    w = np.linspace(0.2, 6.0, 30)
    heave = Hydro(omega=w, added_mass=1000.0 + 0 * w, radiation_damping=100 * w,
                  excitation=1e4 + 0j * w, hydrostatic_stiffness=1e4, mass=1000.0)
    save_dataset_as_netcdf(tmp_path / "heave.nc", heave.to_dataset())
    assert main(["buoy", "--dofs", "surge,heave,pitch", "--hydro",
                 str(tmp_path / "heave.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "hydro" in err and "pitch" in err.lower(), err


def test_pivot_outside_the_barge_refused_before_the_bem(capsys):
    assert main(["buoy", "--dofs", "surge,heave,pitch", "--pivot-offset", "6"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "error: pivot-offset:" in err, err


@pytest.mark.slow
def test_short_irregular_record(dataset):
    """A 4-wave record (Hs 1 m, Tp 5 s, repeating after 20 s): rotation turns once per
    wave on average (the winding over the record) both ways, then its other turns in the
    better sense; the balance closes, the power lies
    below the radiation bound and the harmonics were refined until it settled."""
    import parapend

    r = parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, hs=1.0, tp=5.0,
                      repeat_period=20.0, mass=4000.0, length=1.0, inertia=5000.0,
                      damping_coefficient=50.0, pivot_height=1.5, pivot_offset=1.0)
    assert r.success, r.status
    windings = [m["winding"] for m in r.modes]
    assert windings[0] >= 3 and windings[1:3] == [-windings[0], 0] and windings[-1] is None
    # the better sense's other turns climbed (searched), none the other sense's
    sense = 1 if max(r.modes[:2], key=lambda m: m["power_w"])["winding"] > 0 else -1
    assert all(m["searched"] and m["winding"] * sense > 0 for m in r.modes[3:-1])
    assert r.energy_balance_residual < 1e-9
    assert 0 < r.power_w <= r.radiation_bound_w
    assert r.refinement_change_w <= 1e-3 * r.power_w
    assert r.surge_phase_deg is None  # phases are of a regular wave's first harmonic


@pytest.mark.slow
def test_torque_limit_and_efficiency_on_the_hull(dataset, capsys):
    """``--torque-limit`` and ``--efficiency`` with the hull: the swinging optimum's peak
    torque (located between samples) within the limit, the electrical headline below the
    mechanical power and below eta_g times the ideal answer, the energy balance closed."""
    base = ["buoy", "--dofs", "surge,heave,pitch", "--hydro", dataset, *PEND,
            "--wave-height", "1", "--wave-period", repr(PERIOD), "--winding", "0", "--json"]
    ideal = _json(capsys, base)
    limit = 0.5 * ideal["peak_torque_nm"]
    out = _json(capsys, base + ["--torque-limit", repr(limit), "--efficiency", "0.9"])
    assert out["success"], out["status"]
    assert out["torque_limit_nm"] == limit and out["efficiency"] == [0.9, 0.9]
    assert out["peak_torque_nm"] <= limit * (1 + 1e-3)
    assert 0 < out["power_w"] <= out["mechanical_power_w"]
    assert out["power_w"] <= 0.9 * ideal["power_w"]
    assert out["energy_balance_residual"] < 1e-9
    assert out["refinement_change_w"] is not None
