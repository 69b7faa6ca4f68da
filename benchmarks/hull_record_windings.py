"""The hull's record optimum at fixed windings (net turns of the pendulum over the record),
and on the closed loop's plant model, for one bin of the 4 x 4 causal power matrix.

The record optimum that ``buoy --dofs surge,heave,pitch`` and the power matrix report is the
better of two modes: rotation (one turn per wave on average, ``waves_in(wave)`` turns over
the record) and swinging (winding 0). On a long record a few net turns may do better than
either: this prints the optimum at each ``--windings`` (a local maximum from the solver's
own starts), and the record optimum (the two modes) on the frequency-domain hydrodynamics
and on the closed loop's plant model (the tapered radiation memory and ``A_inf`` of
:mod:`parapend.hydro.hull_control`: its own ``A(w)``, ``B(w)`` at every harmonic), the
references of the bin's causal runs.

    nice python benchmarks/hull_record_windings.py --bin 1,2 --windings 1,2,3,4,8,16
    nice python benchmarks/hull_record_windings.py --bin 2,2 --windings 4,5,6 --search
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from parapend.hydro import hull_control as hc
from parapend.hydro.api import solve_record
from parapend.hydro.hull import waves_in
from parapend.hydro.result import optimum
from parapend.performance import matrix_spec
from parapend.performance.buoy_device import wave_of
from parapend.performance.hull_device import problem as hull_problem_of


class PlantHull:
    """The hull with the closed loop's plant hydrodynamics: ``A_inf - K_s(w) / w`` and
    ``K_c(w)``, the cosine and sine sums of the plant's memory weights (its step, its
    tapered memory), in place of the BEM's ``A(w)``, ``B(w)``; the excitation the BEM's."""

    def __init__(self, hull, tp):
        self._hull = hull
        h = tp / hc.SAMPLES / hc.PLANT_STEPS
        self._w, nk = hc.memory_weights(hull, h, hc.MEMORY_PERIODS * tp)
        self._lag = np.arange(nk + 1) * h
        self._ainf = hc.a_infinity_matrix(hull)

    def __getattr__(self, name):
        return getattr(self._hull, name)

    def coefficients(self, w):
        _, _, f = self._hull.coefficients(w)
        w = np.asarray(w, dtype=float)
        kc = np.einsum("wq,qij->wij", np.cos(np.multiply.outer(w, self._lag)), self._w)
        ks = np.einsum("wq,qij->wij", np.sin(np.multiply.outer(w, self._lag)), self._w)
        zero = w == 0
        ksw = np.empty_like(ks)
        ksw[~zero] = ks[~zero] / w[~zero, None, None]
        ksw[zero] = np.einsum("q,qij->ij", self._lag, self._w)  # the limit w -> 0
        return self._ainf[None] - ksw, kc, f


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", default="1,2", help="i,j: the Hs and Te bins (0-based)")
    ap.add_argument("--windings", default="1,2,3,4,8,16",
                    help="fixed windings to solve (empty: none)")
    ap.add_argument("--search", action="store_true",
                    help="also the record optimum as the matrix finds it (the windings "
                         "searched) and skip the plant's model")
    a = ap.parse_args()
    i, j = (int(v) for v in a.bin.split(","))
    spec = matrix_spec(hs="0.5,1,1.5,2", te="5,6,7,8", realizations=1, device="buoy",
                       dofs="surge,heave,pitch", controller="mpc", forecast="perfect,ar")
    p = hull_problem_of(spec)
    wave, info = wave_of(spec, i, j, 0)
    tp = float(info["tp"])
    print(f"bin Hs {spec.hm0[i]:g} m, Te {spec.period[j]:g} s (Tp {tp:.4f} s), seed 0, record "
          f"{info['repeat_period']:.1f} s, {waves_in(wave)} waves; load {os.getloadavg()}")

    def solve(hull, windings):
        t = time.process_time()
        r = optimum(hull, p["pendulum"], wave, wave_info=info, winding=windings,
                    harmonics=p["harmonics"], pto=p["pto"], pivot=p["pivot"],
                    pitch_inertia=p["pitch_inertia"], geometry=p["geometry"])
        return r, time.process_time() - t

    modes = (waves_in(wave), 0)
    fd, s = solve(p["hull"], modes)
    print(f"record optimum (rotation, swinging), frequency domain: {fd.power_w:.3f} W, "
          f"winding {fd.winding}; {fd.status}; {s:.0f} s CPU")
    if a.search:
        t = time.process_time()
        r = solve_record(p, wave, info)
        print(f"record optimum, windings searched (solve_record, the matrix's): "
              f"{r.power_w:.3f} W ({r.power_w / fd.power_w:.5f} of the two modes'), "
              f"winding {r.winding}; {r.status}; {time.process_time() - t:.0f} s CPU",
              flush=True)
    else:
        pl, s = solve(PlantHull(p["hull"], tp), modes)
        print(f"the same on the plant's model: {pl.power_w:.3f} W "
              f"({pl.power_w / fd.power_w:.5f} of it), winding {pl.winding}; {s:.0f} s CPU")
    for k in (int(v) for v in a.windings.split(",") if v):
        r, s = solve(p["hull"], (k,))
        print(f"winding {k:3d}: {r.power_w:.3f} W ({r.power_w / fd.power_w:.5f} of the record "
              f"optimum); {r.status}; {s:.0f} s CPU", flush=True)


if __name__ == "__main__":
    main()
