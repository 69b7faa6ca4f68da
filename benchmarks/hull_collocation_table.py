"""The hull's causal controller with the collocation planner (``planner="collocation"``)
against its record's non-causal optimum: docs/hull.md's "Causal control" table.

Embedded barge (10 x 4 x 1 m), its default sea state (Hs 1 m, Tp 6 s, JONSWAP 3.3, a record
of 4 Tp, seeds given), :func:`parapend.hydro.hull_control.hull_mpc` with the horizon of 2 Tp,
4 Tp of warm-up, the storage-corrected mean over one repeat, the start the ``buoy``
command picks (:func:`parapend.hydro.hull_control.start_mode` from the optimum's motion);
per seed and forecast: the power, its fraction of the optimum (``solve_record``), the failed
solves, the horizon solves IPOPT ended short of its tolerance (iteration cap), and the update
time's p99 (forecast + solve) against the update interval (0.75 s), the plant's energy
balance residual and the largest turn of the generator in one plant step (rad).

    nice python benchmarks/hull_collocation_table.py --seeds 0 1 2 --forecast perfect
    nice python benchmarks/hull_collocation_table.py --seeds 0 1 2 --forecast ar
    nice python benchmarks/hull_collocation_table.py --seeds 0 --plant-steps 12
    nice python benchmarks/hull_collocation_table.py --seeds 0 1 2 3 --solver compiled
    nice python benchmarks/hull_collocation_table.py --seeds 0 1 2 --tp 8.9 --max-iter 40
    nice python benchmarks/hull_collocation_table.py --seeds 0 1 2 --solver compiled --step kkt
    python benchmarks/hull_collocation_table.py --seeds 0 1 2 --update-interval 0.25
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from parapend.hydro import _hull_collocation as hcol
from parapend.hydro import hull_control as hc
from parapend.hydro.api import hull_problem, solve_record
from parapend.hydro.declared import default_of
from parapend.hydro.inputs import _irregular_wave
from parapend.units import Units


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--forecast", nargs="+", default=["perfect"], choices=["perfect", "ar"])
    ap.add_argument("--tp", type=float, default=6.0,
                    help="peak period, s (default the default sea's 6; its record 4 Tp)")
    ap.add_argument("--planner", default="collocation", choices=["collocation", "lbfgsb"])
    ap.add_argument("--plant-steps", type=int, default=hc.PLANT_STEPS)
    ap.add_argument("--max-turn", type=float, default=None,
                    help="the speed bound, rad a plant step (default MAX_TURN)")
    ap.add_argument("--terminal-weight", type=float, default=None,
                    help="kappa, the weight of the energy left at the horizon's end")
    ap.add_argument("--intervals", type=int, default=None,
                    help="Hermite-Simpson intervals a torque sample (default INTERVALS)")
    ap.add_argument("--max-iter", type=int, default=None,
                    help="the horizon solve's iterations at most (default the planner's)")
    ap.add_argument("--update-interval", type=float, default=0.125,
                    help="peak periods between updates (default hull_mpc's)")
    ap.add_argument("--solver", default=None, choices=["compiled", "ipopt"],
                    help="the horizon's solver (default _hull_collocation.SOLVER)")
    ap.add_argument("--step", default=None, choices=["auto", "kkt", "nullspace"],
                    help="the compiled solver's Newton step (default "
                         "_hull_collocation_ipm.STEP)")
    a = ap.parse_args()
    if a.solver is not None:
        hcol.SOLVER = a.solver
    if a.step is not None:
        from parapend.hydro import _hull_collocation_ipm as ipm

        ipm.STEP = a.step
    if a.intervals is not None:
        hcol.INTERVALS = a.intervals
    if a.max_turn is not None:
        hcol.MAX_TURN = a.max_turn
    p = hull_problem()
    pend = p["pendulum"]
    caps = []
    orig = hc._plan

    def plan(prob, plant, fseg, u0, max_iter):
        r = orig(prob, plant, fseg, u0, max_iter)
        caps.append(getattr(r, "status", 0) == 1)
        return r

    hc._plan = plan
    print(f"planner {a.planner}, {a.plant_steps} plant steps a sample, speed bound "
          f"{hcol.MAX_TURN} rad a plant step, at most {hcol.INTERVALS} intervals a sample, "
          f"terminal weight {a.terminal_weight}, solver {hcol.SOLVER}, max_iter {a.max_iter}, "
          f"update every {a.update_interval:g} Tp"
          + (f", step {a.step}" if a.step else ""))
    print("seed forecast mode optimum_w power_w fraction stored_w failed capped "
          "update_median_s update_p99_s interval_s status wall_s balance_residual "
          "max_turn_per_step", flush=True)
    fr = {fc: [] for fc in a.forecast}
    for seed in a.seeds:
        wave, info = _irregular_wave(1.0, a.tp, "jonswap", 3.3, 4 * a.tp, seed,
                                     default_of("cutoff", None), None,
                                     default_of("taper", None),
                                     Units(pend.length, pend.mass, 9.81, pend.inertia))
        opt = solve_record(p, wave, info)
        winding = int(opt.winding) if opt.winding is not None else 0
        mode = hc.start_mode(winding, opt.mean_angle_deg, opt.swing_amplitude_deg)
        for fc in a.forecast:
            caps.clear()
            t = time.time()
            r = hc.hull_mpc(p["hull"], pend, wave, peak_period=a.tp, pivot=p["pivot"],
                            forecast=fc, mode=mode, planner=a.planner,
                            plant_steps=a.plant_steps, terminal_weight=a.terminal_weight,
                            max_iter=a.max_iter, update_interval=a.update_interval)
            f = r.mean_power_w / opt.power_w
            fr[fc].append(f)
            print(f"{seed} {fc} {mode} {opt.power_w:.1f} {r.mean_power_w:.1f} {f:.3f} "
                  f"{r.stored_w:.1f} {r.failed_solves}/{r.solves} {sum(caps)}/{len(caps)} "
                  f"{r.update_time_median_s:.3f} {r.update_time_p99_s:.3f} "
                  f"{r.update_interval_s:.3f} {r.status} {time.time() - t:.0f} "
                  f"{r.energy_balance_residual:.2g} "
                  f"{np.max(np.abs(r.series['theta_dot'])) * r.units['plant_step_s']:.3f}",
                  flush=True)
    for fc, v in fr.items():
        ok = [x for x in v if math.isfinite(x)]
        print(f"mean {fc}: {np.mean(ok) if ok else math.nan:.3f} over {len(ok)} of {len(v)}, "
              f"min {min(ok) if ok else math.nan:.3f}", flush=True)


if __name__ == "__main__":
    main()
