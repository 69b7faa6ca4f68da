#!/usr/bin/env bash
# The GPU path of `parapend persistence` on a machine with a CUDA GPU (run from the
# repository root): the same statistics as the CPU path side by side, then the time of the
# 20 Hs x 20 Tp x 1000 realizations x 400 Tp map on the GPU (compiled first, then timed).
#
#   bash benchmarks/gpu_persistence.sh            # everything (about a minute)
#   QUICK=1 bash benchmarks/gpu_persistence.sh    # the comparison only
#
# Needs numba's CUDA support (numba.cuda, or the numba-cuda package); CuPy is used for the
# FFTs when installed (else they run on the CPU and are copied). Python: $PYTHON, else
# python3, else python. Wheels in .whl/ (packages the machine lacks: zarr, dask, ...) are
# installed into /tmp/site first. numba-cuda releases that call numpy.row_stack (removed in
# NumPy 2.5) get it as numpy.vstack in this script's Python (not in the library). Prints
# what it could not do.
set -u
if [ -n "${PYTHON:-}" ]; then PY=$PYTHON
elif command -v python3 >/dev/null 2>&1; then PY=python3
else PY=python; fi
if compgen -G ".whl/*.whl" >/dev/null; then
  $PY -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
    --target /tmp/site .whl/*.whl || exit 1
  export PYTHONPATH="/tmp/site${PYTHONPATH:+:$PYTHONPATH}"
fi
export PYTHONPATH="$PWD/src:$PWD/benchmarks${PYTHONPATH:+:$PYTHONPATH}"
export PYTHONUNBUFFERED=1
# the compatibility line, run before anything imports numba.cuda
SHIM='import numpy as np
if not hasattr(np, "row_stack"):
    np.row_stack = np.vstack
'

nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null \
  || echo "nvidia-smi: not found"
$PY - <<EOF2
$SHIM
import importlib.util
from parapend.dynamics._persist_gpu import available
why = available()
print("numpy", np.__version__, "| numba.cuda:", "ready" if not why else why)
print("cupy:", "installed" if importlib.util.find_spec("cupy") else "not installed (FFTs on the CPU)")
if why:
    raise SystemExit(1)
EOF2
[ $? -eq 0 ] || exit 1

# 1. The same cells on the CPU and on the GPU: 2 Hs x 2 Tp x 1000 realizations of 400 Tp.
#    The GPU's sine and fused multiply-adds differ in the last bits and the motion is
#    chaotic: the statistics must agree within their intervals, the realizations need not.
$PY - <<EOF2
$SHIM
import math, time
import parapend

t0 = 2 * math.pi * math.sqrt(0.3 / 9.81)
kw = dict(mass=1.0, length=0.3, damping_coefficient=2e-4, generator_damping=5e-4,
          hs="0.01,0.03", realizations=1000, seed=0)
for tp in (0.25 * t0, 0.45 * t0):
    out = {}
    for gpu in (False, True):
        parapend.persistence(**{**kw, "realizations": 8}, tp=tp, duration=40 * tp, gpu=gpu)
        t = time.perf_counter()
        r = parapend.persistence(**kw, tp=tp, duration=400 * tp, gpu=gpu, time_limit=3600)
        out[gpu] = (r, time.perf_counter() - t)
    for (sc, sg) in zip(out[False][0].sea_states, out[True][0].sea_states):
        print(f"Tp/T0 {sc['tp_over_t0']:.3f} Hs {sc['hs_m']:.3f}:")
        for k in ("p_rot", "p_throughout", "rho_mean", "power_mean_w"):
            ci = k + "_ci" if k != "power_mean_w" else "power_mean_ci_w"
            a, b = sc[k], sg[k]
            overlap = (max(sc[ci][0], sg[ci][0]) <= min(sc[ci][1], sg[ci][1])
                       if sc[ci][0] is not None else True)
            print(f"   {k:14s} CPU {a:.5g} {[round(x, 5) for x in sc[ci]]}  "
                  f"GPU {b:.5g} {[round(x, 5) for x in sg[ci]]}  "
                  f"intervals overlap: {overlap}")
        print(f"   energy residual max: CPU {sc['energy_residual_max']:.2g}, "
              f"GPU {sg['energy_residual_max']:.2g}")
    print(f"   time for 2 cells x 1000: CPU {out[False][1]:.1f} s, GPU {out[True][1]:.1f} s")
EOF2

[ "${QUICK:-0}" = "1" ] && exit 0
# 2. The acceptance map on the GPU (one persistence call per Tp column: 400 peak periods
#    each; a column is one block, one launch), its time, steps per second and step check.
$PY - <<EOF2
$SHIM
import bench_persistence
bench_persistence.main(["--gpu", "--skip-kernel", "--grid", "20", "--realizations", "1000"])
EOF2
