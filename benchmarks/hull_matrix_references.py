"""The hull's causal power matrix against record optima found two ways: the causal store's
own (computed before the winding search: rotation and swinging) and an omniscient store of
the same bins computed with the search (the windings between them on long records).

The causal runs do not depend on how the optimum was found beyond its start (the pump's
where the optimum rotates or swings through the upright, as both do here), so a causal store
and an omniscient one of the same bins and records give each causal run's fraction of the
searched optimum. Prints, per bin: both optima, the perfect and AR runs, their fractions
of each, and whether the unsearched bins agree to the bit.

    python benchmarks/hull_matrix_references.py CAUSAL_STORE OMNISCIENT_STORE [--scatter CSV]

With ``--scatter`` (the power matrix's: ``hs``, ``te``, ``frequency``), the annual energies
8766 h x sum P f of the searched optimum and of each forecast's runs, every bin counted.
"""

from __future__ import annotations

import argparse

import numpy as np
import xarray as xr

from parapend.performance import CAUSAL_SLACK


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("causal")
    ap.add_argument("omniscient")
    ap.add_argument("--scatter")
    a = ap.parse_args()
    c = xr.open_zarr(a.causal, consolidated=False)
    o = xr.open_zarr(a.omniscient, consolidated=False)
    hs, te = c["hm0"].values, c["te"].values
    assert np.array_equal(hs, o["hm0"].values) and np.array_equal(te, o["te"].values)
    pc, po = c["power"].values[..., 0], o["power"].values[..., 0]
    perf = c["causal_perfect_power"].values[..., 0]
    ar = c["causal_ar_power"].values[..., 0]
    print("Hs (m)  Te (s)  two modes (W)  searched (W)  ratio     perfect (W)  of two  of "
          "searched  AR (W)  of searched")
    counted = {"two": [0, 0], "searched": [0, 0]}
    same = 0
    for i, h in enumerate(hs):
        for j, t in enumerate(te):
            if not (c["done"].values[i, j, 0] and o["done"].values[i, j, 0]):
                print(f"{h:5g}  {t:6g}  not in both stores")
                continue
            r = po[i, j] / pc[i, j]
            same += pc[i, j] == po[i, j]
            print(f"{h:5g}  {t:6g}  {pc[i, j]:13.3f}  {po[i, j]:12.3f}  {r:.5f}  "
                  f"{perf[i, j]:11.3f}  {perf[i, j] / pc[i, j]:6.4f}  "
                  f"{perf[i, j] / po[i, j]:11.4f}  {ar[i, j]:7.2f}  {ar[i, j] / po[i, j]:.4f}")
            for name, ref in (("two", pc[i, j]), ("searched", po[i, j])):
                for k, run in enumerate((perf[i, j], ar[i, j])):
                    counted[name][k] += run <= ref * (1 + CAUSAL_SLACK)
    print(f"bins whose optimum is the same to the bit: {same}")
    for name, (p, q) in counted.items():
        print(f"within CAUSAL_SLACK ({CAUSAL_SLACK:g}) of the {name} optimum: perfect {p}, "
              f"AR {q}")
    if a.scatter:
        from parapend.performance.annual import read_scatter

        f = read_scatter(a.scatter, tuple(hs), tuple(te), "te")
        aep = {k: 8766.0 * float(np.nansum(v * f)) / 1e6
               for k, v in (("two modes", pc), ("searched", po), ("perfect", perf),
                            ("AR", ar))}
        print("annual energy (MWh/yr, 8766 h x sum P f, every bin counted): "
              + "; ".join(f"{k} {v:.4f}" for k, v in aep.items())
              + f"; perfect {aep['perfect'] / aep['searched']:.4f} and AR "
              f"{aep['AR'] / aep['searched']:.4f} of the searched optimum's")


if __name__ == "__main__":
    main()
