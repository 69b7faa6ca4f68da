"""``parapend.buoy(dofs="surge,heave,pitch", ...)``: the input side of the hull problem.

Checks the options, builds the hull's coefficients (:mod:`.hull_data`), the pendulum and
the wave, and returns :func:`.hull_result.hull_answer`'s result (one wave or record) or a
:class:`.hull_result.HullSweepResult` (power against wave period). Options of the heave-only
command that this problem does not take yet are refused by name, never ignored.
"""

from __future__ import annotations

import math

import numpy as np

from .. import limits
from ..defaults import HULL, given
from ..errors import ParameterError, check_int, check_range
from .hull_optimum import waves_in

__all__ = ["hull_buoy", "hull_problem", "parse_dofs", "solve_record"]

#: the hull's degrees of freedom the command takes
DOF_SETS = {("heave",): "heave", ("surge", "heave", "pitch"): "surge,heave,pitch"}


def parse_dofs(text) -> tuple:
    """``"surge,heave,pitch"`` (any order) or ``"heave"`` as a tuple in that order."""
    if isinstance(text, str):
        names = [s.strip().lower() for s in text.split(",") if s.strip()]
    else:
        names = [str(s).strip().lower() for s in (text or ())]
    order = ("surge", "heave", "pitch")
    if len(set(names)) != len(names) or any(n not in order for n in names):
        raise ParameterError(f"dofs: expected heave or surge,heave,pitch, got {text!r:.60}")
    out = tuple(n for n in order if n in names)
    if out not in DOF_SETS:
        raise ParameterError(f"dofs: expected heave or surge,heave,pitch (surge and pitch "
                             f"come together), got {text!r:.60}")
    return out


def _refuse_unsupported(opts: dict) -> None:
    """The heave-only command's options this problem does not take (yet): one line each."""
    later = {"optimize_design": "optimize-design", "mass_bounds": "mass-bounds",
             "length_bounds": "length-bounds", "inertia_bounds": "inertia-bounds",
             "damping_coefficient_bounds": "damping-coefficient-bounds",
             "horizon": "horizon", "update_interval": "update-interval",
             "forecast": "forecast"}
    for key, name in later.items():
        if opts.get(key) is not None:
            raise ParameterError(f"{name}: not available with --dofs surge,heave,pitch yet; "
                                 "drop it")
    if opts.get("controller") not in (None, "optimum"):
        raise ParameterError("controller: the causal controllers run on the heaving buoy "
                             "only; drop --controller with --dofs surge,heave,pitch")


def _pto(opts):
    """The power take-off (:class:`.hull_optimum.HullPTO`) from ``torque_limit`` (N m),
    ``efficiency`` and ``copper_loss`` (W per (N m)^2)."""
    from .hull_optimum import HullPTO
    from .pto import efficiency_pair

    eta = efficiency_pair(opts.get("efficiency"))
    limit = opts.get("torque_limit")
    if limit is not None:
        limit = check_range("torque-limit", limit, 1e-6, 1e12, why="N m")
    r = opts.get("copper_loss")
    r = 0.0 if r is None else check_range("copper-loss", r, 0.0, 1e6, why="W/(N m)^2")
    return HullPTO(efficiency=eta, copper_loss=r, torque_limit=limit)


def _value(opts, name):
    """The option, or the hull's default when the caller did not give it (the heave-only
    command's defaults are for a 1 m buoy, not a 10 m hull)."""
    v = opts.get(name)
    return v if given(v) else HULL.get(name)


def _pendulum(opts):
    from .inputs import _pendulum as build

    return build(_value(opts, "mass"), _value(opts, "length"), _value(opts, "inertia"),
                 _value(opts, "damping_coefficient"))


def _hull(opts):
    """How to build the hull's coefficients (a callable: the BEM runs when it is called,
    after the checks) and the geometry a check can use (or None)."""
    from . import hull_data as hd

    body, mesh, hydro = opts.get("body"), opts.get("mesh"), opts.get("hydro")
    barge_opts = {k: opts.get(k) for k in ("barge_length", "barge_beam", "barge_draft")}
    given_src = [n for n, v in (("mesh", mesh), ("hydro", hydro)) if v is not None]
    if len(given_src) > 1:
        raise ParameterError("hydro: give either --mesh or --hydro, not both")
    if given_src:
        bad = [k for k in ("body", "radius", "draft") if opts.get(k) is not None] + [
            k for k, v in barge_opts.items() if v is not None]
        if bad:
            raise ParameterError(f"{bad[0].replace('_', '-')}: the hull comes from "
                                 f"--{given_src[0]}; drop it")
        if hydro is not None:
            return (lambda: hd.load_hull(hydro, wave_direction=opts.get("wave_direction")),
                    None)
        return (lambda: hd.hull_from_mesh(mesh)), None
    if opts.get("wave_direction") is not None:
        raise ParameterError("wave-direction: needs --hydro (a dataset with several wave "
                             "directions)")
    body = "barge" if body is None else body
    lo, hi = limits.BUOY_SIZE_RANGE
    if body == "barge":
        for k in ("radius", "draft"):
            if opts.get(k) is not None:
                raise ParameterError(f"{k}: the barge takes --barge-length, --barge-beam and "
                                     "--barge-draft; drop it")
        length = check_range("barge-length", _value(opts, "barge_length"), lo, hi, why="m")
        beam = check_range("barge-beam", _value(opts, "barge_beam"), lo, hi, why="m")
        draft = check_range("barge-draft", _value(opts, "barge_draft"), lo, hi, why="m")
        def build():
            try:
                return hd.barge(length, beam, draft, omega="body")
            except ParameterError as exc:  # the builder's own names for the barge's options
                msg = str(exc)
                for name in ("length", "beam", "draft"):
                    if msg.startswith(f"{name}:"):
                        raise ParameterError(f"barge-{msg}") from None
                raise
        return build, {"draft_m": draft, "freeboard_m": draft, "half_length_m": length / 2,
                   "half_beam_m": beam / 2, "body": "barge", "length_m": length,
                   "beam_m": beam}
    for k, v in barge_opts.items():
        if v is not None:
            raise ParameterError(f"{k.replace('_', '-')}: only with --body barge; drop it")
    from ..defaults import BUOY

    if body not in ("cylinder", "sphere"):
        raise ParameterError(f"body: expected barge, cylinder or sphere, got {body!r:.40}")
    r = check_range("radius", BUOY["radius"] if opts.get("radius") is None
                    else opts["radius"], lo, hi, why="m")
    if body == "sphere":
        # a sphere floating at its centre has no pitch stiffness about its waterplane
        # centre: a hull that pitches floats higher (default: half its radius immersed)
        d = check_range("draft", 0.5 * r if opts.get("draft") is None else opts["draft"],
                        lo, hi, why="m")
        top = 2 * r - d
        def build():
            return (hd.sphere_hull(r, draft=d, omega="body"))
    else:
        d = check_range("draft", BUOY["draft"] if opts.get("draft") is None
                        else opts["draft"], lo, hi, why="m")
        top = d  # its mesh: a cylinder of length twice the draft
        def build():
            return (hd.cylinder_hull(r, d, omega="body"))
    return build, {"draft_m": d, "freeboard_m": top, "half_length_m": r, "half_beam_m": r,
                   "body": body, "radius_m": r}


def _pivot(opts, geometry):
    d = _value(opts, "pivot_offset")
    h = _value(opts, "pivot_height")
    for name, v in (("pivot-offset", d), ("pivot-height", h)):
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise ParameterError(f"{name}: expected a finite number of metres, got {v!r:.40}")
    if geometry is not None:
        half, depth, top = geometry["half_length_m"], geometry["draft_m"], \
            geometry["freeboard_m"]
        if abs(d) >= half:
            raise ParameterError(f"pivot-offset: the pivot must lie inside the hull, within "
                                 f"+-{half:g} m of its centre, got {d:g}")
        if not -depth < h < top:
            raise ParameterError(f"pivot-height: the pivot must lie inside the hull, between "
                                 f"{-depth:g} m (its bottom) and {top:g} m (its deck) above "
                                 f"the waterline, got {h:g}")
    return float(d), float(h)


def hull_problem(**opts) -> dict:
    """Everything but the wave, checked, and the hull's coefficients built once (the BEM runs
    after the checks): the pieces :func:`solve_record` solves a wave with (the power matrix
    builds them once per process and solves each bin's record)."""
    _refuse_unsupported(opts)
    pto = _pto(opts)
    pend = _pendulum(opts)
    build, geometry = _hull(opts)
    pivot = _pivot(opts, geometry)  # before the BEM: a pivot outside the hull is refused
    hull = build()
    if not pend.mass < hull.mass:
        raise ParameterError(f"mass: the pendulum's {pend.mass:g} kg is not less than the "
                             f"floating mass {hull.mass:.6g} kg (rho x displaced volume, "
                             "which includes the pendulum)")
    inertia = opts.get("hull_pitch_inertia")
    if inertia is not None:
        inertia = check_range("hull-pitch-inertia", inertia, 1e-6, 1e12, why="kg m^2")
    winding = opts.get("winding")
    windings = (1, 0) if winding is None else (check_int("winding", winding, 0, 16),)
    harmonics = opts.get("harmonics")
    if harmonics is not None:
        harmonics = check_int("harmonics", harmonics, 2, limits.HULL_MAX_HARMONICS)
    return {"hull": hull, "pendulum": pend, "pivot": pivot, "pitch_inertia": inertia,
            "winding": winding, "windings": windings, "harmonics": harmonics,
            "geometry": geometry, "pto": pto}


def solve_record(problem: dict, wave, info, *, check_only: bool = False):
    """One irregular record ``wave`` (described by ``info``) of :func:`hull_problem`'s
    ``problem``: its size and frequencies checked, then solved (rotation one turn per wave
    and swinging unless a winding was given); ``check_only``: the checks alone."""
    from .hull_result import hull_answer

    windings = problem["windings"]
    if problem["winding"] is None:
        windings = (waves_in(wave), 0)
    _check_size(wave, windings, problem["harmonics"])
    amps = np.abs(np.asarray(wave.amplitudes))
    sig = np.nonzero(amps >= 1e-3 * amps.max())[0]
    problem["hull"].check_covers(wave.omega * (sig[0] + 1), wave.omega * (sig[-1] + 1),
                                 name="tp")
    if check_only:
        return None
    return hull_answer(problem["hull"], problem["pendulum"], wave, pivot=problem["pivot"],
                       windings=windings, pitch_inertia=problem["pitch_inertia"],
                       harmonics=problem["harmonics"], wave_info=info,
                       geometry=problem["geometry"], pto=problem["pto"])


def hull_buoy(**opts):
    """The optimum of a pendulum in a surging, heaving, pitching hull (see
    :func:`parapend.buoy`, ``dofs="surge,heave,pitch"``)."""
    from .coupled import Wave
    from .hull_result import hull_answer
    from .inputs import _irregular_wave, _period, parse_periods

    _check_wave_kind(opts)  # before the BEM
    p = hull_problem(**opts)
    hull, pend, pivot, inertia, geometry, pto, windings, harmonics = (
        p[k] for k in ("hull", "pendulum", "pivot", "pitch_inertia", "geometry", "pto",
                       "windings", "harmonics"))
    irregular = any(opts.get(k) is not None for k in ("hs", "tp", "record", "repeat_period",
                                                      "seed"))
    if irregular:
        from ..units import Units

        if opts.get("repeat_period") is None and opts.get("record") is None:
            tp = opts.get("tp") or HULL["tp"]
            opts = dict(opts, repeat_period=HULL["repeat_periods"] * tp)
        wave, info = _irregular_wave(
            opts.get("hs"), opts.get("tp"), _or(opts, "spectrum", "jonswap"),
            _or(opts, "gamma_peak", 3.3), opts.get("repeat_period"), opts.get("seed"),
            _or(opts, "cutoff", 3.0), opts.get("record"), _or(opts, "taper", 0.1),
            Units(pend.length, pend.mass, 9.81, pend.inertia))
        return solve_record(p, wave, info)
    height = check_range("wave-height", _value(opts, "wave_height"), 1e-4, 30.0,
                         why="regular wave height, m")
    periods = parse_periods(opts.get("wave_period"))
    if periods is None:
        periods = np.array([_period(_value(opts, "wave_period"))])
    w = 2 * math.pi / periods
    hull.check_covers(float(np.min(w)), float(np.max(w)), name="wave-period")
    results = []
    for t in periods:
        wave = Wave.regular(height, float(t))
        info = {"kind": "regular", "height_m": height, "period_s": float(t)}
        results.append(hull_answer(hull, pend, wave, pivot=pivot, windings=windings,
                                   pitch_inertia=inertia, harmonics=harmonics,
                                   wave_info=info, geometry=geometry, pto=pto))
    if parse_periods(opts.get("wave_period")) is None:
        return results[0]
    from .hull_result import HullSweepResult

    return HullSweepResult.from_results(periods, results, height)


def _or(opts, name, default):
    """The option, or ``default`` when not given (a 0 or "" given is checked, not replaced)."""
    v = opts.get(name)
    return default if v is None else v


def _check_wave_kind(opts):
    """Refuse, as the heaving buoy's command does, a regular wave's options beside an
    irregular sea and a sea's options beside a regular wave (they were ignored)."""
    irregular = any(opts.get(k) is not None for k in ("hs", "tp", "record", "repeat_period",
                                                      "seed"))
    if irregular:
        for name in ("wave_height", "wave_period"):
            if opts.get(name) is not None:
                raise ParameterError(f"{name.replace('_', '-')}: a regular wave or an "
                                     "irregular sea (--hs, --tp, --record), not both")
    for name in ("spectrum", "gamma_peak", "cutoff", "taper"):
        if opts.get(name) is None:
            continue
        flag = name.replace("_", "-")
        if not irregular:
            raise ParameterError(f"{flag}: an irregular sea's option; needs --hs and --tp "
                                 "(or --record)")
        if name == "taper" and opts.get("record") is None:
            raise ParameterError("taper: needs --record")
        if name in ("spectrum", "gamma_peak") and opts.get("record") is not None:
            raise ParameterError(f"{flag}: not used with --record; drop it")


def _check_size(wave, windings, harmonics):
    """Refuse a record whose motion needs more harmonics than finish in about a minute."""
    from .hull_optimum import HARMONICS_PER_TURN

    n = harmonics or HARMONICS_PER_TURN * max(max(windings), waves_in(wave))
    cap = limits.HULL_MAX_HARMONICS
    if n > cap:
        raise ParameterError(f"repeat-period: the record holds about {waves_in(wave)} waves "
                             f"and needs {n} harmonics ({HARMONICS_PER_TURN} per wave or "
                             f"turn), more than the {cap} that finish in about a minute; use "
                             f"a record of at most {cap // HARMONICS_PER_TURN} waves")
