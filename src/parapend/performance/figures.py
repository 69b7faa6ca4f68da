"""The figures a reader of a WEC paper expects, drawn from a power-matrix Dataset: the power
matrix as a table of numbers on a colour scale, the capture width against the period, and
the scatter diagram with each bin's energy-weighted contribution; and the text report."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_capture_width", "plot_matrix", "plot_scatter", "text_report"]


def _period(ds) -> str:
    return "tp" if "tp" in ds.dims else "te"


def _label(pk: str) -> str:
    return "energy period $T_e$ (s)" if pk == "te" else "peak period $T_p$ (s)"


def _table_image(ax, ds, values, cmap, fmt, cbar_label, fig, mask=None, labels=None):
    """``values`` (hm0 x period) as coloured cells with their numbers written in."""
    import matplotlib.colors as mcolors

    pk = _period(ds)
    x = ds[pk].values
    y = ds["hm0"].values
    v = np.ma.masked_invalid(values if mask is None else np.where(mask, values, np.nan))
    xe = ds[f"{pk}_edges"].values.copy()
    ye = ds["hm0_edges"].values.copy()
    # the first MHKiT edge is 0: draw the first cell as wide as its neighbour
    xe[0] = x[0] - (xe[1] - x[0])
    ye[0] = y[0] - (ye[1] - y[0])
    finite = v.compressed()
    norm = mcolors.Normalize(vmin=float(finite.min()) if finite.size else 0.0,
                             vmax=float(finite.max()) if finite.size else 1.0)
    mesh = ax.pcolormesh(xe, ye, v, cmap=cmap, norm=norm, shading="flat")
    cm = mesh.get_cmap()
    ax.grid(False)
    size = 8 if max(x.size, y.size) <= 12 else 6
    for i, h in enumerate(y):
        for k, t in enumerate(x):
            val = values[i, k]
            if mask is not None and not mask[i, k]:
                continue
            text = None if labels is None else labels[i][k]
            if labels is not None and text is None:
                continue
            if not np.isfinite(val):
                ax.text(t, h, text or "n/a", ha="center", va="center", fontsize=size,
                        color="0.3")
                continue
            r, g, b, _ = cm(norm(val))
            dark = 0.299 * r + 0.587 * g + 0.114 * b < 0.5
            ax.text(t, h, text or format(val, fmt), ha="center", va="center", fontsize=size,
                    color="white" if dark else "black")
    ax.set_xticks(x)
    ax.set_yticks(y)
    ax.set_xticklabels([f"{t:g}" for t in x], rotation=90 if x.size > 8 else 0)
    ax.set_yticklabels([f"{h:g}" for h in y])
    ax.set_xlabel(_label(pk))
    ax.set_ylabel("significant wave height $H_{m0}$ (m)")
    cb = fig.colorbar(mesh, ax=ax)
    cb.set_label(cbar_label)
    return mesh


def plot_matrix(ds, path=None):
    """The power matrix: mean optimum power (W) of each bin, numbers on a colour scale."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..plotting import _finish
    from ..style import figure_style

    with figure_style():
        n = ds.sizes[_period(ds)]
        fig, ax = plt.subplots(figsize=(max(6.0, 0.75 * n + 2.5), max(4.0, 0.45 *
                                                                       ds.sizes["hm0"] + 2)))
        _table_image(ax, ds, ds["power_mean"].values, "viridis", ".3g",
                     "mean optimum power (W)", fig)
        ax.set_title(f"power matrix: mean over {_records(ds.sizes['realization'])} of "
                     f"{_waves(ds)} peak periods per bin", fontsize=9)
        return _finish(fig, path)


def _records(n: int) -> str:
    """``1 record``, ``3 records``."""
    return f"{n} record" + ("" if n == 1 else "s")


def _waves(ds) -> str:
    import json

    return f"{json.loads(ds.attrs['sweep'])['waves']:g}"


def plot_capture_width(ds, path=None):
    """Capture width P / J (m) against the period, one line per Hm0 bin, with the range
    (min to max over the realizations) shaded."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..plotting import _finish
    from ..style import figure_style

    pk = _period(ds)
    x = ds[pk].values
    with figure_style():
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        for i, h in enumerate(ds["hm0"].values):
            y = ds["capture_width_matrix"].values[i]
            line, = ax.plot(x, y, "o-", ms=3, lw=1.0, label=f"$H_{{m0}}$ = {h:g} m")
            ax.fill_between(x, ds["capture_width_min"].values[i],
                            ds["capture_width_max"].values[i], color=line.get_color(),
                            alpha=0.15, lw=0)
        cw = ds["capture_width_matrix"].values
        cw = cw[np.isfinite(cw)]
        if cw.size and cw.min() > 0 and cw.max() > 20 * cw.min():
            ax.set_yscale("log")  # two decades and more: every line readable
        ax.set_xlabel(_label(pk))
        ax.set_ylabel("capture width $P/J$ (m)")
        ax.set_title("capture width of the mean optimum (shaded: min to max over the "
                     "records)", fontsize=9)
        ax.legend(loc="lower left", bbox_to_anchor=(1.01, 0.0), frameon=False, fontsize=7)
        return _finish(fig, path)


def plot_scatter(ds, path=None):
    """The site's scatter diagram (share of the year, %) with each bin's energy-weighted
    contribution to the annual energy (% of the AEP) written in the cells."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..plotting import _finish
    from ..style import figure_style

    f = ds["frequency"].values
    # the device's power (never below 0: a bin with a negative optimum is at rest)
    p = ds["power_matrix"].values if "power_matrix" in ds else ds["power_mean"].values
    e = np.where(f > 0, np.nan_to_num(p) * f, 0.0)
    share = 100 * e / e.sum() if e.sum() > 0 else np.zeros_like(e)
    with figure_style():
        n = ds.sizes[_period(ds)]
        fig, ax = plt.subplots(figsize=(max(6.0, 0.75 * n + 2.5), max(4.0, 0.45 *
                                                                       ds.sizes["hm0"] + 2)))
        labels = [[(f"{100 * f[i, k]:.2g}% yr\n{share[i, k]:.2g}% E"
                    + ("" if np.isfinite(p[i, k]) else "\nno power")) if f[i, k] > 0 else None
                   for k in range(f.shape[1])] for i in range(f.shape[0])]
        _table_image(ax, ds, 100 * f, "Blues", ".2g", "share of the year (%)", fig,
                     labels=labels)
        aep = ds.attrs.get("annual_energy_mwh")
        bounds = ds.attrs.get("annual_energy_mwh_bounds")
        what = (f"{aep:.4g} MWh/yr" if aep is not None else
                _range(bounds[0], bounds[1], "MWh/yr") + ", incomplete"
                if bounds is not None else None)
        ax.set_title("scatter diagram: share of the year (% yr, colour) and of the annual "
                     f"energy (% E; {what})" if what is not None
                     else "scatter diagram", fontsize=9)
        return _finish(fig, path)


def _range(lo, hi, unit: str = "") -> str:
    """``lo to hi`` (4 digits, ``unit`` after), or ``at least lo`` without an upper end
    (None or NaN)."""
    tail = f" {unit}" if unit else ""
    if hi is None or not np.isfinite(hi):
        return f"at least {lo:.4g}{tail} (no upper bound)"
    return f"{lo:.4g} to {hi:.4g}{tail}"


#: SI prefixes of the text report, largest first
_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"))


def with_unit(value, unit: str, digits: int = 4, smallest: str = "m") -> str:
    """``value`` (in ``unit``) to ``digits`` significant digits with the SI prefix that
    puts it in [1, 1000): ``with_unit(41000.0, "Wh")`` is ``"41 kWh"``, ``with_unit(0.05,
    "W")`` ``"50 mW"``. Prefixes below ``smallest`` ("m" or "") are not used; zero is
    ``"0 unit"``, a value that is not finite ``"n/a"``. The prefix is chosen after the
    rounding, so 999.96 W is ``"1 kW"``, never ``"1000 W"``."""
    v = float(value)
    if not np.isfinite(v):
        return "n/a"
    prefixes = _PREFIXES[:[p for _, p in _PREFIXES].index(smallest) + 1]
    r = float(f"{v:.{digits}g}")
    scale, prefix = prefixes[-1]
    for s, p in prefixes:
        if abs(r) >= s:
            scale, prefix = s, p
            break
    if r == 0:
        scale, prefix = 1.0, ""
    return f"{float(f'{r / scale:.{digits}g}'):.{digits}g} {prefix}{unit}"


def _right_table(rows, header) -> str:
    """Plain-text table, every column right-aligned (values with their units)."""
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(v.rjust(w) for v, w in zip(r, widths)) for r in [header, *rows]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _per_year(wh: float) -> str:
    """An annual energy in Wh as Wh, kWh, MWh or GWh per year, by magnitude."""
    text = with_unit(wh, "Wh", smallest="")
    return text if text == "n/a" else text + "/yr"


def _hull(ds) -> bool:
    """The store's spec is the hull's (``dofs`` other than heave alone)."""
    import json

    return json.loads(ds.attrs.get("sweep") or "{}").get("dofs", "heave") != "heave"


def text_report(ds, out: dict, drawn: list) -> str:
    """The plain-text summary of ``parapend power-matrix``."""
    pk = _period(ds)
    hm0, per = ds["hm0"].values, ds[pk].values
    what = (f"{out['device']} pendulum" if out["device"] != "buoy" else
            "hull (surge, heave, pitch)" if _hull(ds) else "coupled buoy")
    lines = [f"power matrix, {what}: {hm0.size} Hm0 x {per.size} {pk} bins, "
             f"{_records(out['realizations'])} of {out['waves']:g} peak periods each ("
             + (f"seed {out['seeds'][0]}" if len(out["seeds"]) == 1 else
                f"seeds {out['seeds'][0]}..{out['seeds'][-1]}")
             + f"); Te/Tp = {out['te_over_tp']:.6g}",
             f"computed now {out['computed_bins']} bins, found finished "
             f"{out['resumed_bins']}; {out['seconds']:.1f} s ({out['executor']})"
             + (f"; store {out['store']}" if out["store"] else ""), "",
             ("mean electrical power (the take-off's output; mechanical_power beside it "
              "in --json)" if "mechanical_power_mean" in ds else "mean optimum power")
             + ", rows Hm0, columns " + pk + ":"]
    rows = [[f"{h:g} m", *(with_unit(v, "W") for v in ds["power_mean"].values[i])]
            for i, h in enumerate(hm0)]
    lines += [_right_table(rows, ["Hm0 \\ " + pk, *(f"{t:g} s" for t in per)]), ""]
    if "power_ci_low" in ds and np.isfinite(ds["power_ci_low"].values).any():
        lo, hi = ds["power_ci_low"].values, ds["power_ci_high"].values
        rows = [[f"{h:g} m", *("-" if not np.isfinite(a) else
                               f"{with_unit(a, 'W')} to {with_unit(b, 'W')}"
                               for a, b in zip(lo[i], hi[i]))] for i, h in enumerate(hm0)]
        lines += ["95 % interval of each bin's mean (Student t over its solved realizations):",
                  _right_table(rows, ["Hm0 \\ " + pk, *(f"{t:g} s" for t in per)]), ""]
    for key, what, unit in (("peak_torque_nm", "peak torque", "N m"),
                            ("peak_pivot_force_n", "peak bearing load", "N")):
        if out.get(key) is not None:
            rows = [[f"{h:g} m", *("-" if v is None else f"{v:.4g}" for v in out[key][i])]
                    for i, h in enumerate(hm0)]
            lines += [f"{what} ({unit}), each bin's largest over its solved records:",
                      _right_table(rows, ["Hm0 \\ " + pk, *(f"{t:g} s" for t in per)])]
            top, where = out.get(f"site_{key}"), out.get(f"site_{key.rsplit('_', 1)[0]}_bin")
            if top is not None:
                lines += [f"the site's largest {what}: {top:.6g} {unit} (Hm0 {where['hm0']:g} "
                          f"m, {pk} {where[pk]:g} s)", ""]
    for b in out.get("bin_failures") or ():
        lines.append(f"bin Hm0 {b['hm0']:g} m, {pk} {b[pk]:g} s: {b['failed']} of "
                     f"{b['realizations']} records without a resolved answer ("
                     + ", ".join(b["reasons"]) + "); left out of the bin's mean"
                     + ("" if b["failed"] < b["realizations"] else
                        " (the bin has no power: out of the annual energy)"))
    brk = out.get("bins_past_breaking") or ()
    if brk:
        share = out.get("past_breaking_frequency")
        lines.append(f"{len(brk)} bin{'s' if len(brk) > 1 else ''} past breaking (Hs / "
                     "lambda_p > 1/7: no real sea is that steep; solved as linear theory's sea): "
                     + ", ".join(
                         f"(Hm0 {b['hm0']:g} m, {pk} {b[pk]:g} s)" for b in brk[:8])
                     + (" ..." if len(brk) > 8 else "")
                     + ("" if not share else
                        f"; the site gives them {share:.4g} of the year, "
                        f"{out['past_breaking_mwh']:.4g} MWh/yr of the annual energy"))
    if "operating_mode" in ds:
        from .hull_device import MODES

        m = ds["operating_mode"].values
        lines.append("operating mode of the bins: " + "; ".join(
            f"{int((m == v).sum())} {name}" for v, name in (
                *((c, MODES[c]) for c in (1, 3, 2, 0)), (-1, "no result"))
            if (m == v).any()))
    if "operating_mode" in ds and (ds["operating_mode"].values == 0).any():
        lines.append(f"{int((ds['operating_mode'].values == 0).sum())} bins with a negative "
                     "mean optimum: the pendulum rests there (0 W in the power matrix and "
                     "the annual energy)")
    if out["failed_solves"]:
        lines.append(f"{out['failed_solves']} solves did not converge (status in the store; "
                     "left out of the statistics: see the count)")
    c = out.get("causal")
    if c is not None:
        lines += _causal_lines(ds, c, hm0, per, pk)
    a = out["annual_energy"]
    if a is not None:
        p = a["power"]
        eff = "mechanical_power" in a  # with an efficiency the headline is electrical
        names = (("limit_power", "limit"), ("uniform_power", "uniform rotation"),
                 ("mechanical_power", "mechanical"),
                 *(() if eff else (("electrical_power", "electrical"),)),
                 ("radiation_bound_power", "radiation bound"), ("one_way_power", "one-way"))
        def aep(e):
            # an incomplete AEP is never one plain number: its bounds
            if e.get("complete", True) or "wh_bounds" not in e:
                return _per_year(e["wh"])
            lo, hi = e["wh_bounds"]
            return (f"{_per_year(lo)} to {_per_year(hi)}" if hi is not None
                    else f"at least {_per_year(lo)}")

        lines.append(f"mean annual energy (8766 h/yr): {'electrical' if eff else 'optimum'} "
                     f"{aep(p)}"
                     + "".join(f", {label} {aep(a[q])}" for q, label in names if q in a))
        if p.get("mwh_ci"):
            lo, hi = p["mwh_ci"]
            lines.append(f"95 % interval of the annual energy counted: {_per_year(lo * 1e6)} "
                         f"to {_per_year(hi * 1e6)} ({p['ci_method'].split(':')[0]}: "
                         "docs/performance.md)")
        if p.get("counted_frequency") is not None and not p.get("complete", True):
            lines.append(f"completeness: the bins counted hold "
                         f"{100 * p['counted_frequency']:.4g} % of the year's hours")
        if p.get("complete") is True:
            lines.append("complete: every sea state of the site lies in a bin with a result")
        if not p.get("complete", True) and "uncounted_frequency" in p:
            lines.append(f"incomplete: {p['uncounted_frequency']:.4g} of the year has no "
                         f"power (the lower bound counts it at 0 W; the upper: "
                         f"{p.get('upper_bound_note', '-')})")
        if p.get("capacity_factor") is not None:
            lines.append(f"capacity factor {p['capacity_factor']:.4g} "
                         f"({100 * p['capacity_factor']:.3g} % of the rated power's energy)")
        elif p.get("capacity_factor_bounds"):
            lo, hi = p["capacity_factor_bounds"]
            lines.append(f"capacity factor {_range(lo, hi)} (incomplete)")
        if p.get("rest_frequency"):
            lines.append(f"{p['rest_frequency']:.4g} of the year in bins where the optimum is "
                         "negative: the pendulum at rest there, counted at 0 W")
        if p["bins_without_power"]:
            miss = ", ".join(f"(Hm0 {b['hm0']:g} m, {pk} {b[pk]:g} s)"
                             for b in p["bins_without_power"][:8])
            lines.append(f"bins of the site without power (left out of the sum): {miss}"
                         f"{' ...' if len(p['bins_without_power']) > 8 else ''}; "
                         f"{p.get('missing_bin_frequency', p['missing_frequency']):.4g} "
                         "of the year")
        if p.get("outside_frequency"):
            o = p["outside_frequency"]
            lines.append(f"{o['sea_states']} sea states ({o['frequency']:.4g} of the year) "
                         "lie outside the matrix's bins (not counted: see the bounds)")
    if c is not None and "annual_energy" in c:
        lines.append(_side_by_side(c))
    for key in ("netcdf", "zarr", "csv"):
        if out[key]:
            lines.append(f"{key} written to {out[key]}")
    for d in drawn:
        lines.append(f"figure written to {d}")
    return "\n".join(lines)


def _causal_lines(ds, c: dict, hm0, per, pk) -> list:
    """The causal column's tables: each forecast's power matrix (the bin's best of the
    controller's run and rest) and the bins at rest."""
    lines = ["", f"causal receding-horizon control (horizon {c['horizon_peak_periods']:g} "
                 f"peak periods, a plan every {c['update_interval_peak_periods']:g} of them, "
                 + (f"{c['plan_samples']} torque samples per plan interval"
                    if c.get("buoy_controller") is None else
                    f"the hull's controller ({c['planner']} planner)"
                    if c["buoy_controller"].startswith("hull") else
                    f"the buoy's {c['buoy_controller']} controller")
                 + ("" if c.get("speed_limit") is None else
                    f", speed penalty above {c['speed_limit']:g} sqrt(g/l)")
                 + "): storage-corrected "
                 f"mean power over one repeat after a warm-up of "
                 f"{c['warm_up_peak_periods']:g} peak periods from rest, the bin's best of "
                 "the controller and rest"]
    for f in c["forecasts"]:
        name = "perfect forecast" if f == "perfect" else "autoregressive forecast"
        lines.append(f"causal power matrix, {name}, rows Hm0, columns {pk}:")
        rows = [[f"{h:g} m", *(with_unit(v, "W") for v in
                               ds[f"causal_{f}_power_matrix"].values[i])]
                for i, h in enumerate(hm0)]
        lines += [_right_table(rows, ["Hm0 \\ " + pk, *(f"{t:g} s" for t in per)])]
        runs = ds[f"causal_{f}_power"].values
        above = int(ds[f"causal_{f}_power"].attrs.get("above_optimum", 0))
        bad = int((~np.isfinite(runs)).sum()) - above
        if above:
            lines.append(f"{above} of {runs.size} causal runs above their record's "
                         "non-causal optimum (no causal controller beats it: not an answer, "
                         "e.g. a storage correction larger than the work): left out of the "
                         "bins' means")
        if bad:
            body = "hull" if c.get("buoy_controller", "").startswith("hull") else "buoy"
            why = (f"the log names them and their status, e.g. \"solves_failed\": most of "
                   f"the {body}'s horizon solves failed" if c.get("buoy_controller") else
                   "the log names them; \"unresolved\": the plans spun the pendulum past a "
                   "turn per torque sample, see --speed-limit")
            lines.append(f"{bad} of {runs.size} causal runs failed ({why}): left out of the "
                         "bins' means, see the count in --json")
        m = ds[f"causal_{f}_mode"].values
        rest, none = int((m == 0).sum()), int((m == -1).sum())
        if rest or none:
            lines.append(", ".join(
                s for s in (f"{rest} bins at rest (the controller's mean power is not "
                            "positive: 0 W)" if rest else "",
                            f"{none} bins without a causal result" if none else "") if s))
        lines.append("")
    return lines


def _side_by_side(c: dict) -> str:
    """The annual energy of the optimum and of each causal column on one line (bounds
    where incomplete), with the capacity factors."""
    labels = {"optimum": "non-causal optimum", "causal_perfect": "causal, perfect forecast",
              "causal_ar": "causal, AR forecast"}
    parts = []
    for col, e in c["annual_energy"].items():
        if e["complete"]:
            text = _per_year(e["annual_energy_mwh"] * 1e6)
        else:
            lo, hi = e["annual_energy_mwh_bounds"]
            text = (f"{_per_year(lo * 1e6)} to {_per_year(hi * 1e6)} (incomplete)"
                    if hi is not None else f"at least {_per_year(lo * 1e6)} (incomplete, "
                    "no upper bound)")
        if "capacity_factor" in e:
            cf = e["capacity_factor"]
            if cf is not None:
                text += f", capacity factor {cf:.4g}"
            else:
                lo, hi = e["capacity_factor_bounds"]
                text += f", capacity factor {_range(lo, hi)}"
        parts.append(f"{labels.get(col, col) + ':':27s} {text}")
    return "\n".join(["annual energy side by side (8766 h/yr):", *("  " + p for p in parts)])
