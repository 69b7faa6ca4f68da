"""The uncontrolled pendulum (paper Eq. 1) from the command line, the compiled
basin kernel, and stability by continuation against direct simulation."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from parapend.cli import main
from parapend.dynamics import (
    basin_map,
    periodic_orbit,
    rotation_boundaries,
    rotation_boundaries_at,
    simulate,
)

COEX = (0.1, 0.8, 2.1)


def _run(capsys, *args):
    code = main(list(args))
    out = capsys.readouterr()
    return code, out.out, out.err


# --- the compiled kernel ---------------------------------------------------------------
@pytest.mark.slow
def test_numba_kernel_labels_equal_numpy_engine():
    # 48 x 25 points integrated (> 1024: the pilot and capture are used by both engines)
    kw = dict(n_phi=48, n_dphi=48, periods=300)
    a = basin_map(*COEX, engine="numba", **kw)
    b = basin_map(*COEX, engine="numpy", **kw)
    assert list(a["name"].values) == list(b["name"].values)
    np.testing.assert_array_equal(a["attractor"].values, b["attractor"].values)
    np.testing.assert_array_equal(a["phase"].values, b["phase"].values)
    np.testing.assert_allclose(a["basin_fraction"].values, b["basin_fraction"].values,
                               atol=1e-3)
    np.testing.assert_allclose(a["poincare_phi"].values, b["poincare_phi"].values, atol=1e-5)
    assert json.loads(a.attrs["stats"])["verified"] == 3


@pytest.mark.slow  # several seconds; the default run stays within its budget
def test_numba_kernel_without_capture_and_without_symmetry():
    kw = dict(n_phi=24, n_dphi=24, periods=300, capture_radius=0.0, symmetric=False)
    a = basin_map(*COEX, engine="numba", **kw)
    b = basin_map(*COEX, engine="numpy", **kw)
    np.testing.assert_array_equal(a["attractor"].values, b["attractor"].values)
    np.testing.assert_array_equal(a["periods_used"].values, b["periods_used"].values)


def test_numba_trajectory_bitwise_equal_to_numpy_rk4():
    from parapend.dynamics import _kernel
    from parapend.dynamics.simulate import _RK4Map

    rng = np.random.default_rng(3)
    th = rng.uniform(-math.pi, math.pi, 40)
    v = rng.uniform(-3, 3, 40)
    m = _RK4Map(*COEX, 128)
    th_c, v_c = _kernel.full_time_kernel(th.copy(), v.copy(), m.a, m.gamma, m.h, m.steps, 5)
    th_n, v_n = th.copy(), v.copy()
    for _ in range(5):
        m.advance(th_n, v_n)
        th_n -= 2 * math.pi * np.rint(th_n / (2 * math.pi))
    np.testing.assert_array_equal(th_c, th_n)
    np.testing.assert_array_equal(v_c, v_n)


# --- acceptance: the paper's coexistence case from the command line ----------------------
def test_cli_basins_coexistence_equals_library(capsys, tmp_path):
    nc = tmp_path / "b.nc"
    png = tmp_path / "b.png"
    code, out, _ = _run(capsys, "basins", "--gamma", "0.1", "--p", "0.8", "--omega", "2.1",
                        "--resolution", "60", "--json", "--save", str(nc), "--plot", str(png))
    assert code == 0
    js = json.loads(out)
    ds = basin_map(*COEX, n_phi=60, n_dphi=60)
    kinds = {(t["kind"], t["period"], t["winding"]): t for t in js["attractors"]}
    assert ("oscillation", 2, 0) in kinds          # the period-2 oscillation
    assert ("rotation", 1, 1) in kinds and ("rotation", 1, -1) in kinds   # both directions
    for t in js["attractors"]:
        assert set(t) >= {"name", "kind", "period", "winding", "basin_fraction",
                          "poincare_phi", "poincare_dphi"}
        assert t["basin_fraction"] == pytest.approx(
            float(ds["basin_fraction"].values[t["code"]]), abs=1e-9)
        assert len(t["poincare_phi"]) == t["period"]
    assert sum(t["basin_fraction"] for t in js["attractors"]) == pytest.approx(1.0)
    assert nc.stat().st_size > 0 and png.stat().st_size > 0
    import xarray as xr

    with xr.open_dataset(nc) as back:
        np.testing.assert_array_equal(back["attractor"].values, ds["attractor"].values)


@pytest.mark.slow
def test_cli_rotations_equal_rotation_boundaries(capsys):
    code, out, _ = _run(capsys, "rotations", "--gamma", "0.1", "--omega", "2.1", "--json")
    assert code == 0
    js = json.loads(out)
    ref = rotation_boundaries(0.1, [2.1])
    assert js["p_J"][0] == ref["p_J"].values[0]
    assert js["p_G"][0] == ref["p_G"].values[0]
    assert js["p_E"] == [] and math.isnan(ref["p_E"].values[0])     # E above p = 3 here
    assert js["p_J"][0] < 0.8 < js["p_G"][0]     # the rotation at p = 0.8 is stable


@pytest.mark.slow
def test_cli_simulate_final_motions(capsys, tmp_path):
    csv_path = tmp_path / "m.csv"
    for dphi0, name in (("0", "P2 oscillation"), ("2.5", "P1 rotation (+)"),
                        ("-2.5", "P1 rotation (-)")):
        args = ["simulate", "--phi0", "0.5" if dphi0 == "0" else "0", "--dphi0", dphi0,
                "--periods", "150", "--json"]
        if dphi0 == "0":
            args += ["--save", str(csv_path)]
        code, out, _ = _run(capsys, *args)
        assert code == 0
        assert json.loads(out)["final"]["name"] == name
    with open(csv_path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["time", "phi", "phi_dot", "energy"]
    assert rows[1] == ["sqrt(l/g)", "rad", "rad sqrt(g/l)", "m g l"]  # the units row
    assert len(rows) == 150 * 64 + 3
    code, out, _ = _run(capsys, "simulate", "--periods", "120")
    assert code == 0 and "P2 oscillation" in out


# --- stability: continuation (Floquet) against direct simulation ---------------------------
def _settles_on_rotation(orbit, gamma, p, omega):
    """Start 1e-3 off the orbit, DOP853 for 250 periods: back on the period-1 rotation?"""
    m = simulate(gamma, p, omega, orbit.phi0 + 1e-3, orbit.dphi0 - 1e-3, 250,
                 points_per_period=2)
    c = m.classification
    if c.name != "P1 rotation (+)":
        return False
    return bool(max(abs(c.phi[0] - orbit.phi0), abs(c.dphi[0] - orbit.dphi0)) < 1e-4)


@pytest.mark.slow  # several seconds; the default run stays within its budget
def test_floquet_stability_agrees_with_simulation_across_G_and_E():
    gamma, omega = 0.1, 1.4      # G = 0.515, E = 2.268 (docs/dynamics.md)
    r = rotation_boundaries_at(gamma, omega, p_max=2.5)
    assert r.success and len(r.p_G) >= 1 and len(r.p_E) >= 1
    g, e = r.lowest_G, r.lowest_E
    guess = None
    for p, stable in ((g - 0.05, True), (g + 0.05, False), (e - 0.05, False),
                      (e + 0.05, True)):
        orb = periodic_orbit(gamma, p, omega, **({} if guess is None else guess))
        assert orb.success, p
        assert orb.stable is stable, p
        assert _settles_on_rotation(orb, gamma, p, omega) is stable, p
        guess = {"phi0": orb.phi0, "dphi0": orb.dphi0}


# --- errors --------------------------------------------------------------------------------
@pytest.mark.parametrize("args, word", [
    (["basins", "--resolution", "0"], "resolution"),
    (["basins", "--resolution", "5000"], "resolution"),
    (["basins", "--resolution", "1000", "--periods", "1000"], "periods"),
    (["basins", "--dphi-range", "3:-3"], "dphi-range"),
    (["basins", "--phi-range", "1"], "phi-range"),
    (["basins", "--omega", "0"], "omega"),
    (["basins", "--p", "nan"], "p"),
    (["basins", "--save", "x.png"], "--save"),
    (["simulate", "--periods", "0"], "periods"),
    (["simulate", "--periods", "20000", "--omega", "0.1"], "periods"),
    (["simulate", "--gamma", "-1"], "gamma"),
    (["simulate", "--plot", "x.txt"], "--plot"),
    (["rotations", "--omega", "2:1:5"], "omega"),
    (["rotations", "--omega", "1:2:1000"], "omega"),
    (["rotations", "--omega", "1:2"], "omega"),
    (["rotations", "--p-max", "50"], "p-max"),
    (["rotations", "--omega", "0.5"], "omega"),
])
def test_cli_errors_one_line_exit_2(capsys, args, word):
    code, out, err = _run(capsys, *args)
    assert code == 2
    assert out == ""
    assert len(err.strip().splitlines()) == 1 and word in err
    assert "Traceback" not in err


def test_cli_negative_ranges_parse(capsys):
    code, out, err = _run(capsys, "basins", "--resolution", "8", "--dphi-range", "-3:-1",
                          "--phi-range", "-1:1", "--periods", "50", "--json")
    assert code == 0, err
    js = json.loads(out)
    assert js["dphi_range"] == [-3.0, -1.0] and js["phi_range"] == [-1.0, 1.0]


def test_cli_help(capsys):
    for cmd in ("simulate", "basins", "rotations"):
        code, out, _ = _run(capsys, cmd, "--help")
        assert code == 0 and "--json" in out and "--plot" in out and "--save" in out


def test_simulate_api_checks():
    from parapend.errors import ParameterError

    with pytest.raises(ParameterError, match="periods"):
        simulate(periods=0)
    with pytest.raises(ParameterError, match="points_per_period"):
        simulate(periods=20000, points_per_period=1024)
    with pytest.raises(ParameterError, match="engine"):
        basin_map(*COEX, n_phi=4, n_dphi=4, engine="cuda")
