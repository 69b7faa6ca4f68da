"""``parapend figure | reproduce``: the paper's figures and the full report."""

from __future__ import annotations

from pathlib import Path

from ..errors import ParameterError
from . import _output
from ._common import _check_output, _fmt, _Progress, _table


def add_parsers(sub) -> None:
    """Add figure and reproduce to the subcommand parser."""
    p = sub.add_parser("figure", help="recompute one of the paper's figures",
                       description="Recompute one of the paper's figures and save it: 1 "
                                   "(uncontrolled motions), 2a/2b (rotation boundaries, "
                                   "basins), 4-10 (optima; 5, 7 and 10 are Euler-Lagrange BVP "
                                   "solutions).")
    p.add_argument("number", choices=["1", "2a", "2b", "4", "5", "6", "7", "8", "9", "10"],
                   help="figure number in the paper")
    p.add_argument("--plot", metavar="PNG", required=True, help="output file (PNG or SVG)")
    p.add_argument("--json", action="store_true", help="print the figure's numbers as JSON")

    p = sub.add_parser("reproduce", help="regenerate the paper's tables and figures, with a report",
                       description="Recompute every table and figure of the paper, compare each "
                                   "number with the paper's and write DIR/report.html, "
                                   "DIR/figures/, DIR/tables/ and DIR/results.json.")
    p.add_argument("--out", default="parapend-report", metavar="DIR",
                   help="output directory (default: parapend-report)")
    p.add_argument("--json", action="store_true", help="print results.json to stdout")


def _cmd_figure(a) -> dict | str:
    from ..report import paper_figure

    _check_output(a.plot, "--plot", (".png", ".svg"))
    fig, numbers = paper_figure(f"fig{a.number}")
    _output.save_figure(fig, a.plot)
    if a.json:
        return {"figure": a.number, "file": a.plot, "numbers": numbers}
    return f"figure {a.number} written to {a.plot}"


def _cmd_reproduce(a) -> dict | str:
    from ..report import reproduce

    out = Path(a.out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out: expected a directory, got the file {a.out!r}")
    if not out.parent.is_dir():
        raise ParameterError(f"--out: parent directory {str(out.parent)!r} does not exist")
    bar = _Progress("reproduce")
    res = reproduce(out, progress=lambda done, total, label: bar(done, total))
    if a.json:
        return res
    rows = []
    for key in ("table1", "table2", "table3", "scalars"):
        for r in res["tables"][key]:
            rows.append([key, r["quantity"], _fmt(r["paper"], 4), _fmt(r["parapend"]),
                         _fmt(r["difference"])])
    return "\n".join([_table(rows, ["table", "quantity", "paper", "parapend", "difference"]),
                      "", f"report: {out / 'report.html'}",
                      f"figures: {out / 'figures'}  tables: {out / 'tables'}  "
                      f"numbers: {out / 'results.json'}"])


COMMANDS = {"figure": _cmd_figure, "reproduce": _cmd_reproduce}
