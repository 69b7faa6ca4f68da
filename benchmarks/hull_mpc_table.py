"""The hull's causal controller against its non-causal record optimum (docs/hull.md's table).

Embedded barge (10 x 4 x 1 m), its default sea state (Hs 1 m, Tp 6 s, JONSWAP 3.3, a record
of 4 Tp), seeds given on the command line: the record optimum (``parapend.buoy`` with
``dofs="surge,heave,pitch"``) and :func:`parapend.hydro.hull_control.hull_mpc` with a perfect
and an AR forecast of 2 Tp, 4 Tp of warm-up, the storage-corrected mean over one repeat, in
the optimum's mode, and with a perfect forecast in the other mode; the L-BFGS-B planner
(``planner="lbfgsb"``; the collocation planner's table: hull_collocation_table.py).

    nice python benchmarks/hull_mpc_table.py 0 1 2
"""

import sys
import time

from parapend.hydro.api import hull_problem, solve_record
from parapend.hydro.declared import default_of
from parapend.hydro.hull_control import hull_mpc
from parapend.hydro.inputs import _irregular_wave
from parapend.units import Units


def main(seeds):
    p = hull_problem()
    pend = p["pendulum"]
    print("seed optimum_w mode perfect_w perfect_frac perfect_p99_s ar_w ar_frac ar_p99_s "
          "interval_s failed(perfect,ar) other_mode_perfect_w other_mode_frac", flush=True)
    for seed in seeds:
        wave, info = _irregular_wave(1.0, 6.0, "jonswap", 3.3, 24.0, seed,
                                     default_of("cutoff", None), None,
                                     default_of("taper", None),
                                     Units(pend.length, pend.mass, 9.81, pend.inertia))
        opt = solve_record(p, wave, info)
        mode = "swing" if opt.winding == 0 else "rotate"
        row = [seed, f"{opt.power_w:.1f}", mode]
        fails = []
        for fc in ("perfect", "ar"):
            t = time.time()
            r = hull_mpc(p["hull"], pend, wave, peak_period=6.0, pivot=p["pivot"],
                         forecast=fc, mode=mode, planner="lbfgsb")
            row += [f"{r.mean_power_w:.1f}", f"{r.mean_power_w / opt.power_w:.3f}",
                    f"{r.update_time_p99_s:.3f}"]
            fails.append(f"{r.failed_solves}/{r.solves}")
            print(f"  seed {seed} {fc}: {r.status} {time.time() - t:.0f} s, stored "
                  f"{r.stored_w:.1f} W, balance {r.energy_balance_residual:.2g}", flush=True)
        row += [f"{r.update_interval_s:.3f}", ",".join(fails)]
        other = "rotate" if mode == "swing" else "swing"
        r = hull_mpc(p["hull"], pend, wave, peak_period=6.0, pivot=p["pivot"], mode=other,
                     planner="lbfgsb")
        row += [f"{r.mean_power_w:.1f}", f"{r.mean_power_w / opt.power_w:.3f}"]
        print(" ".join(str(v) for v in row), flush=True)


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]] or [0, 1, 2])
