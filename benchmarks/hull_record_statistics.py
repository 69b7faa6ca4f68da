"""How a hull's sea-state mean power and its 95 % interval settle with the record's length.

For the embedded barge (``parapend buoy --dofs surge,heave,pitch``'s defaults) in one sea
state, ``R`` realizations (seeds 0..R-1) of records of each length in ``--waves`` (peak
periods): each length's mean power, its Student t-interval (``parapend.confidence``), the
spread and the time, as a table on stdout and, with ``--plot``, a PNG of the mean and its
interval against the length (log axis); with ``--data``, the measured rows as JSON (the
docs draw their figure from benchmarks/hull_record_statistics.json at build time). The docs'
table (docs/hull.md) comes from it. ``--realizations`` is one count for every length or a
comma list, one per length (long records cost more, short ones spread more).

    python benchmarks/hull_record_statistics.py --waves 4,10 --realizations 3
    python benchmarks/hull_record_statistics.py --waves 4,10,50,200 --realizations 20,20,10,5 \\
        --data benchmarks/hull_record_statistics.json --plot stats.png

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
    return {"waves": waves, "realizations": realizations,
            "seconds": time.perf_counter() - t0, "mean": r.mean_power_w,
            "ci": r.power_ci_w, "half": r.power_ci_half_width_w, "std": r.power_std_w,
            "solved": r.realizations_solved, "done": len(r.realization_seeds),
            "partial": r.status == "time_limit", "powers": r.realization_powers_w}


def table(rows) -> str:
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
        out.append(f"{r['waves']:>6g} {r['solved']:>3d} of {r['realizations']:<3d}"
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


def save_data(rows, a, path: str) -> None:
    """The measured rows (each length's records' powers, mean, interval, time) as JSON,
    rewritten after each length so an interrupted run keeps what it finished."""
    import json
    import os

    doc = {"device": "embedded barge (buoy --dofs surge,heave,pitch defaults)",
           "hs_m": a.hs, "tp_s": a.tp, "seeds": "0..R-1 per length",
           "ci": "Student t, 95 %", "rows": rows}
    tmp = f"{path}.part"
    with open(tmp, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    os.replace(tmp, path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--waves", default="4,10,50,200",
                    help="record lengths in peak periods, a comma list (default 4,10,50,200)")
    ap.add_argument("--realizations", default="5",
                    help="records per length: one count, or a comma list one per length")
    ap.add_argument("--hs", type=float, default=1.5)
    ap.add_argument("--tp", type=float, default=6.0)
    ap.add_argument("--time-limit", type=float, default=3600.0,
                    help="seconds per length (its realizations finished by then)")
    ap.add_argument("--plot", metavar="PNG", help="draw the figure into this file")
    ap.add_argument("--data", metavar="JSON", help="write the measured rows into this file")
    a = ap.parse_args()
    waves = [float(x) for x in a.waves.split(",")]
    counts = [int(x) for x in a.realizations.split(",")]
    if len(counts) == 1:
        counts = counts * len(waves)
    if len(counts) != len(waves):
        ap.error("--realizations: one count, or one per length in --waves")
    rows = []
    for w, n in zip(waves, counts):
        rows.append(run(w, n, a.hs, a.tp, a.time_limit))
        print(table(rows[-1:]).splitlines()[-1], flush=True)
        if a.data:
            save_data(rows, a, a.data)
    print(f"\nembedded barge, Hs {a.hs:g} m, Tp {a.tp:g} s, seeds 0..R-1 per length:")
    print(table(rows))
    if a.plot:
        plot(rows, a.plot)
        print(f"written: {a.plot}")


if __name__ == "__main__":
    main()
