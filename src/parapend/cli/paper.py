"""``parapend figure | reproduce``: the paper's figures and the full report."""

from __future__ import annotations

from pathlib import Path

from ..errors import ParameterError
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    _blocking_file,
    _check_output,
    _fmt,
    _Progress,
    _run,
    _table,
    _Ticker,
)


def add_parsers(sub) -> None:
    """Add figure and reproduce to the subcommand parser."""
    p = sub.add_parser("figure", help="recompute one of the paper's figures",
                       description="Recompute one of the paper's figures and save it: 1 "
                                   "(uncontrolled motions), 2a/2b (rotation boundaries, "
                                   "basins), 4-10 (optima; 5, 7 and 10 are Euler-Lagrange BVP "
                                   "solutions).")
    p.add_argument("number", choices=["1", "2a", "2b", "4", "5", "6", "7", "8", "9", "10"],
                   help="figure number in the paper")
    p.add_argument("--plot", metavar="PNG",
                   help="output file, PNG, SVG or PDF (default: figN.png in the current "
                        "directory, e.g. fig5.png)")
    p.add_argument("--json", action="store_true", help="print the figure's numbers as JSON")

    p = sub.add_parser("reproduce", help="regenerate the paper's tables and figures, with a report",
                       description="Recompute every table and figure of the paper, compare each "
                                   "number with the paper's and write DIR/report.html, "
                                   "DIR/figures/, DIR/tables/ and DIR/results.json.")
    p.add_argument("--out", metavar="DIR",
                   help="output directory (default: parapend-report)")
    p.add_argument("--json", action="store_true", help="print results.json to stdout")


def _cmd_figure(a) -> dict | str:
    default = a.plot is None
    path = f"fig{a.number}.png" if default else a.plot
    _check_output(path, "--plot", FIGURE_SUFFIXES)
    with _Ticker(f"figure {a.number}"):
        r = _run(a)
    if a.json:
        return r.to_dict()
    how = " (default name; choose another with --plot)" if default else ""
    return f"figure {a.number} written to {r.file}{how}"


def _cmd_reproduce(a) -> dict | str:
    if not a.out.strip():
        raise ParameterError("--out: expected a directory name, got an empty string")
    out = Path(a.out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out: expected a directory, got the file {a.out!r}")
    blocker = _blocking_file(out)
    if blocker is not None:
        raise ParameterError(f"--out: {str(blocker)!r} is a file, not a directory")
    if not out.parent.is_dir():
        raise ParameterError(f"--out: parent directory {str(out.parent)!r} does not exist")
    try:
        _output.probe_dir(out if out.is_dir() else out.parent)
    except _output.OutputError as exc:
        raise ParameterError(f"--out: {exc}") from None
    bar = _Progress("reproduce", delay=0.0)
    res = _run(a, progress=lambda done, total, label: bar(done, total, label))
    if a.json:
        return res.to_dict()
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
