"""``parapend pto-curve``, and the power take-off and physical-unit options of ``optimize``."""

from __future__ import annotations

import math

from .. import limits
from ..errors import ParameterError
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    Default,
    _add_excitation,
    _check_output,
    _dataset_json,
    _excitation_kwargs,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _table,
    given,
)


def add_pto_options(p, torque_limit: bool = True) -> None:
    """``--torque-limit``, ``--efficiency``, ``--efficiency-generating/-motoring``."""
    g = p.add_argument_group("power take-off (issue 9)")
    if torque_limit:
        g.add_argument("--torque-limit", type=_finite_float("torque-limit"), default=None,
                       help="|T(t)| <= this, units m g l (> 0)")
        g.add_argument("--torque-limit-nm", type=_finite_float("torque-limit-nm"),
                       default=None, help="the torque limit in N m (needs --length, --mass)")
    g.add_argument("--efficiency", type=_finite_float("efficiency"), default=None,
                   help="generator and motor efficiency in (0, 1]: electrical power eta p "
                        "when harvesting (p = -T theta' > 0), p / eta when motoring")
    g.add_argument("--efficiency-generating", type=_finite_float("efficiency-generating"),
                   default=None, help="eta_g in (0, 1] (overrides --efficiency)")
    g.add_argument("--efficiency-motoring", type=_finite_float("efficiency-motoring"),
                   default=None, help="eta_m in (0, 1] (overrides --efficiency)")


def add_unit_options(p) -> None:
    """Physical pendulum: ``--length --mass --gravity --frequency --amplitude ...``."""
    g = p.add_argument_group("physical units (docs/units.md); output adds W, N m, J")
    g.add_argument("--length", type=_finite_float("length"), default=None,
                   help="pivot to centre of mass, m")
    g.add_argument("--mass", type=_finite_float("mass"), default=None, help="kg")
    g.add_argument("--inertia", type=_finite_float("inertia"), default=None,
                   help="moment of inertia about the pivot, kg m^2 (default m l^2)")
    g.add_argument("--gravity", type=_finite_float("gravity"), default=None,
                   help="m/s^2 (default 9.81)")
    g.add_argument("--frequency", type=_finite_float("frequency"), default=None,
                   help="base heave frequency, Hz (sets omega = 2 pi f sqrt(l/g))")
    g.add_argument("--amplitude", type=_finite_float("amplitude"), default=None,
                   help="base heave displacement amplitude A, m (sets delta = -A (2 pi f)^2/g)")
    g.add_argument("--damping-coefficient", type=_finite_float("damping-coefficient"),
                   default=None, help="viscous damping c, N m s/rad (sets gamma)")


def wants_pto(a) -> bool:
    return any(getattr(a, k, None) is not None for k in (
        "torque_limit", "torque_limit_nm", "efficiency", "efficiency_generating",
        "efficiency_motoring"))


def apply_units(a, kw: dict):
    """Units from the options, and ``kw`` (optimize's parameters) with omega, delta, gamma
    replaced by the physical ones; refuses a non-dimensional value given beside its
    physical counterpart."""
    from ..units import from_options

    units, params = from_options(length=a.length, mass=a.mass, gravity=a.gravity,
                                 inertia=a.inertia, frequency=a.frequency,
                                 amplitude=a.amplitude,
                                 damping_coefficient=a.damping_coefficient)
    kw = dict(kw)
    if "omega" in params and given(kw.get("omega")):
        raise ParameterError("frequency: give either --frequency or --omega, not both")
    if "delta" in params and kw.get("delta") is not None:
        raise ParameterError("amplitude: give either --amplitude or --delta, not both")
    if "gamma" in params and given(kw.get("gamma")):
        raise ParameterError("damping-coefficient: give either --damping-coefficient or "
                             "--gamma, not both")
    kw.update(params)
    if getattr(a, "torque_limit_nm", None) is not None:
        if units is None:
            raise ParameterError("torque-limit-nm: needs --length and --mass")
        if a.torque_limit is not None:
            raise ParameterError("torque-limit-nm: give either --torque-limit or "
                                 "--torque-limit-nm, not both")
        a.torque_limit = units.from_newton_metres(a.torque_limit_nm)
    return units, kw


def pto_kwargs(a) -> dict:
    return {"torque_limit": getattr(a, "torque_limit", None), "efficiency": a.efficiency,
            "efficiency_generating": a.efficiency_generating,
            "efficiency_motoring": a.efficiency_motoring}


def physical_lines(r, units) -> list[str]:
    """Text lines with watts, N m and joules beside the non-dimensional numbers."""
    if units is None:
        return []
    out = [f"physical (l = {units.length:g} m, m = {units.mass:g} kg, g = {units.gravity:g} "
           f"m/s^2; power unit {units.power:.6g} W, torque unit {units.torque:.6g} N m, time "
           f"unit {units.time:.6g} s): base {units.frequency(r.omega):.6g} Hz",
           f"  power {r.power_w:.6g} W ({r.energy_per_cycle_j:.6g} J per cycle), uniform "
           f"{r.uniform_power_w:.6g} W, limit {r.limit_power_w:.6g} W, peak torque "
           f"{r.peak_torque_nm:.6g} N m"]
    if r.electrical_power_w is not None and r.efficiency_generating is not None:
        out.append(f"  electrical power {r.electrical_power_w:.6g} W")
    if r.motoring_energy_j is not None:
        out.append(f"  motoring energy {r.motoring_energy_j:.6g} J per cycle")
    return out


def pto_lines(r) -> list[str]:
    """Text lines on the PTO: limits, electrical power, peak power, motoring energy."""
    out = []
    if r.torque_limit is not None:
        out.append(f"torque limit {r.torque_limit:.6g} (peak |T| {r.peak_torque:.6g}, "
                   f"violation {r.max_violation:.1e})")
    if r.method == "hermite":
        out.append(f"time domain: {r.intervals} cubic Hermite intervals, interior point; "
                   f"power change at the last doubling {_change(r.refinement_change)}")
    if r.method == "constant-brake":
        out.append(f"constant brake: T = -T_max throughout, {r.harmonics} harmonics; power "
                   f"change from half of them {_change(r.refinement_change)}")
    if r.method == "collocation":
        out.append(f"time domain: {r.intervals} Hermite-Simpson intervals (torque piecewise "
                   f"linear), interior point; electrical power change at the last doubling "
                   f"{_change(r.refinement_change)}")
    if r.peak_torque_converged is False and r.peak_torque_coarse is not None:
        grows = r.peak_torque_coarse is not None and \
            r.peak_torque > 1.5 * r.peak_torque_coarse
        out.append(f"peak torque NOT converged under mesh refinement: {r.peak_torque:.6g} on "
                   f"{r.intervals} intervals, {r.peak_torque_coarse:.6g} on "
                   f"{r.intervals // 2}; "
                   + ("it grows with the mesh (impulsive braking): read it as a lower bound"
                      if grows else "the optimal torque is singular there (many torques give "
                      "the same power): the peak is a property of the mesh")
                   + "; so are peak power and the peak in N m")
        if r.torque_impulse is not None:
            out.append(f"torque impulse over the peak's arc (int |T| dt): "
                       f"{r.torque_impulse:.6g}, change from {r.intervals // 2} intervals "
                       f"{_change(r.torque_impulse_change)}")
    if r.efficiency_generating == 1.0 and r.efficiency_motoring == 1.0 and \
            r.method == "fourier":
        out.append("efficiency 1 both ways, no limit: lossless, the ideal problem (its "
                   "Fourier optimum)")
    elif r.efficiency_generating is not None:
        out.append(f"efficiency: generating {r.efficiency_generating:g}, motoring "
                   f"{r.efficiency_motoring:g}; electrical power {_fmt(r.electrical_power, 8)}"
                   " (exact kink at p = 0, slacks p+ - p- = p)")
    if r.unconstrained_power is not None and r.unconstrained_power != r.power:
        out.append(f"ideal (unlimited, lossless) optimum: {_fmt(r.unconstrained_power, 8)}")
    if r.peak_power is not None:
        out.append(f"peak power {r.peak_power:.6g}; per cycle: harvested "
                   f"{r.harvested_energy:.6g}, motoring {r.motoring_energy:.6g} (m g l)")
    return out


def _change(x) -> str:
    """A refinement change, or what stands in for it when no finer mesh was solved."""
    if x is None or not math.isfinite(x):
        return "not available (no finer mesh solved)"
    return f"{x:.1e}"


def add_parsers(sub) -> None:
    p = sub.add_parser("pto-curve", help="optimal power against torque limit or efficiency",
                       description="Optimal mechanical and electrical power through a power "
                                   "take-off, against the torque limit (from the ideal peak "
                                   "torque down to the smallest feasible limit, by "
                                   "continuation) or against the efficiency.")
    _add_excitation(p)
    p.add_argument("--vary", choices=["torque-limit", "efficiency"], default="torque-limit",
                   help="the varied parameter (default torque-limit)")
    p.add_argument("--gamma", type=_finite_float("gamma"), default=Default(0.03),
                   help="viscous damping gamma in [0, 1e3] (default 0.03)")
    p.add_argument("--harmonics", type=_int, default=24,
                   help=f"N, at most {limits.MAX_PTO_HARMONICS} (default 24)")
    p.add_argument("--points", type=_int, default=10,
                   help=f"number of values, 2 to {limits.MAX_PTO_POINTS} (default 10)")
    add_pto_options(p)
    add_unit_options(p)
    p.add_argument("--plot", metavar="PNG", help="draw the curve (PNG, SVG or PDF)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _cmd_pto_curve(a) -> dict | str:
    from ..pto import plot_pto_curve, pto_curve

    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    kw = {"gamma": a.gamma, "harmonics": a.harmonics, **_excitation_kwargs(a)}
    units, kw = apply_units(a, kw)
    if a.vary == "torque-limit" and (a.torque_limit is not None):
        raise ParameterError("torque-limit: it is the varied quantity with --vary "
                             "torque-limit; drop it")
    from .. import errors

    errors.check_int("harmonics", a.harmonics, 1, limits.MAX_PTO_HARMONICS)
    extra = pto_kwargs(a)
    if a.vary == "torque-limit":
        extra.pop("torque_limit")
    ds = pto_curve(a.vary, points=a.points, units=units, progress=_Progress("pto-curve"),
                   **extra, **kw)
    if a.plot:
        _output.plot(plot_pto_curve, ds, a.plot)
    if a.json:
        return _dataset_json(ds)
    name = "T_max" if a.vary == "torque-limit" else "eta"
    rows = [[f"{v:.6g}", _fmt(p, 8), _fmt(e, 8), f"{t:.5g}" + ("*" if c == 0 else ""),
             _fmt(m), str(s)]
            for v, p, e, t, m, s, c in zip(ds["value"].values, ds["power"].values,
                                           ds["electrical_power"].values,
                                           ds["peak_torque"].values,
                                           ds["motoring_energy"].values, ds["status"].values,
                                           ds["peak_torque_converged"].values)]
    head = [name, "mech. P", "electrical", "peak |T|", "motoring E", "status"]
    if units is not None:
        for r, w in zip(rows, ds["power_w"].values):
            r.insert(2, f"{w:.5g}")
        head.insert(2, "P (W)")
    out = [_table(rows, head), "",
           f"ideal optimum {_fmt(ds.attrs['unconstrained_power'], 8)}, best uniform "
           f"{_fmt(ds.attrs['uniform_power'], 8)} (gamma = {ds.attrs['gamma']:g}, N = "
           f"{ds.attrs['harmonics']}); units m g l, m g l / t0"]
    if (ds["peak_torque_converged"].values == 0).any():
        out.append("* peak torque not converged under mesh refinement (impulsive or singular "
                   "braking): a property of the mesh, not of the motion (optimize --json: "
                   "torque_impulse)")
    if a.vary == "torque-limit":
        if "smallest_feasible_limit" in ds.attrs:
            how = ("a free rotation needs no torque"
                   if ds.attrs["smallest_feasible_status"] == "free rotation" else
                   f"phase 1, {ds.attrs['smallest_feasible_status']}")
            out.append(f"smallest peak torque of a rotation: "
                       f"{ds.attrs['smallest_feasible_limit']:.6g} ({how}); smallest limit "
                       f"solved: {ds.attrs['smallest_solved_limit']:.6g}")
        else:
            out.append(f"smallest limit solved: {ds.attrs['smallest_solved_limit']:.6g}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


COMMANDS = {"pto-curve": _cmd_pto_curve}
