"""``parapend pto-curve``, and the power take-off and physical-unit options of ``optimize``."""

from __future__ import annotations

import math

from .. import limits
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    SAVE_ALL,
    _add_excitation,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _run,
    _table,
    add_output_options,
)


def add_pto_options(p, torque_limit: bool = True) -> None:
    """``--torque-limit``, ``--efficiency``, ``--efficiency-generating/-motoring``."""
    g = p.add_argument_group("power take-off")
    if torque_limit:
        g.add_argument("--torque-limit", type=_finite_float("torque-limit"),
                       help="|T(t)| <= this, units m g l (> 0)")
        g.add_argument("--torque-limit-nm", type=_finite_float("torque-limit-nm"),
                       help="the torque limit in N m (needs --length, --mass)")
    g.add_argument("--efficiency", type=_finite_float("efficiency"),
                   help="generator and motor efficiency in (0, 1]: electrical power eta p "
                        "when harvesting (p = -T theta' > 0), p / eta when motoring")
    g.add_argument("--efficiency-generating", type=_finite_float("efficiency-generating"),
                   help="eta_g in (0, 1] (overrides --efficiency)")
    g.add_argument("--efficiency-motoring", type=_finite_float("efficiency-motoring"),
                   help="eta_m in (0, 1] (overrides --efficiency)")


def add_unit_options(p, damping: bool = True, torque: bool = False,
                     excitation: bool = True,
                     adds: str = "output adds W, N m, J") -> None:
    """Physical pendulum: ``--length --mass --gravity --frequency --amplitude ...``
    (``--damping-coefficient`` where the command takes a damping, ``--torque-limit-nm``
    with ``torque``, for commands that have no other take-off options; ``--frequency`` and
    ``--amplitude`` only with ``excitation``: a design map's axes stay non-dimensional)."""
    g = p.add_argument_group(f"physical units (docs/units.md); {adds}")
    g.add_argument("--length", type=_finite_float("length"),
                   help="pivot to centre of mass, m")
    g.add_argument("--mass", type=_finite_float("mass"), help="kg")
    g.add_argument("--inertia", type=_finite_float("inertia"),
                   help="moment of inertia about the pivot, kg m^2 (default m l^2)")
    g.add_argument("--gravity", type=_finite_float("gravity"),
                   help="m/s^2 (default 9.81)")
    if excitation:
        g.add_argument("--frequency", type=_finite_float("frequency"),
                       help="base heave frequency, Hz (sets omega = 2 pi f sqrt(l/g))")
        g.add_argument("--amplitude", type=_finite_float("amplitude"),
                       help="base heave displacement amplitude A, m (sets delta = "
                            "-A (2 pi f)^2/g)")
    if damping:
        g.add_argument("--damping-coefficient", type=_finite_float("damping-coefficient"),
                       help="viscous damping c, N m s/rad (sets gamma)")
    if torque:
        g.add_argument("--torque-limit-nm", type=_finite_float("torque-limit-nm"),
                       help="the torque limit in N m (needs --length, --mass)")


def units_of(r):
    """The :class:`parapend.units.Units` of a result's ``units`` description, or of a
    Dataset's attributes (None when it has none)."""
    from ..units import Units

    u = r.attrs if hasattr(r, "attrs") else r.units
    if u is None or "length_m" not in u:
        return None
    return Units(length=u["length_m"], mass=u["mass_kg"], gravity=u["gravity_m_s2"],
                 inertia=u["inertia_kg_m2"])


def physical_lines(r, units) -> list[str]:
    """Text lines with watts, N m and joules beside the non-dimensional numbers."""
    if units is None:
        return []
    out = [f"physical (l = {units.length:g} m, m = {units.mass:g} kg, g = {units.gravity:g} "
           f"m/s^2; power unit {units.power:.6g} W, torque unit {units.torque:.6g} N m, time "
           f"unit {units.time:.6g} s): base {units.frequency(r.omega):.6g} Hz",
           (f"  power {r.power_w:.6g} W" if r.mechanical_power_w is None else
            f"  power (electrical) {r.power_w:.6g} W, mechanical power "
            f"{r.mechanical_power_w:.6g} W")
           + f" ({r.energy_per_cycle_j:.6g} J per cycle), uniform "
           f"{r.uniform_power_w:.6g} W, limit {r.limit_power_w:.6g} W, peak torque "
           f"{r.peak_torque_nm:.6g} N m"]
    if r.motoring_energy_j is not None:
        out.append(f"  motoring energy {r.motoring_energy_j:.6g} J per cycle")
    if r.uniform_pto_power_w is not None:
        out.append(f"  best uniform rotation through the same take-off: mechanical "
                   f"{r.uniform_pto_power_w:.6g} W, electrical "
                   f"{r.uniform_pto_electrical_power_w:.6g} W")
    return out


def like_for_like_rows(r, name: str) -> list[list[str]]:
    """The rows of ``optimize`` with a power take-off: the ideal uniform rotation, the
    uniform rotation through the same take-off, the optimum, the limit; "vs uniform"
    compares the optimum with the uniform rotation through the same take-off, electrical
    with electrical (mechanical without an efficiency or copper loss)."""
    elec = r.mechanical_power is not None  # a lossy take-off: power is the electrical power
    what = "electrical" if elec else "mechanical"
    if r.uniform_pto_feasible:
        uni = [f"best uniform rotation, same take-off ({what})",
               _fmt(r.uniform_pto_electrical_power if elec else r.uniform_pto_power), ""]
        gain = (f"{100 * r.gain_over_uniform_pto:+.2f} %" if r.gain_over_uniform_pto
                is not None else "- (uniform delivers nothing)")
    else:
        uni = ["best uniform rotation, same take-off", "infeasible",
               "no phase within the torque limit"]
        gain = "- (uniform infeasible)"
    mine = r.power
    return [["best uniform rotation, ideal (Eq. 17)", _fmt(r.uniform_power), ""],
            uni,
            [f"{name} ({what})", _fmt(mine), gain],
            ["limit gamma -> 0, ideal (Eqs. 19/24/32)", _fmt(r.limit_power), ""]]


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
    if r.efficiency_generating == 1.0 and r.efficiency_motoring == 1.0:
        out.append("efficiency 1 both ways, no limit: lossless, the ideal problem (its "
                   "Fourier optimum)" if r.method == "fourier" else
                   "efficiency 1 both ways: lossless, solved as without an efficiency")
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
    p.add_argument("--vary", choices=["torque-limit", "efficiency"],
                   help="the varied parameter (default torque-limit)")
    p.add_argument("--gamma", type=_finite_float("gamma"),
                   help="viscous damping gamma in [0, 1e3] (default 0.03; docs/defaults.md)")
    p.add_argument("--harmonics", type=_int,
                   help=f"N, at most {limits.MAX_PTO_HARMONICS} (default 24)")
    p.add_argument("--points", type=_int,
                   help=f"number of values, 2 to {limits.MAX_PTO_POINTS} (default 10)")
    add_pto_options(p)
    add_unit_options(p)
    add_output_options(p, plot="the curve", save="the curve", figures=True)


def _cmd_pto_curve(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_ALL)
    ds = _run(a, progress=_Progress("pto-curve"))
    units = ds.attrs.get("power_unit_w")
    if a.plot:
        _output.save_plot(ds, a.plot)
    if a.save:
        _output.save_result(ds, a.save)
    if a.json:
        return ds.to_dict()
    name = "T_max" if a.vary == "torque-limit" else "eta"
    mech = ds["mechanical_power" if "mechanical_power" in ds else "power"]
    rows = [[f"{v:.6g}", _fmt(p, 8), _fmt(e, 8), "-" if math.isnan(u) else _fmt(u, 8),
             f"{t:.5g}" + ("*" if c == 0 else ""), _fmt(m), str(s)]
            for v, p, e, u, t, m, s, c in zip(ds["value"].values, mech.values,
                                              ds["electrical_power"].values,
                                              ds["uniform_pto_electrical_power"].values,
                                              ds["peak_torque"].values,
                                              ds["motoring_energy"].values,
                                              ds["status"].values,
                                              ds["peak_torque_converged"].values)]
    head = [name, "mech. P", "electrical", "uniform, same", "peak |T|", "motoring E",
            "status"]
    if units is not None:
        mech_w = ds["mechanical_power_w" if "mechanical_power_w" in ds else "power_w"]
        for r, w in zip(rows, mech_w.values):
            r.insert(2, f"{w:.5g}")
        head.insert(2, "P (W)")
    out = [_table(rows, head), "",
           f"ideal optimum {_fmt(ds.attrs['unconstrained_power'], 8)}, best uniform "
           f"{_fmt(ds.attrs['uniform_power'], 8)} (gamma = {ds.attrs['gamma']:g}, N = "
           f"{ds.attrs['harmonics']}); units m g l, m g l / t0",
           "uniform, same: the best uniform rotation through the same take-off, electrical "
           "('-': no phase within the torque limit)"]
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
    if a.save:
        out.append(f"curve written to {a.save}")
    return "\n".join(out)


COMMANDS = {"pto-curve": _cmd_pto_curve}
