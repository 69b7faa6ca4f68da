"""``parapend reproduce``: regenerate the paper's tables and figures, compare, write a report.

Writes into ``out``: ``figures/*.png|svg``, ``tables/*.csv``, ``results.json`` (every number
with the parameters that produced it; no timings or versions of other packages, so two runs
give identical files) and ``report.html`` (one self-contained page, figures embedded as PNG
data URIs, with the versions, the environment and the run time in its header).

The report is written whole or not at all: everything goes into a hidden staging directory
``.OUT.parapend-staging-*`` beside ``out``, which then takes the place of ``out`` by renaming
(an older report is renamed aside first and removed after the swap). A run that is killed
leaves the older report as it was, and at worst hidden directories that the next run removes.
"""

from __future__ import annotations

import base64
import contextlib
import csv
import html
import io
import json
import os
import platform
import re
import shutil
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

from . import __version__, paper
from .errors import OutputError
from .fileio import output_error, save_figure, umask, write_text
from .plotting import (
    plot_damping_sweep,
    plot_square_approximations,
    plot_theta_panels,
)
from .results import CONVENTION, to_jsonable

__all__ = ["FIGURES", "REPORT_ENTRIES", "paper_figure", "reproduce"]

#: What a report directory holds; ``reproduce`` replaces only a directory holding nothing else.
REPORT_ENTRIES = frozenset({"figures", "tables", "results.json", "report.html"})


def _save(fig, figdir: Path, name: str) -> dict:
    """Save PNG and SVG (reproducible bytes, 200 dpi); return the PNG bytes for embedding."""
    png = save_figure(fig, figdir / f"{name}.png", close=False)
    save_figure(fig, figdir / f"{name}.svg")
    return {"name": name, "png": png.read_bytes()}


# Each figure: (key, title, paper caption summary, how this run differs, builder)
def _dyn(data):
    return data["figure"], data["numbers"]


def _figures():
    return [
        ("fig1", "Figure 1 (right): coexisting oscillation and period-1 rotation of Eq. 1",
         "At gamma = 0.1, p = 0.8, omega = 2.1 a period-2 oscillation and a period-1 rotation "
         "coexist (Eq. 1, phi from the hanging position).",
         "Both attractors found from recorded initial conditions (plus the mirror rotation), "
         "started on the orbits found by shooting and integrated with DOP853; the rotation's "
         "Floquet multipliers multiply to exp(-gamma T) (Liouville).",
         lambda: _dyn(paper.fig1())),
        ("fig2a", "Figure 2 (left): where period-1 rotations exist and are stable",
         "Curves J (birth), G (loss of stability) and E (stability regained) of period-1 "
         "rotations in the (omega, p) plane, adopted from Horton et al. (2011).",
         "Recomputed at gamma = 0.1 by shooting with Floquet multipliers and continuation in p "
         "through folds (steps of 0.1 in arclength, bifurcations located exactly), for omega "
         "from 1.1 to 3 in steps of 0.1, up to p = 6: J is a fold (multiplier "
         "+1), G and E period doublings (-1). The rotation exists above J and is unstable in "
         "the shaded band between G and E. The paper's operating points are marked: Fig. 1's "
         "(omega, p) = (2.1, 0.8) and Fig. 2's basins at (1.8, 0.5), both where the rotation "
         "is stable.",
         lambda: _dyn(paper.fig2_left())),
        ("fig2b", "Figure 2 (right): basins of attraction at p = 0.5, omega = 1.8",
         "Four coexisting attractors at p = 0.5, omega = 1.8 (damping not stated); the "
         "period-1 rotation's basin is narrow.",
         "At gamma = 0.1 (our choice): the two rotations and a period-2 oscillation seen at "
         "its two phases on the t = 0 section, which makes the paper's four; 200 x 200 grid.",
         lambda: _dyn(paper.fig2_right())),
        ("fig4", "Figure 4: Fourier optima approach a piecewise-constant motion",
         "Optima for increasing N at four (delta, omega) near the 1:2 resonance "
         "(values not listed).",
         "We use (delta, omega) = " + ", ".join(f"({d:g}, {w:g})" for d, w in paper.FIG4_CASES)
         + "; each N is solved to a gradient below 1e-11 by Newton's method, continuing in N. "
         "The four panels look identical, and they are: at gamma = 0 the power of a motion "
         "is P = <q' cos(theta)> = delta omega <cos(2 pi tau) cos(theta)>, so as a function "
         "of tau = omega t / 2 pi the optimal motion does not depend on (delta, omega) (for "
         "delta < 0), and every power scales with omega |delta|: the table divides it out.",
         lambda: _panels_fig(paper.fig4(), "panels")),
        ("fig5", "Figure 5: penalized Euler-Lagrange solutions (Eq. 13)",
         "bvp4c solutions for progressively smaller epsilon, down to 1e-4.",
         "Our BVP solver reaches epsilon = 1e-6 with automatic continuation and an adaptive "
         "mesh; large epsilon gives the uniform rotation omega t + pi, as the paper notes.",
         lambda: _panels_fig(paper.fig5(), "panel")),
        ("fig6", "Figure 6: power against damping",
         "Net power output against gamma; none beyond gamma = 0.0856.",
         "Left: the same curve (sign: positive = harvested; Fourier optimum, N = 32); gamma* "
         "from Newton's method on the convex optimal-power curve. Right: the deficit below "
         "the gamma -> 0 limit on logarithmic axes, which resolves small gamma: the "
         "penalized Euler-Lagrange BVP (epsilon = 2 gamma) approaches the limit like a power "
         "of gamma, while any fixed N levels off at its own gamma = 0 value.",
         _fig6),
        ("fig7", "Figure 7: two-harmonic excitation (Eq. 23)",
         "Left, Fourier optima for increasing N; right, Eq. 22 at epsilon = 1e-4; "
         "transitions at the zeros of q'.",
         "Both panels recomputed; the jumps sit at the exact zeros tau = 0.19036, 0.80964.",
         _fig7),
        ("fig8", "Figure 8 (right): tanh approximation of the square wave (Eq. 26)",
         "Eq. 26 for decreasing alpha at omega = 1.8.",
         "Same construction.",
         lambda: (plot_square_approximations(1.8, (0.2, 0.05, 0.001)), {"omega": 1.8,
                                                                       "alphas": [0.2, 0.05,
                                                                                  0.001]})),
        ("fig9", "Figure 9: non-unique optima for the square wave",
         "Three different N = 40 optima (alpha = 0.001) of equal power (to 6 decimals), "
         "all through (0.5, 2 pi).",
         "Distinct optima from seeded random starts: equal power to about 1e-10, all through "
         "theta = 2 pi at tau = 0.5.",
         lambda: _panels_fig(paper.fig9(), "panel")),
        ("fig10", "Figure 10: the penalty selects the uniform rotation (square wave)",
         "Eq. 27 at epsilon = 0.001 for decreasing alpha approaches omega t + pi.",
         "Left: theta as in the paper. Right: theta - (omega t + pi), the distance to the "
         "uniform rotation, which shrinks with alpha (the table gives its maximum).",
         lambda: _panels_fig(paper.fig10(), "panels")),
    ]


def _panels_fig(data, key):
    panels = data[key] if key == "panels" else [data[key]]
    return plot_theta_panels(panels), data["numbers"]


def _fig6():
    d = paper.fig6()
    return plot_damping_sweep(d["dataset"], extra=d["extra"]), d["numbers"]


def _fig7():
    left, right = paper.fig7_left(), paper.fig7_right()
    fig = plot_theta_panels([left["panel"], right["panel"]])
    return fig, {"left": left["numbers"], "right": right["numbers"]}


FIGURES = ("fig1", "fig2a", "fig2b", "fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "fig10")


def paper_figure(key: str):
    """Recompute one of the paper's figures: returns ``(matplotlib Figure, numbers dict)``."""
    for k, _, _, _, build in _figures():
        if k == key:
            return build()
    raise ValueError(f"figure: expected one of {', '.join(FIGURES)}, got {key!r}")


# ---------------------------------------------------------------------------------------
def _write_table(path: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["quantity", "paper", "parapend", "difference", "note"])
    for r in rows:
        w.writerow([r["quantity"], r["paper"], repr(r["parapend"]),
                    "" if r["difference"] is None else repr(r["difference"]), r["note"]])
    write_text(path, buf.getvalue())


def _fmt(x, nd=6):
    if x is None:
        return ""
    if isinstance(x, str):
        return html.escape(x)
    return f"{x:.{nd}f}" if abs(x) < 1e4 else f"{x:.4g}"


def _diff(r):
    d = r["difference"]
    return d if isinstance(d, float) else None


def _figure_rows(key: str, n) -> list[dict]:
    """The numbers a reader can compare for each figure: paper (where it gives one) and ours."""
    row = paper._row
    pc = paper.PAPER
    if key == "fig1":
        return [row("attractor reached from " + str(tuple(v)), name, n["reached"][name], {},
                    "Initial condition at t = 0 (phi, phi'), Eq. 1 convention.")
                for name, v in n["initial_conditions"].items()] + [
            row("Floquet product of the P1 rotation", None, n["rotation_floquet_product"], {},
                f"Liouville: exp(-gamma T) = {n['liouville_exp_minus_gamma_T']:.10f}.")]
    if key == "fig2a":
        i = n["omega"].index(1.8)
        return [row("birth J of P1 rotation at omega = 1.8 (p)", None, n["p_J"][i], {},
                    "Fold of the shooting branch; the paper's case p = 0.5 lies above it."),
                row("loss of stability G at omega = 1.8 (p)", None, n["p_G"][i], {},
                    "Period doubling; p = 0.5 lies below it, so the rotation is stable.")]
    if key == "fig2b":
        names = [a for a in n["attractors"] if a != "other"]
        return [row("number of attractors", 4.0, float(len(names)), {},
                    "Counting the period-2 oscillation at both phases, as a basin picture "
                    "at fixed forcing phase shows it.")] + [
            row(f"basin fraction: {a}", None, f, {}, "") for a, f in
            zip(n["attractors"], n["basin_fraction"]) if a != "other"]
    if key == "fig4":
        return [row(f"delta = {c['delta']:g}, omega = {c['omega']:g}: N = "
                    f"{c['harmonics'][-1]}", None, c["power"][-1], {},
                    f"limit {c['limit_power']:.6f}, uniform {c['uniform_power']:.6f}; divided "
                    f"by omega |delta|: {c['power'][-1] / (c['omega'] * abs(c['delta'])):.10f}")
                for c in n]
    if key == "fig5":
        return [row(f"power at epsilon = {c['epsilon']:g}", None, c["power"], {},
                    f"{c['mesh_nodes']} mesh nodes, residual {c['max_residual']:.1e}")
                for c in n]
    if key == "fig6":
        return [row("damping threshold gamma*", pc["fig6"]["damping_threshold"],
                    n["damping_threshold"], {}, "Read off the figure in the paper."),
                row("power at gamma = 0 (N = 32)", pc["table1"]["limit"], n["power"][0], {},
                    "The paper's curve approaches the limit 0.3438; N = 32 is just below."),
                row(f"BVP power at gamma = {n['bvp_gamma'][0]:.0e}", None, n["bvp_power"][0],
                    {}, f"{n['limit_power'] - n['bvp_power'][0]:.1e} below the limit (right "
                        "panel).")]
    if key == "fig7":
        taus = n["left"]["switch_tau"]
        return [row("first transition (tau)", pc["section71"]["tau1"], taus[0], {},
                    "Zero of q'; the paper truncates."),
                row("second transition (tau)", pc["section71"]["tau2"], taus[1], {}, ""),
                row("BVP power, epsilon = 1e-4", None, n["right"]["power"], {},
                    "Right panel.")]
    if key == "fig9":
        spread = max(n["power"]) - min(n["power"])
        return [row("power of the distinct optima", pc["table3"]["fourier"], max(n["power"]),
                    {}, f"{len(n['power'])} optima, spread {spread:.1e} (paper: identical to "
                        "6 decimals)."),
                row("theta at tau = 0.5 (rad)", None,
                    max(n["theta_at_half_period"], key=lambda v: abs(v - 6.283185307179586)),
                    {}, "Paper: all pass through (0.5, 2 pi); the worst of ours is shown.")]
    if key == "fig10":
        last = n[-1]
        return [row(f"max |theta - (omega t + pi)| at alpha = {c['square_alpha']:g}", None,
                    c["max_deviation_from_uniform"], {}, "Shrinks with alpha: the penalty "
                    "selects the uniform rotation.") for c in n] + [
            row("theta at tau = 0.5, smallest alpha (rad)", None, last["theta_at_half_period"],
                {}, "Paper: passes through (0.5, 2 pi).")]
    return []


_COLUMNS = (("quantity", "quantity"), ("paper", "paper"), ("parapend", "parapend"),
            ("difference", "difference"), ("note", "why"))


def _cells(r: dict) -> dict:
    return {"quantity": html.escape(r["quantity"]), "paper": _fmt(r["paper"], 4),
            "parapend": _fmt(r["parapend"]), "difference": _fmt(_diff(r)),
            "note": html.escape(r["note"])}


def _html_table(rows: list[dict]) -> str:
    """Rows as an HTML table; a column that is empty in every row is left out."""
    cells = [_cells(r) for r in rows]
    cols = [(k, h) for k, h in _COLUMNS if any(c[k] for c in cells)]
    out = ["<table><tr>" + "".join(f"<th class='{k}'>{h}</th>" for k, h in cols) + "</tr>"]
    for c in cells:
        out.append("<tr>" + "".join(f"<td class='{k}'>{c[k]}</td>" for k, _ in cols) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


_CSS = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
line-height:1.45;color:#222}
h1{font-size:1.6em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:1em 0;font-size:.9em}
td,th{border:1px solid #ccc;padding:.3em .6em;vertical-align:top}
th{background:#f4f4f4;text-align:left}
td.paper,td.parapend,td.difference{font-variant-numeric:tabular-nums;text-align:right;white-space:nowrap}
img{max-width:100%;height:auto;border:1px solid #eee}
.note{color:#555;font-size:.92em}
header.run{background:#f7f7f7;border:1px solid #e2e2e2;padding:.6em 1em;font-size:.9em}
header.run dl{display:grid;grid-template-columns:max-content auto;gap:.1em 1em;margin:0}
header.run dt{color:#555}header.run dd{margin:0;font-family:monospace}
nav.toc ol{columns:2;font-size:.95em}
"""

_TABLES = (("table1", "Table 1: harmonic excitation"),
           ("table2", "Table 2: two-harmonic excitation (Eq. 23)"),
           ("table3", "Table 3: square-wave excitation (Eq. 26, alpha = 0.001)"),
           ("scalars", "Other numbers in the text"))


def environment() -> dict:
    """Versions of parapend, Python and the numerical libraries, and the platform."""
    import matplotlib
    import numpy
    import scipy
    import xarray

    return {"parapend": __version__, "Python": platform.python_version(),
            "NumPy": numpy.__version__, "SciPy": scipy.__version__,
            "matplotlib": matplotlib.__version__, "xarray": xarray.__version__,
            "platform": f"{platform.system()} {platform.machine()}, {os.cpu_count()} CPU(s)"}


def _css_width(png: bytes) -> int:
    """Display width in CSS pixels of a 200-dpi PNG: as at 100 dpi, so that every figure's
    text has the same size on the page (a single panel is not stretched to the full width)."""
    return int.from_bytes(png[16:20], "big") // 2


def _header(run: dict) -> str:
    env = run["environment"]
    items = [("parapend", env["parapend"]),
             ("environment", ", ".join(f"{k} {env[k]}" for k in (
                 "Python", "NumPy", "SciPy", "matplotlib", "xarray"))),
             ("machine", env["platform"]),
             ("generated", run["finished"]),
             ("run time", f"{run['seconds']:.1f} s")]
    dl = "".join(f"<dt>{html.escape(k)}</dt><dd>{html.escape(v)}</dd>" for k, v in items)
    return f"<header class='run'><dl>{dl}</dl></header>"


def _html(results: dict, figures: list[dict], run: dict) -> str:
    t = results["tables"]
    toc = [f"<li><a href='#{k}'>{html.escape(title)}</a></li>" for k, title in _TABLES]
    toc += [f"<li><a href='#{f['key']}'>{html.escape(f['title'])}</a></li>" for f in figures]
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<title>parapend: reproduction of Nandakumar, Wiercigroch &amp; Chatterjee (2012)"
        "</title>", f"<style>{_CSS}</style></head><body>",
        "<h1>Optimum energy extraction from a parametrically excited pendulum: the paper's "
        "results, recomputed</h1>", _header(run),
        "<p>Nandakumar, Wiercigroch &amp; Chatterjee, <i>Mech. Res. Commun.</i> 2012, "
        f"recomputed by parapend {html.escape(__version__)}. Every value in the "
        "<b>parapend</b> column is computed by this run; the <b>paper</b> column holds the "
        "paper's printed values. Differences are parapend minus paper. The numbers are also "
        "in <code>results.json</code> and <code>tables/*.csv</code>, the figures in "
        "<code>figures/</code> (PNG and SVG).</p>",
        f"<p class='note'>Convention: {html.escape(CONVENTION)}. Model: theta'' + gamma "
        "theta' - (1 + q(t)) sin(theta) = T(t); paper case delta = -0.3, omega = 1.8.</p>",
        "<nav class='toc'><h2>Contents</h2><ol>" + "".join(toc) + "</ol></nav>",
    ]
    for key, title in _TABLES:
        parts += [f"<h2 id='{key}'>{html.escape(title)}</h2>", _html_table(t[key])]
    for f in figures:
        uri = base64.b64encode(f["png"]).decode()
        parts += [f"<h2 id='{f['key']}'>{html.escape(f['title'])}</h2>",
                  f"<p><b>Paper:</b> {html.escape(f['paper'])}<br><b>Here:</b> "
                  f"{html.escape(f['here'])}</p>",
                  f"<img alt='{html.escape(f['title'])}' width='{_css_width(f['png'])}' "
                  f"src='data:image/png;base64,{uri}'>"]
        if f["rows"]:
            parts.append(_html_table(f["rows"]))
    parts.append("</body></html>")
    return "\n".join(parts)


# ---------------------------------------------------------------------------------------
# Writing the report whole: a staging directory beside ``out``, swapped into place.
def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return False  # ours, left by an earlier call that failed: no longer in use
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # e.g. another user's process: alive
        return True
    return True


def _clean_stale(parent: Path, name: str) -> None:
    """Remove staging and set-aside directories of ``name`` left by runs that were killed."""
    pat = re.compile(re.escape(f".{name}.parapend-") + r"(staging|old)-(\d+)-")
    with contextlib.suppress(OSError):
        for entry in parent.iterdir():
            m = pat.match(entry.name)
            if m and entry.is_dir() and not entry.is_symlink() and not _pid_alive(
                    int(m.group(2))):
                shutil.rmtree(entry, ignore_errors=True)


def _check_out(out) -> Path:
    """The report directory to (re)place, or an OutputError saying why it may not be."""
    if str(out) == "":
        raise OutputError("cannot write report: expected a directory name, got an empty string")
    out = Path(out)
    try:
        if out.is_symlink():
            out = out.resolve()
        out = Path(os.path.abspath(out))
        if out.exists() and not out.is_dir():
            raise OutputError(f"cannot write report {str(out)!r}: it exists and is not a "
                              "directory")
        cwd = Path.cwd()
        if out == cwd or out in cwd.parents or out.parent == out:
            raise OutputError(f"cannot write report {str(out)!r}: it is the current "
                              "directory or contains it; give a new or report directory")
        for parent in out.parents:
            if parent.exists():
                if not parent.is_dir():
                    raise OutputError(f"cannot write report {str(out)!r}: {str(parent)!r} "
                                      "is a file, not a directory")
                break
        if out.is_dir():
            foreign = sorted(p.name for p in out.iterdir() if p.name not in REPORT_ENTRIES)
            if foreign:
                raise OutputError(
                    f"cannot write report {str(out)!r}: it holds {len(foreign)} entr"
                    f"{'y' if len(foreign) == 1 else 'ies'} that are not part of a parapend "
                    f"report (e.g. {foreign[0]!r}), which replacing it would delete; give a "
                    "new, empty or report directory")
    except OSError as exc:
        raise output_error(out, exc) from None
    return out


def _swap(staging: Path, out: Path) -> None:
    """Move ``staging`` to ``out``; an existing ``out`` is renamed aside, then removed."""
    if not out.exists():
        os.rename(staging, out)
        return
    aside = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.parapend-old-"
                                                         f"{os.getpid()}-"))
    os.rename(out, aside / "report")
    try:
        os.rename(staging, out)
    except BaseException:
        os.rename(aside / "report", out)
        raise
    finally:
        shutil.rmtree(aside, ignore_errors=True)


def _write_all(root: Path, figs: list, progress) -> tuple[dict, list[dict]]:
    figdir, tabdir = root / "figures", root / "tables"
    figdir.mkdir()
    tabdir.mkdir()
    total = len(figs) + 2
    tables = paper.tables()
    for name, rows in tables.items():
        _write_table(tabdir / f"{name}.csv", rows)
    if progress:
        progress(1, total, "tables")
    results = {"parapend_version": __version__, "convention": CONVENTION,
               "paper_case": paper.PAPER_CASE, "tables": tables, "figures": {}}
    rendered = []
    for i, (key, title, paper_text, here, build) in enumerate(figs, start=2):
        fig, numbers = build()
        saved = _save(fig, figdir, key)
        results["figures"][key] = numbers
        rendered.append({"key": key, "title": title, "paper": paper_text, "here": here,
                         "png": saved["png"], "rows": _figure_rows(key, numbers)})
        if progress:
            progress(i, total, key)
    text = json.dumps(to_jsonable(results), indent=1, sort_keys=True)
    write_text(root / "results.json", text)
    return results, rendered


def reproduce(out, progress=None) -> dict:
    """Regenerate every table and figure into directory ``out``; return the results dict.

    The report is built in a hidden staging directory beside ``out`` and moved into place
    when complete, so ``out`` always holds one whole report, old or new (see the module
    docstring). ``out`` may not exist yet (its parents are created), may be empty, or may
    hold an earlier report; a directory holding anything else is refused.

    Parameters
    ----------
    out : str or os.PathLike
        The report directory.
    progress : callable, optional
        ``progress(done, total, label)``, called after each step.

    Returns
    -------
    dict
        What ``results.json`` holds.

    Raises
    ------
    OutputError
        ``out`` cannot be written, or is a directory that is not a report.
    """
    start = time.perf_counter()
    out = _check_out(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _clean_stale(out.parent, out.name)
        staging = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.parapend-staging-"
                                                               f"{os.getpid()}-"))
    except OSError as exc:
        raise output_error(out, exc) from None
    try:
        os.chmod(staging, 0o777 & ~umask())
        figs = _figures()
        results, rendered = _write_all(staging, figs, progress)
        run = {"environment": environment(), "seconds": time.perf_counter() - start,
               "finished": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}
        write_text(staging / "report.html", _html(results, rendered, run))
        _swap(staging, out)
    except OSError as exc:
        raise output_error(out, exc) from None
    finally:  # any failure, KeyboardInterrupt included: no staging directory is left
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)
    if progress:
        progress(len(figs) + 2, len(figs) + 2, "report")
    return results


def contact_sheet(out):
    """One figure holding every figure of the report in ``out`` (its ``figures/*.png``,
    in the report's order), each titled with its name: the ``plot()`` of a
    ``reproduce`` result."""
    import math as _math

    import matplotlib.image as mpimg

    from .plotting import plt
    from .style import figure_style

    figdir = Path(out) / "figures"
    names = [key for key, *_ in _figures() if (figdir / f"{key}.png").exists()]
    if not names:
        raise OutputError(f"cannot read the figures of the report in {str(out)!r}")
    cols = 4
    rows = _math.ceil(len(names) / cols)
    with figure_style():
        fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.6 * rows))
        for ax in axes.flat:
            ax.axis("off")
        for ax, key in zip(axes.flat, names):
            ax.imshow(mpimg.imread(figdir / f"{key}.png"))
            ax.set_title(key, fontsize=9)
        fig.suptitle("parapend reproduce: the paper's figures recomputed")
        fig.tight_layout()
    return fig
