"""How a hull's sea-state mean power and its 95 % interval settle with the record's length.

For the embedded barge (``parapend buoy --dofs surge,heave,pitch``'s defaults) in one sea
state, ``R`` realizations (seeds 0..R-1) of records of each length in ``--waves`` (peak
periods): each length's mean power, its Student t-interval (``parapend.confidence``), the
spread and the time, as a table on stdout and, with ``--plot``, a PNG of the mean and its
interval against the length (log axis). The docs' table (docs/hull.md) comes from it.

    python benchmarks/hull_record_statistics.py --waves 4,10 --realizations 3
    python benchmarks/hull_record_statistics.py --waves 4,10,50,200 --realizations 5 \\
        --plot docs/_build/hull_record_statistics.png

Records beyond about 10 waves need the hull's near-linear record solver (refused without
it: that length's row says so and the run goes on). Each length runs with a time limit per
realization set (``--time-limit``, s), so a slow length gives a partial, marked row.
"""

from __future__ import annotations

import argparse
import math
import time


def run(waves: float, realizations: int, hs: float, tp: float, time_limit: float) -> dict:
    import parapend
    from parapend.errors import ParameterError

    t0 = time.perf_counter()
    try:
        r = parapend.buoy(dofs="surge,heave,pitch", hs=hs, tp=tp, repeat_period=waves * tp,
                          seed=0, realizations=realizations, time_limit=time_limit)
    except ParameterError as err:
        return {"waves": waves, "refused": str(err).split(";")[0]}
    return {"waves": waves, "seconds": time.perf_counter() - t0, "mean": r.mean_power_w,
            "ci": r.power_ci_w, "half": r.power_ci_half_width_w, "std": r.power_std_w,
            "solved": r.realizations_solved, "done": len(r.realization_seeds),
            "partial": r.status == "time_limit", "powers": r.realization_powers_w}


def table(rows, realizations: int) -> str:
    head = (f"{'waves':>6} {'records':>8} {'mean (W)':>10} {'95 % interval (W)':>24} "
            f"{'+- (%)':>7} {'std (W)':>9} {'time (s)':>9}")
    out = [head, "-" * len(head)]
    for r in rows:
        if "refused" in r:
            out.append(f"{r['waves']:>6g} refused: {r['refused']}")
            continue
        ci = ("-" if r["ci"] is None else f"{r['ci'][0]:.5g} to {r['ci'][1]:.5g}")
        rel = ("-" if r["half"] is None or not r["mean"] else
               f"{100 * r['half'] / r['mean']:.3g}")
        std = "-" if r["std"] is None else f"{r['std']:.4g}"
        mark = " PARTIAL" if r["partial"] else ""
        out.append(f"{r['waves']:>6g} {r['solved']:>3d} of {realizations:<3d}"
                   f"{r['mean']:>10.5g} {ci:>24} {rel:>7} {std:>9} "
                   f"{r['seconds']:>9.1f}{mark}")
    return "\n".join(out)


def plot(rows, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if "refused" not in r and r["mean"] is not None]
    fig, ax = plt.subplots(figsize=(5.5, 3.5))
    for r in ok:
        ax.plot([r["waves"]] * len(r["powers"]),
                [p for p in r["powers"] if p is not None and math.isfinite(p)], ".",
                color="0.6")
        if r["ci"] is not None:
            ax.errorbar(r["waves"], r["mean"], yerr=r["half"], fmt="o", color="C0", capsize=4)
        else:
            ax.plot(r["waves"], r["mean"], "o", color="C0")
    ax.set_xscale("log")
    ax.set_xlabel("record length (peak periods)")
    ax.set_ylabel("mean power (W)")
    ax.set_title("embedded barge: mean power and its 95 % interval", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--waves", default="4,10,50,200",
                    help="record lengths in peak periods, a comma list (default 4,10,50,200)")
    ap.add_argument("--realizations", type=int, default=5)
    ap.add_argument("--hs", type=float, default=1.5)
    ap.add_argument("--tp", type=float, default=6.0)
    ap.add_argument("--time-limit", type=float, default=3600.0,
                    help="seconds per length (its realizations finished by then)")
    ap.add_argument("--plot", metavar="PNG", help="draw the figure into this file")
    a = ap.parse_args()
    rows = []
    for w in (float(x) for x in a.waves.split(",")):
        rows.append(run(w, a.realizations, a.hs, a.tp, a.time_limit))
        print(table(rows[-1:], a.realizations).splitlines()[-1], flush=True)
    print(f"\nembedded barge, Hs {a.hs:g} m, Tp {a.tp:g} s, seeds 0..{a.realizations - 1}:")
    print(table(rows, a.realizations))
    if a.plot:
        plot(rows, a.plot)
        print(f"written: {a.plot}")


if __name__ == "__main__":
    main()
