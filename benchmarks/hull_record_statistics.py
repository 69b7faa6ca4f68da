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


def plot(rows, path: str | None = None):
    """The settling figure: each record's power (grey dots), each length's mean and its
    95 % interval against the record's length on a log axis, the longest records' mean
    drawn across as the reference the shorter ones are read against, each length's count
    of records below it. ``rows`` as :func:`run` returns them (or
    the ``rows`` of ``--data``'s JSON). Returns the figure (saved into ``path`` if given)."""
    import matplotlib.pyplot as plt

    ok = [r for r in rows if "refused" not in r and r["mean"] is not None]
    fig, ax = plt.subplots(figsize=(6.0, 3.8))
    ref = max(ok, key=lambda r: r["waves"])
    ax.axhline(ref["mean"], color="C0", lw=0.8, ls=":",
               label=f"{ref['waves']:g}-wave mean")
    for i, r in enumerate(ok):
        pw = [p for p in r["powers"] if p is not None and math.isfinite(p)]
        ax.plot([r["waves"] / 1.1] * len(pw), pw, "_", color="0.55", ms=8,
                label="one record" if i == 0 else None)
        if r["ci"] is not None:
            ax.errorbar(r["waves"], r["mean"], yerr=r["half"], fmt="o", color="C0",
                        capsize=4, label="mean, 95 % interval" if i == 0 else None)
        else:
            ax.plot(r["waves"], r["mean"], "o", color="C0")
        short = "" if r["solved"] == r["realizations"] else f" of {r['realizations']}"
        ax.annotate(f"R = {r['solved']}{short}", (r["waves"], min(pw)), xytext=(0, -10),
                    textcoords="offset points", ha="center", va="top", fontsize=8)
    ax.set_xscale("log")
    ax.set_xticks([r["waves"] for r in ok], [f"{r['waves']:g}" for r in ok])
    ax.minorticks_off()
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo - 0.08 * (hi - lo), hi)
    ax.set_xlabel("record length (peak periods)")
    ax.set_ylabel("mean power (W)")
    ax.set_title("embedded barge, Hs 1.5 m, Tp 6 s: a sea state's mean power", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    if path:
        fig.savefig(path, dpi=120)
    return fig


def save_data(rows, a, path: str) -> None:
    """The measured rows (each length's records' powers, mean, interval, time) as JSON,
    rewritten after each length so an interrupted run keeps what it finished. Rows of other
    lengths already in ``path`` are kept (a length measured again replaces its row): one
    length can be re-run alone."""
    import json
    import os

    if os.path.exists(path):
        with open(path) as fh:
            old = json.load(fh).get("rows", [])
        now = {r["waves"] for r in rows}
        rows = sorted([r for r in old if r["waves"] not in now] + list(rows),
                      key=lambda r: r["waves"])
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
        import matplotlib

        matplotlib.use("Agg")
        plot(rows, a.plot)
        print(f"written: {a.plot}")


if __name__ == "__main__":
    main()
