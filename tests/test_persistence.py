"""Rotation persistence (parapend persistence): the batched RK4 kernel against SciPy's DOP853
on the same records, the energy identity per realization, the regular-wave limit against
the period-1 rotation's stability from ``rotations`` (shooting and continuation), the decay
as Hs -> 0, the records against ``parapend sea``'s, the statistics' intervals against
closed forms, the bad inputs, and a map killed with -9 and resumed bit for bit."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import parapend
from parapend.dynamics import persistence as P

ROOT = Path(__file__).resolve().parents[1]
M, L = 1.0, 0.3
INERTIA = M * L * L


def _spec(**kw):
    args = {"mass": M, "length": L, "inertia": None, "gravity": 9.81,
            "damping_coefficient": 2e-4, "generator_damping": 5e-4, "hs": 0.02, "tp": 0.3,
            "spectrum": "jonswap", "gamma_peak": 3.3, "cutoff": 3.0, "response": None,
            "duration": 6.0, "transient": 0.6, "realizations": 8, "seed": 0,
            "omniscient": 0, "controller": None, "gpu": False}
    args.update(kw)
    return P.persistence_spec(**args)


def _dop853(spec, seed, cg):
    """The same realization by SciPy's DOP853 with z'' summed term by term (no FFT)."""
    tp = spec.tp[0]
    z = P.record_heave(spec, spec.hs[0], tp, seed)
    w = 2 * math.pi * np.arange(z.size) / spec.duration
    amp, ph = np.abs(z), np.angle(z)
    c, g = spec.damping_coefficient, spec.gravity

    def zdd(t):
        return float(np.sum(-(w**2) * amp * np.cos(w * t + ph)))

    def rhs(t, y):
        th, om = y[0], y[1]
        a = zdd(t)
        return [om, (M * L * (g + a) * math.sin(th) - (c + cg) * om) / INERTIA, om * om,
                M * L * a * math.sin(th) * om]

    plan = P.cell_plan(spec, 0, 0)
    tw = plan["k0"] * plan["h"]
    s1 = solve_ivp(rhs, (0.0, tw), [math.pi, 2 * math.pi / tp, 0, 0], method="DOP853",
                   rtol=1e-12, atol=1e-12)
    s2 = solve_ivp(rhs, (tw, spec.duration), [*s1.y[:2, -1], 0.0, 0.0], method="DOP853",
                   rtol=1e-12, atol=1e-12)
    window = spec.duration - tw
    return {"rho": (s2.y[0, -1] - s1.y[0, -1]) * tp / (2 * math.pi * window),
            "power": cg * s2.y[2, -1] / window, "base_work": s2.y[3, -1]}


def test_records_are_the_sea_command_s():
    """Realization r is ``parapend sea``'s record of seed + r, bit for bit, and its z'' on
    the step grid (one inverse FFT) is the Fourier sum."""
    from parapend.seas import sea_record
    from parapend.units import Units

    spec = _spec(hs=1.5, tp=7.0, duration=700.0, transient=70.0)
    for seed in (0, 5):
        rec = sea_record(Units(L, M), hs=1.5, tp=7.0, repeat_period=700.0, seed=seed)
        np.testing.assert_array_equal(P.record_heave(spec, 1.5, 7.0, seed), rec.heave)
    plan = P.cell_plan(spec, 0, 0)
    zdd = P.acceleration(spec, plan, [3])[0]
    z = P.record_heave(spec, 1.5, 7.0, 3)
    w = 2 * math.pi * np.arange(z.size) / 700.0
    for j in (0, 17, zdd.size - 1):
        t = j * plan["h"] / 2
        direct = np.sum(-(w**2) * np.abs(z) * np.cos(w * t + np.angle(z)))
        assert zdd[j] == pytest.approx(direct, rel=1e-9, abs=1e-12 * np.max(np.abs(zdd)))


def test_kernel_against_dop853_and_the_energy_identity():
    """Short records (20 peak periods) where the motion is not sensitive: rho and the power
    of the kernel (step refined 4 times) equal DOP853's to its accuracy; and the energy
    identity holds per realization to 1e-6."""
    spec = _spec()
    cg = 5e-4
    plan = P.cell_plan(spec, 0, 0, refine=4)
    vals = P.run_cell(spec, plan, cg, range(4))
    coarse = P.run_cell(spec, P.cell_plan(spec, 0, 0), cg, range(4))
    assert np.all(P.energy_residual(vals) < 1e-6)
    assert np.all(P.energy_residual(coarse) < 1e-4)
    for r in range(4):
        ref = _dop853(spec, r, cg)
        assert vals["rho"][r] == pytest.approx(ref["rho"], abs=1e-7)
        assert vals["power"][r] == pytest.approx(ref["power"], rel=1e-6)
        assert vals["base_work"][r] == pytest.approx(ref["base_work"], rel=1e-6, abs=1e-9)


def _regular(p, seeds=32):
    """A one-component record: paper Eq. 1 at gamma = 0.1, omega = 2.1 and excitation p
    (q = z''/g = p cos(omega t + phase)) for the 0.3 m pendulum, the component kept by a
    response table that is 1 at its frequency and 0 at its neighbours'."""
    t0 = math.sqrt(INERTIA / (M * 9.81 * L))
    f = 2.1 / (2 * math.pi * t0)
    tp = 1.0 / f
    tr = 400 * tp
    k = 400
    df = 1.0 / tr
    table = ([(k - 1) * df, k * df, (k + 1) * df], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0])
    from parapend.seas import jonswap

    a1 = math.sqrt(2 * float(jonswap(np.array([k / tr]), 1.0, tp)[0]) / tr)
    hs = p * 9.81 / (2 * math.pi * f) ** 2 / a1
    damping = 0.1 * INERTIA / t0
    return P.persistence_spec(
        mass=M, length=L, inertia=None, gravity=9.81, damping_coefficient=damping / 2,
        generator_damping=damping / 2, hs=hs, tp=tp, spectrum="jonswap", gamma_peak=3.3,
        cutoff=3.0, response=table, duration=tr, transient=300 * tp, realizations=seeds,
        seed=0, omniscient=0, controller=None, gpu=False)


def test_regular_wave_limit_rotates_exactly_where_rotations_says():
    """One component: where ``rotations`` finds the period-1 rotation stable (between the
    fold J and the period doubling G at gamma = 0.1, omega = 2.1) records lock onto it,
    one turn per wave period over the window (to the window's misalignment with the
    period, 1e-4) and throughout; below J no record rotates. (At p = 1 a slipping
    rotation coexists: two of 32 records turn 0.3 % fewer times.)"""
    from parapend.dynamics.continuation import rotation_boundaries_at

    b = rotation_boundaries_at(0.1, 2.1)
    assert b.lowest_J < 1.0 < b.lowest_G
    spec = _regular(1.0)
    v = P.run_cell(spec, P.cell_plan(spec, 0, 0), spec.generator[0], range(32))
    locked = np.abs(v["rho"] - 1.0) < 1e-4
    assert locked.sum() >= 4
    assert np.all(v["throughout"][locked] == 1.0)
    assert np.all(np.abs(v["rho"][v["rho"] >= 0.5] - 1.0) < 0.01)
    spec = _regular(0.9 * b.lowest_J)
    v = P.run_cell(spec, P.cell_plan(spec, 0, 0), spec.generator[0], range(32))
    assert np.all(v["rho"] < 0.05) and not v["throughout"].any()


def test_rotation_decays_as_hs_goes_to_zero():
    r = parapend.persistence(hs="0.0005,0.005,0.02", tp=0.3, duration=240.0, realizations=24)
    p = [s["p_rot"] for s in r.sea_states]
    rho = [s["rho_mean"] for s in r.sea_states]
    assert p[0] == 0.0 and p[2] > p[0]
    assert rho[0] < rho[1] < rho[2]
    assert r.step_check["energy_residual_max"] < 1e-3


def test_intervals_against_closed_forms():
    # Wilson: 0 of 10 -> [0, z^2 / (n + z^2)]
    z = 1.959963984540054
    lo, hi = P.wilson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(z * z / (10 + z * z), rel=1e-12)
    lo, hi = P.wilson_interval(5, 10)
    assert (lo + hi) / 2 == pytest.approx(0.5, rel=1e-12)
    x = np.array([1.0, 2.0, 3.0])
    lo, hi = P.t_interval(x)
    assert hi - 2.0 == pytest.approx(4.302652729749464 * 1.0 / math.sqrt(3), rel=1e-9)


def test_result_protocol_and_json_keys(tmp_path):
    r = parapend.persistence(hs="0.01,0.02", tp="0.25,0.3", duration=30.0, realizations=6)
    d = r.to_dict()
    keys = {"hs_m", "tp_s", "p_rot", "p_rot_ci", "p_throughout", "p_throughout_ci",
            "rho_mean", "rho_mean_ci", "power_mean_w", "power_mean_ci_w"}
    assert len(d["sea_states"]) == 4 and all(keys <= set(s) for s in d["sea_states"])
    json.dumps(d, allow_nan=False)
    ds = r.to_dataset()
    assert ds["p_rot"].shape == (2, 2, 1)
    for name in ds.variables:
        assert ds[name].attrs.get("units") and ds[name].attrs.get("long_name"), name
    r.save(tmp_path / "r.nc")
    r.save(tmp_path / "r.png")
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"
    assert "PersistenceResult(" in repr(r) and len(repr(r)) < 400
    # the same cell again: the same bits (seeded records, deterministic kernel)
    again = parapend.persistence(hs=0.02, tp=0.3, duration=30.0, realizations=6)
    assert again.sea_states[0]["power_mean_w"] == d["sea_states"][3]["power_mean_w"]


def test_time_limit_gives_a_marked_partial_map():
    r = parapend.persistence(hs="0.01,0.02,0.03", tp=0.3, duration=30.0, realizations=8,
                             time_limit=1e-6)
    assert r.status == "time_limit" and not r.success
    assert 1 <= r.cells_finished < 3
    done = [s for s in r.sea_states if s["p_rot"] is not None and not math.isnan(s["p_rot"])]
    assert len(done) == r.cells_finished
    d = r.to_dict()
    assert d["sea_states"][-1]["p_rot"] is None and "time limit" in d["message"]


def test_generator_damping_best_beats_the_grid_neighbours():
    r = parapend.persistence(hs=0.02, tp=0.3, duration=30.0, realizations=8,
                             generator_damping="best")
    s = r.sea_states[0]
    cg = s["generator_damping_nm_s_per_rad"]
    assert cg > 0
    for f in (0.5, 2.0):  # the same records at other dampings give less power on average
        other = parapend.persistence(hs=0.02, tp=0.3, duration=30.0, realizations=8,
                                     generator_damping=cg * f)
        assert other.sea_states[0]["power_mean_w"] < s["power_mean_w"]


@pytest.mark.parametrize("argv, word", [
    (["--hs", "0"], "hs:"), (["--hs", "-1"], "hs:"), (["--tp", "100"], "tp:"),
    (["--tp", "0.01"], "tp:"), (["--realizations", "0"], "realizations:"),
    (["--generator-damping", "-1"], "generator-damping:"),
    (["--duration", "2", "--tp", "0.3"], "duration:"),
    (["--transient", "50", "--duration", "40"], "duration:")])
def test_bad_input_is_one_line_exit_2(argv, word, capsys):
    from parapend.cli import main

    assert main(["persistence", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0], err


def _cli(args, store, env):
    # the output to files: a pipe that nobody reads would block the JSON's write
    with open(Path(str(store) + ".log"), "w") as log:  # the child keeps its own descriptor
        return subprocess.Popen([sys.executable, "-m", "parapend", "persistence", *args,
                                 "--store", str(store), "--json"], env=env, stdout=log,
                                stderr=subprocess.STDOUT, cwd=ROOT)


@pytest.mark.slow
def test_kill_9_halfway_and_resume_is_bit_for_bit(tmp_path):
    """A 10 x 10 map of 200 realizations from the command line, killed with -9 when about
    half its blocks are written, then run again: the store equals an uninterrupted run's."""
    import xarray as xr

    args = ["--hs", "0.005:0.03:10", "--tp", "0.2:0.5:10", "--duration", "12",
            "--transient", "2", "--realizations", "200"]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    whole = tmp_path / "whole.zarr"
    p = _cli(args, whole, env)
    assert p.wait(timeout=600) == 0, (tmp_path / "whole.zarr.log").read_text()
    cut = tmp_path / "cut.zarr"
    p = _cli(args, cut, env)
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline:
        done = list((cut / "done" / "c").rglob("*")) if (cut / "done" / "c").exists() else []
        if sum(f.is_file() for f in done) >= 40:
            break
        time.sleep(0.05)
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert p.returncode == -signal.SIGKILL
    blocks = sum(f.is_file() for f in (cut / "done" / "c").rglob("*"))
    assert 0 < blocks < 100, blocks
    p = _cli(args, cut, env)
    assert p.wait(timeout=600) == 0, (tmp_path / "cut.zarr.log").read_text()
    a = xr.open_zarr(whole, consolidated=False).load()
    b = xr.open_zarr(cut, consolidated=False).load()
    assert bool(b["done"].all())
    for v in a.data_vars:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)


@pytest.mark.slow
def test_cell_statistics_within_intervals_of_an_independent_integration():
    """40 records of 20 peak periods: P_rot and the mean power by DOP853 realization by
    realization lie in the kernel's 95 % intervals (and the kernel's in DOP853's)."""
    spec = _spec(realizations=40, hs=0.03, tp=0.25, duration=5.0, transient=0.5)
    vals = P.run_cell(spec, P.cell_plan(spec, 0, 0), 5e-4, range(40))
    st = P.cell_statistics({**vals, "status": np.zeros(40)}, np.ones(40, bool))
    ref = [_dop853(spec, r, 5e-4) for r in range(40)]
    p_ref = np.mean([x["rho"] >= 0.5 for x in ref])
    pw_ref = np.mean([x["power"] for x in ref])
    assert st["p_rot_ci"][0] <= p_ref <= st["p_rot_ci"][1]
    assert st["power_mean_ci_w"][0] <= pw_ref <= st["power_mean_ci_w"][1]


@pytest.mark.slow
def test_omniscient_and_controller_beside_the_passive_answer():
    """On the same records: the omniscient optimum (parapend sea's, on the similar pendulum
    for Tp < 1.25 s) and the regular-wave tracker; the similar pendulum gives sea's own
    answer where sea takes the record directly."""
    from parapend.dynamics import _persist_cells as C

    r = parapend.persistence(hs=0.04, tp=1.2, length=3.0, duration=36.0, realizations=2,
                             omniscient=1, controller="track")
    s = r.sea_states[0]
    assert s["omniscient_realizations"] == 1 and s["controller_realizations"] == 1
    assert s["omniscient_power_mean_w"] > 0 and math.isfinite(s["controller_power_mean_w"])
    alone = parapend.persistence(hs=0.04, tp=1.2, length=3.0, duration=36.0,
                                 realizations=1).sea_states[0]["power_mean_w"]
    assert s["passive_fraction_of_omniscient"] == pytest.approx(
        alone / s["omniscient_power_mean_w"], rel=1e-12)
    # the similar pendulum: the same record solved by sea at twice the length scale's
    # square root in time (lambda = 4: lengths x 4, inertia x 16, damping x 8, power x 2)
    spec = _spec(hs=0.04, tp=1.2, length=3.0, duration=36.0, transient=12.0)
    plan = C.cell_plan(spec, 0, 0)
    direct = parapend.sea(hs=0.16, tp=2.4, repeat_period=72.0, seed=0, length=12.0, mass=M,
                          inertia=9.0 * 16, damping_coefficient=2e-4 * 8)
    assert C.omniscient_power(spec, plan, 0) == pytest.approx(direct.power_w / 2, rel=1e-6)


@pytest.mark.slow
def test_worker_processes_give_the_same_bits():
    kw = dict(hs="0.01,0.02", tp="0.3,0.35", duration=30.0, realizations=8)
    a = parapend.persistence(**kw, workers=2)
    b = parapend.persistence(**kw)
    assert a.executor == "2 local processes"
    for v in a.dataset.data_vars:
        np.testing.assert_array_equal(a.dataset[v].values, b.dataset[v].values, err_msg=v)


_SIMULATED = r"""
import json, sys
import numpy as np
import zarr
import parapend
from parapend.dynamics._persist_gpu import run_column_gpu  # noqa: F401 - importable
kw = dict(mass=1.0, length=0.3, damping_coefficient=2e-4, generator_damping="5e-4,2e-3",
          hs="0.01,0.03,0.4", tp=0.3, duration=6.0, transient=0.6, realizations=3, seed=0)
g = parapend.persistence(**kw, gpu=True, store=sys.argv[1])
again = parapend.persistence(**kw, gpu=True, store=sys.argv[1])
c = parapend.persistence(**kw)
out = {"chunks": list(zarr.open_group(sys.argv[1], mode="r")["rho"].chunks)}
for v in ("rho", "throughout", "power", "harvested_energy", "dissipated_energy", "base_work",
          "stored_energy_change", "status"):
    out[v] = [g.dataset[v].values.tolist(), c.dataset[v].values.tolist(),
              again.dataset[v].values.tolist()]
print(json.dumps(out))
"""


@pytest.mark.slow
def test_gpu_kernel_on_the_cuda_simulator_gives_the_cpu_kernel_s_numbers(tmp_path):
    """numba's CUDA simulator (no GPU needed) runs the GPU path: a Tp column of 3 Hs (two
    step sizes) x 2 generator dampings x 3 realizations in one launch (one block, one chunk,
    in a store that a second run resumes), against the CPU kernel on the same records (20
    peak periods; the sines differ in the last bit, which the violent 0.4 m records grow to
    4e-8: the numbers to 1e-6, where a lane given another cell's Hs, step or damping is off
    by far more)."""
    import importlib.util

    if importlib.util.find_spec("numba.cuda") is None:
        pytest.skip("numba has no CUDA support (simulator included) here")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "NUMBA_ENABLE_CUDASIM": "1"}
    p = subprocess.run([sys.executable, "-c", _SIMULATED, str(tmp_path / "g.zarr")], env=env,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    out = json.loads(p.stdout.splitlines()[-1])
    assert out.pop("chunks") == [1, 3, 2, 3]
    for v, (gpu, cpu, again) in out.items():
        gpu, cpu = np.array(gpu), np.array(cpu)
        np.testing.assert_array_equal(gpu, np.array(again), err_msg=v)
        if v in ("throughout", "status"):
            np.testing.assert_array_equal(gpu, cpu, err_msg=v)
        else:
            np.testing.assert_allclose(gpu, cpu, rtol=1e-6, atol=1e-12, err_msg=v)
    assert np.ptp(np.array(out["power"][1])) > 0  # the cells and dampings differ
