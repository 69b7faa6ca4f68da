"""Does ``parapend.buoy`` give the same answer in every run? (docs/buoy.md, "Torque limit")

Runs the default design's calls in fresh subprocesses, in different orders, with the BEM
cache cold (a new ``PARAPEND_CACHE``) and warm, and with the body's mass changed by a few
ulp (the last bits another BLAS kernel or another machine could change), and under four
OpenBLAS kernels (``OPENBLAS_CORETYPE``; one the processor lacks falls back), and prints one
fingerprint per call: the power, the peak torque, a hash of the motion's coefficients, and
for the ideal optimum its motion sent through a take-off of 0.9 both ways.

    python benchmarks/buoy_determinism.py [--src PATH]

``--src``: the source tree to import parapend from (default this checkout's ``src``), to
compare two versions. Calls: I (ideal), L (``torque_limit=254.95``), E (``efficiency=0.9``),
H (the cylinder's coefficients).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r'''
import dataclasses, hashlib, sys
import numpy as np
import parapend
from parapend.hydro.optimum import coupled_optimum
from parapend.hydro.pto import electrical_power


def fp(a):
    return hashlib.sha256(np.ascontiguousarray(np.asarray(a)).tobytes()).hexdigest()[:10]


def line(tag, power, peak, x, extra=""):
    print(f"{tag:4s} P={power!r:21s} peak={peak:8.3f} x={fp(x)}{extra}", flush=True)


def through(sol):
    t = sol.period * np.arange(20000) / 20000
    d = sol.sample(t)
    return f" through 0.9/0.9: {electrical_power(-d['tau'] * d['theta_dot'], (0.9, 0.9))[0]:.4f} W"


for c in sys.argv[1].split(","):
    if c == "H":
        from parapend.hydro import bem as hy
        h = hy.cylinder(0.5, 0.5)
        print("H    hydro", fp(h.added_mass), fp(h.radiation_damping), fp(h.excitation),
              repr(h.hydrostatic_stiffness), repr(h.mass), flush=True)
    elif c.startswith("U"):  # ideal and limited optimum with the mass changed by j ulp
        r0 = parapend.buoy()
        for j in range(int(c[1:])):
            h = dataclasses.replace(r0._hydro, mass=r0._hydro.mass * (1 + j * 2.0**-52))
            s = coupled_optimum(h, r0.solution._pendulum, r0._wave)
            line(f"I+{j}", s.power, s.peak_torque(), s.theta_coefficients["x"], through(s))
            s = coupled_optimum(h, r0.solution._pendulum, r0._wave, torque_limit=254.95)
            line(f"L+{j}", s.power, s.peak_torque(), s.theta_coefficients["x"])
    else:
        kw = {"I": {}, "L": {"torque_limit": 254.95}, "E": {"efficiency": 0.9}}[c]
        r = parapend.buoy(**kw)
        s = r.solution
        extra = through(s) if c == "I" else (
            f" electrical={r.electrical_power_w!r}" if c == "E" else "")
        line(c, r.power_w, r.peak_torque_nm, s.theta_coefficients["x"], extra)
'''


def run(src: str, calls: str, cache: str, coretype: str | None = None) -> str:
    env = dict(os.environ, PYTHONPATH=src, PARAPEND_CACHE=cache, OPENBLAS_NUM_THREADS="1",
               OMP_NUM_THREADS="1")
    if coretype:
        env["OPENBLAS_CORETYPE"] = coretype
    out = subprocess.run([sys.executable, "-c", CHILD, calls], env=env, capture_output=True,
                         text=True, check=False)
    return out.stdout + (out.stderr if out.returncode else "")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", default=str(Path(__file__).resolve().parents[1] / "src"))
    ap.add_argument("--ulp", type=int, default=6, help="mass changes of 0..ULP-1 ulp")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        plan = [("cold cache", "H,I,L,E"), ("warm cache", "H,E,I,L"), ("warm cache", "L,I"),
                ("warm cache", f"U{args.ulp}")]
        for what, calls in plan:
            print(f"--- fresh process, {what}: {calls}", flush=True)
            print(run(args.src, calls, tmp), end="", flush=True)
        for core in ("Prescott", "Sandybridge", "Haswell", "SkylakeX"):
            print(f"--- fresh process, warm cache, OPENBLAS_CORETYPE={core}: I,L", flush=True)
            print(run(args.src, "I,L", tmp, core), end="", flush=True)


if __name__ == "__main__":
    main()
