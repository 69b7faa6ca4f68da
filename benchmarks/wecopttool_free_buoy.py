r"""The free buoy's heave response: parapend against WecOptTool on the same Capytaine dataset.

WecOptTool (3.3) pins ``capytaine==2.3.1`` while parapend needs ``capytaine>=3``, so the two
cannot share an environment. This script runs in parapend's environment and

1. solves the BEM of the default buoy (the vertical cylinder of radius 0.5 m and draft 0.5 m,
   meshed as :func:`parapend.hydro.bem.cylinder` meshes it) with Capytaine, on a harmonic
   grid ``omega_k = k w1`` (WecOptTool's pseudo-spectral solver needs one), with
   Froude-Krylov and diffraction forces, hydrostatic stiffness and the floating mass, and
   writes it the Capytaine way (``capytaine.io.xarray.save_dataset_as_netcdf``);
2. reads that file back with :func:`parapend.hydro.bem.load` (the ``--hydro`` path, which
   conjugates Capytaine's ``exp(-i w t)`` values) and computes the free heave response
   ``Z/a = F / D`` (:meth:`~parapend.hydro.bem.Hydro.free_response`) at every frequency;
3. runs this same file, with ``--wecopttool``, in a separate virtual environment that has
   WecOptTool: it reads the dataset with ``wot.read_netcdf``, changes the convention with
   ``wot.change_bem_convention``, adds zero friction and WecOptTool's damping floor as
   ``WEC.from_bem`` does, and computes the free heave response twice:

   - **impedance**: ``Z/a = F_exc / (i w Zi)`` at every frequency, with WecOptTool's
     intrinsic impedance ``Zi = wot.hydrodynamic_impedance(...)`` (velocity over force) and
     its excitation ``wot.wave_excitation(FK + diffraction, unit wave)``;
   - **pseudo-spectral**: ``wot.WEC.from_bem(...)`` and ``wec.solve`` of a regular wave
     near the heave resonance with no power take-off (the dynamics alone; a dummy control
     variable that no force sees), its heave harmonic over the wave's;

4. compares amplitude and phase and prints the largest relative differences.

The conventions match when both use ``x(t) = Re(X exp(+i w t))``: the comparison then agrees
to round-off (the impedance route) or to the pseudo-spectral solver's tolerance.

Run (the first line once; it installs WecOptTool 3.3.0 and its pinned Capytaine into the
venv)::

    python benchmarks/wecopttool_free_buoy.py --setup
    python benchmarks/wecopttool_free_buoy.py > benchmarks/wecopttool_free_buoy.out.txt

``--venv DIR`` (default ``$PARAPEND_WOT_VENV`` or ``~/.cache/parapend/wot-venv``) names the
virtual environment. ``--json`` prints the comparison as one JSON object (the slow test
``tests/test_buoy_wecopttool.py`` uses it).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

#: The default buoy (parapend buoy's embedded design).
RADIUS, DRAFT, RHO, G = 0.5, 0.5, 1025.0, 9.81
#: The harmonic BEM grid: omega_k = k * W1, k = 1..NFREQ (0.35 to 10.5 rad/s); the regular
#: wave of the pseudo-spectral check is harmonic K_WAVE (3.5 rad/s, period 1.795 s, beside
#: the default wave's 1.8 s and the heave resonance at 1.76 s).
W1, NFREQ, K_WAVE = 0.35, 30, 10
#: What --setup installs: the version whose functions this script calls (read_netcdf,
#: change_bem_convention, add_linear_friction, check_radiation_damping,
#: hydrodynamic_impedance, wave_excitation, WEC.from_bem, WEC.solve, WEC.post_process).
WECOPTTOOL = "wecopttool==3.3.0"


def default_venv() -> Path:
    env = os.environ.get("PARAPEND_WOT_VENV")
    return Path(env) if env else Path.home() / ".cache" / "parapend" / "wot-venv"


def venv_python(venv: Path) -> Path:
    return venv / ("Scripts/python.exe" if os.name == "nt" else "bin/python")


# -- parapend's side (capytaine >= 3) ----------------------------------------------------------
def write_dataset(path: Path):
    """BEM of the default cylinder on the harmonic grid, written the Capytaine way."""
    import capytaine as cpt
    import xarray as xr
    from capytaine.io.xarray import save_dataset_as_netcdf

    from parapend.hydro.bem import DEFAULT_OMEGA, _keep_resolvable, mesh_size

    cpt.set_logging("ERROR")
    omega = W1 * np.arange(1, NFREQ + 1)
    # the default's mesh: panel radius from the default grid's highest frequency
    h = mesh_size(min(RADIUS, DRAFT), DEFAULT_OMEGA[-1], g=G)
    if _keep_resolvable(omega, h, G, math.inf).size != omega.size:
        raise SystemExit("wecopttool_free_buoy: the harmonic grid exceeds the mesh's range")
    kw = dict(length=2 * DRAFT, radius=RADIUS, center=(0.0, 0.0, 0.0), faces_max_radius=h)
    mesh = cpt.mesh_vertical_cylinder(axial_symmetry=True, **kw).immersed_part()
    hull = cpt.mesh_vertical_cylinder(**kw).immersed_part()
    dofs = cpt.rigid_body_dofs(only=["Heave"])
    plain = cpt.FloatingBody(mesh=hull, dofs=dofs, center_of_mass=(0.0, 0.0, 0.0))
    c = float(np.asarray(plain.compute_hydrostatic_stiffness(rho=RHO, g=G)).ravel()[0])
    mass = RHO * float(plain.disp_volume)
    body = cpt.FloatingBody(mesh=mesh, dofs=dofs, center_of_mass=(0.0, 0.0, 0.0))
    test = xr.Dataset(coords={"omega": omega, "wave_direction": [0.0],
                              "radiating_dof": ["Heave"], "water_depth": [math.inf],
                              "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver().fill_dataset(test, body, n_jobs=1, progress_bar=False)
    heave = {"influenced_dof": ["Heave"], "radiating_dof": ["Heave"]}
    dims = ("influenced_dof", "radiating_dof")
    ds["hydrostatic_stiffness"] = xr.DataArray([[c]], dims=dims, coords=heave)
    ds["inertia_matrix"] = xr.DataArray([[mass]], dims=dims, coords=heave)
    ds.attrs["description"] = (f"vertical cylinder, radius {RADIUS:g} m, draft {DRAFT:g} m, "
                               f"{hull.nb_faces} panels (parapend's default mesh)")
    save_dataset_as_netcdf(str(path), ds)
    return hull.nb_faces, c, mass


def parapend_side(path: Path):
    from parapend.hydro.bem import load

    hydro = load(path)
    return hydro, hydro.free_response(hydro.omega)


# -- WecOptTool's side (run in its venv with --wecopttool; no parapend import) -----------------
def wecopttool_side(path: str, out: str) -> None:
    import logging

    import wecopttool as wot

    logging.getLogger("wecopttool").setLevel(logging.ERROR)
    bem = wot.read_netcdf(path)
    bem = wot.change_bem_convention(bem)          # exp(-i w t) -> exp(+i w t)
    hd = wot.add_linear_friction(bem)            # zero friction, as WEC.from_bem
    hd = wot.check_radiation_damping(hd)         # WEC.from_bem's floor (1e-6 N s/m)
    heave = {"radiating_dof": "Heave", "influenced_dof": "Heave"}
    zi = wot.hydrodynamic_impedance(hd).sel(heave)     # force / velocity
    w = hd["omega"].values
    f1, nfreq = wot.frequency_parameters(w / (2 * np.pi), False)
    unit = wot.waves.elevation_fd(f1, nfreq, 0.0, 1,
                                  np.ones((nfreq, 1, 1)), np.zeros((nfreq, 1, 1)))
    exc = hd["Froude_Krylov_force"] + hd["diffraction_force"]
    fexc = np.asarray(wot.wave_excitation(exc, unit.isel(realization=0))).ravel()
    z_imp = fexc / (1j * w * zi.values)

    # the pseudo-spectral solver on a regular wave, no PTO: the dynamics alone
    t0 = time.perf_counter()
    wec = wot.WEC.from_bem(bem.copy(deep=True))
    amp = 0.1
    k = int(os.environ.get("WOT_K_WAVE", "10"))
    wave = wot.waves.regular_wave(f1, nfreq, k * f1, amp, 30.0)
    waves = wave.expand_dims(realization=[0]) if "realization" not in wave.dims else wave

    def obj(wec_, x_wec, x_opt, wave_):
        return 0.5 * (x_opt[0] ** 2)

    res = wec.solve(waves, obj, 1, x_wec_0=np.zeros(wec.nstate_wec), x_opt_0=np.ones(1),
                    scale_x_wec=[10.0])  # SLSQP, WecOptTool's defaults: the dynamics are
    # linear equality constraints, met in a couple of iterations
    fd, _ = wec.post_process(wec, res, waves)
    fd = fd.isel(realization=0) if "realization" in fd.dims else fd
    pos = complex(np.asarray(fd["pos"].sel(omega=w[k - 1], method="nearest")).ravel()[0])
    elev = complex(np.asarray(waves.isel(realization=0).sel(omega=w[k - 1], method="nearest"))
                   .ravel()[0])
    r0 = res[0]
    out_obj = {
        "omega": w.tolist(),
        "z_impedance": [[z.real, z.imag] for z in z_imp],
        "ps_omega": float(w[k - 1]), "ps_z": [(pos / elev).real, (pos / elev).imag],
        "ps_status": int(r0.status), "ps_message": str(r0.message),
        "ps_seconds": time.perf_counter() - t0,
        "versions": {"wecopttool": wot.__version__ if hasattr(wot, "__version__") else
                     _version("wecopttool"), "capytaine": _version("capytaine"),
                     "jax": _version("jax"), "numpy": np.__version__},
    }
    Path(out).write_text(json.dumps(out_obj))


def _version(name):
    from importlib.metadata import version
    return version(name)


# -- the comparison ----------------------------------------------------------------------------
def setup(venv: Path) -> None:
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run([str(venv_python(venv)), "-m", "pip", "install", WECOPTTOOL], check=True)


def compare(venv: Path, workdir: Path):
    from importlib.metadata import version

    py = venv_python(venv)
    if not py.is_file():
        raise SystemExit(f"wecopttool_free_buoy: no virtual environment at {venv} "
                         "(create it with --setup)")
    nc = workdir / "cylinder_harmonic.nc"
    t = time.perf_counter()
    panels, c, mass = write_dataset(nc)
    t_bem = time.perf_counter() - t
    hydro, z_pp = parapend_side(nc)
    out = workdir / "wecopttool.json"
    env = dict(os.environ, WOT_K_WAVE=str(K_WAVE), PYTHONPATH="")
    t = time.perf_counter()
    run = subprocess.run([str(py), os.path.abspath(__file__), "--wecopttool", str(nc),
                          str(out)], capture_output=True, text=True, env=env)
    t_wot = time.perf_counter() - t
    if run.returncode != 0:
        tail = (run.stderr or run.stdout).strip().splitlines()[-5:]
        raise SystemExit("wecopttool_free_buoy: the WecOptTool side failed:\n  "
                         + "\n  ".join(tail))
    wot = json.loads(out.read_text())
    w = np.asarray(wot["omega"])
    if not np.allclose(w, hydro.omega, rtol=1e-12, atol=0):
        raise SystemExit("wecopttool_free_buoy: the two sides read different frequencies")
    z_wot = np.array([complex(*p) for p in wot["z_impedance"]])
    rel = np.abs(z_wot - z_pp) / np.abs(z_pp)
    amp = np.abs(np.abs(z_wot) - np.abs(z_pp)) / np.abs(z_pp)
    phase = np.abs(np.angle(z_wot / z_pp))
    import xarray as xr

    b_raw = np.asarray(xr.load_dataset(nc)["radiation_damping"].values, dtype=float).ravel()
    # what a missing convention change would give: Capytaine's excitation unconjugated
    _, _, f_pp = hydro.coefficients(hydro.omega)
    z_unconj = np.conj(f_pp) / hydro.impedance(hydro.omega)
    floored = b_raw < 1e-6  # parapend clamps B to >= 0, WecOptTool floors it at 1e-6 N s/m
    zps = complex(*wot["ps_z"])
    zpp_k = complex(z_pp[K_WAVE - 1])
    return {
        "dataset": str(nc), "panels": panels, "hydrostatic_stiffness_n_per_m": c,
        "mass_kg": mass, "bem_seconds": t_bem, "wecopttool_seconds": t_wot,
        "omega": w, "z_parapend": z_pp, "z_wecopttool": z_wot,
        "max_rel_diff": float(rel.max()), "max_amp_rel_diff": float(amp.max()),
        "max_phase_diff_rad": float(phase.max()),
        "floored_omega": w[floored].tolist(), "floored_b": b_raw[floored].tolist(),
        "max_rel_diff_unfloored": float(rel[~floored].max()),
        "max_rel_diff_unconjugated": float((np.abs(z_unconj - z_pp) / np.abs(z_pp)).max()),
        "ps_omega": wot["ps_omega"], "ps_z_wecopttool": zps, "ps_z_parapend": zpp_k,
        "ps_rel_diff": abs(zps - zpp_k) / abs(zpp_k),
        "ps_amp_rel_diff": abs(abs(zps) - abs(zpp_k)) / abs(zpp_k),
        "ps_phase_diff_rad": abs(float(np.angle(zps / zpp_k))),
        "ps_status": wot["ps_status"], "ps_message": wot["ps_message"],
        "versions": {"parapend side": {"capytaine": version("capytaine"),
                                       "numpy": np.__version__},
                     "wecopttool side": wot["versions"]},
    }


def report(r) -> str:
    lines = [
        "# python benchmarks/wecopttool_free_buoy.py  (parapend: capytaine "
        f"{r['versions']['parapend side']['capytaine']}; WecOptTool "
        f"{r['versions']['wecopttool side']['wecopttool']} with capytaine "
        f"{r['versions']['wecopttool side']['capytaine']}, jax "
        f"{r['versions']['wecopttool side']['jax']}, in its own venv)",
        f"# default cylinder r {RADIUS} m, draft {DRAFT} m, {r['panels']} panels; "
        f"C = {r['hydrostatic_stiffness_n_per_m']:.6g} N/m, M = {r['mass_kg']:.6g} kg; "
        f"BEM at omega = {W1} k, k = 1..{NFREQ} ({r['bem_seconds']:.1f} s), saved with "
        "save_dataset_as_netcdf",
        "# parapend: hydro.load(file).free_response; WecOptTool: read_netcdf, "
        "change_bem_convention, F_exc / (i w hydrodynamic_impedance)",
        f"{'omega':>7} {'T s':>7} {'|Z/a| parapend':>15} {'|Z/a| WecOptTool':>17} "
        f"{'phase pp deg':>13} {'phase WOT deg':>14} {'rel diff':>9}",
    ]
    for w, a, b in zip(r["omega"], r["z_parapend"], r["z_wecopttool"]):
        lines.append(f"{w:7.3f} {2 * math.pi / w:7.3f} {abs(a):15.9f} {abs(b):17.9f} "
                     f"{math.degrees(np.angle(a)):13.6f} {math.degrees(np.angle(b)):14.6f} "
                     f"{abs(a - b) / abs(a):9.1e}")
    lines += [
        f"impedance route, all {len(r['omega'])} frequencies: max relative difference of Z/a "
        f"{r['max_rel_diff']:.2e} (amplitude {r['max_amp_rel_diff']:.2e}, phase "
        f"{r['max_phase_diff_rad']:.2e} rad)",
        "  where the BEM's B < 1e-6 N s/m (" + (", ".join(
            f"B = {b:.3g} N s/m at {w:.3f} rad/s" for w, b in
            zip(r["floored_omega"], r["floored_b"])) or "none") + ") parapend uses "
        "max(B, 0) and WecOptTool's check_radiation_damping raises B to 1e-6 N s/m; at the "
        f"other frequencies the largest relative difference is {r['max_rel_diff_unfloored']:.2e}",
        "  (the convention matters: with Capytaine's excitation left unconjugated, Z/a would "
        f"differ by up to {r['max_rel_diff_unconjugated']:.2f} of itself)",
        f"pseudo-spectral WEC.solve, regular wave at {r['ps_omega']:.3f} rad/s "
        f"(T = {2 * math.pi / r['ps_omega']:.4f} s), no PTO: Z/a = "
        f"{abs(r['ps_z_wecopttool']):.9f} at "
        f"{math.degrees(np.angle(r['ps_z_wecopttool'])):.6f} deg against parapend's "
        f"{abs(r['ps_z_parapend']):.9f} at {math.degrees(np.angle(r['ps_z_parapend'])):.6f} "
        f"deg: relative difference {r['ps_rel_diff']:.2e} (amplitude "
        f"{r['ps_amp_rel_diff']:.2e}, phase {r['ps_phase_diff_rad']:.2e} rad); optimizer "
        f"status {r['ps_status']} ({r['ps_message']})",
        f"# WecOptTool side (venv start, jax import, both routes) {r['wecopttool_seconds']:.1f} "
        f"s; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores",
    ]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--venv", type=Path, default=default_venv())
    ap.add_argument("--setup", action="store_true",
                    help="create the venv and pip install wecopttool into it, then exit")
    ap.add_argument("--json", action="store_true", help="print the comparison as JSON")
    ap.add_argument("--keep", type=Path, default=None,
                    help="write the dataset and WecOptTool's numbers into this directory")
    ap.add_argument("--wecopttool", nargs=2, metavar=("DATASET", "OUT"),
                    help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.wecopttool:
        wecopttool_side(*a.wecopttool)
        return
    if a.setup:
        setup(a.venv)
        return
    with tempfile.TemporaryDirectory() as tmp:
        work = a.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        r = compare(a.venv, work)
    if a.json:
        out = {k: v for k, v in r.items() if not isinstance(v, (np.ndarray, complex))}
        for k in ("ps_z_wecopttool", "ps_z_parapend"):
            out[k] = [r[k].real, r[k].imag]
        out["omega"] = r["omega"].tolist()
        print(json.dumps(out))
    else:
        print(report(r))


if __name__ == "__main__":
    main()
