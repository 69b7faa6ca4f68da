"""The pendulum in a hull that surges, heaves and pitches as a power-matrix device
(``--device buoy --dofs surge,heave,pitch``): the hull checked and built as ``parapend buoy
--dofs surge,heave,pitch`` builds it (:func:`parapend.hydro.api.hull_problem`, once per
process), every bin's record checked before any bin runs, and one bin's realization solved
as ``parapend buoy --dofs surge,heave,pitch --hs --tp --repeat-period --seed`` solves it
(:func:`parapend.hydro.api.solve_record`).

The record of bin ``(i, j)``, realization ``r`` is the heave buoy's (:func:`.buoy_device.wave_of`).
Per realization the store keeps the best of rotation (one turn per wave), swinging and rest
(``power``, never below zero; ``mode``), the radiation bound, the one-way power and, with a
lossy take-off (``efficiency`` or ``copper_loss``), the electrical power; all in W.
"""

from __future__ import annotations

import dataclasses
import math

from ..errors import ParameterError

__all__ = ["FAILURES", "MODES", "check_records", "failure_code", "hull_of", "hull_opts",
           "mode_code", "problem", "solve_hull_bin"]

#: the per-realization ``mode`` codes, their index (-1: not computed): rotation turns the
#: pendulum in the sense of a positive pitch, "rotation, reversed" against it (a hull that
#: surges and pitches is not the same problem both ways: which way the generator turns is
#: a design input)
MODES = ("rest", "rotation", "swinging", "rotation, reversed")


def mode_code(res) -> int:
    """The store's code of a record's answer ``res`` (:data:`MODES`): its mode, a rotation
    of negative winding reversed."""
    if res.mode == "rotation" and (getattr(res, "winding", None) or 0) < 0:
        return MODES.index("rotation, reversed")
    return MODES.index(res.mode)


#: the per-realization reason for no resolved answer: an int8 code (-1 not computed)
FAILURES = ("none", "no start converged", "harmonics unresolved",
            "above the radiation bound", "refinement failed", "other")
FAILURE_LONG_NAME = ("why the record has no resolved answer: " + ", ".join(
    f"{i} {name}" for i, name in enumerate(FAILURES)))
#: the per-process hull problems, keyed by the spec's hull
_PROBLEMS: dict = {}
#: the hull options of the spec (besides the pendulum's)
HULL_FIELDS = ("pivot_height", "pivot_offset", "hull_pitch_inertia", "barge_length",
               "barge_beam", "barge_draft", "copper_loss", "torque_limit")


def hull_opts(spec) -> dict:
    """``parapend.buoy``'s keyword arguments for the spec's hull and pendulum (no wave)."""
    opts = {k: getattr(spec, k) for k in HULL_FIELDS}
    opts.update(mass=spec.mass, length=spec.length, inertia=spec.inertia,
                damping_coefficient=spec.damping_coefficient, body=spec.body,
                radius=spec.radius, draft=spec.draft, mesh=spec.mesh, hydro=spec.hydro,
                harmonics=spec.harmonics, efficiency=spec.efficiency, winding=None)
    if opts["mesh"] is not None or opts["hydro"] is not None:
        opts["body"] = None
    return opts


def _key(spec) -> str:
    return repr((sorted(hull_opts(spec).items()), spec.digest))


def problem(spec) -> dict:
    """The spec's hull problem (:func:`parapend.hydro.api.hull_problem`): the checks
    and the hull's coefficients (BEM cached on disk), built once per process."""
    key = _key(spec)
    if key not in _PROBLEMS:
        from ..hydro.api import hull_problem

        # its records within the limits of `buoy` alone (an ideal take-off's records solved
        # matrix-free up to limits.HULL_MAX_RECORD_HARMONICS, a lossy one's up to
        # limits.HULL_MAX_PTO_RECORD_HARMONICS)
        _PROBLEMS[key] = hull_problem(**hull_opts(spec))
    return _PROBLEMS[key]


def hull_of(spec):
    """The spec's :class:`~parapend.hydro.bem.HullHydro`."""
    return problem(spec)["hull"]


def resolve(spec, user: dict):
    """The spec with the hull's defaults filled in as the hull's code resolved them (the
    pendulum, the pivot, the barge), so that the store's identity is the hull solved:
    ``user`` the options as given. Builds the hull (its BEM) after its checks."""
    p = problem(dataclasses.replace(spec, **user))
    pend, geo = p["pendulum"], p["geometry"] or {}
    barge = geo.get("body") == "barge"
    resolved = dict(
        body=geo.get("body", user.get("body")),
        mass=float(pend.mass), length=float(pend.length), inertia=float(pend.inertia),
        damping_coefficient=float(pend.damping_coefficient),
        pivot_offset=float(p["pivot"][0]), pivot_height=float(p["pivot"][1]),
        barge_length=float(geo["length_m"]) if barge else None,
        barge_beam=float(geo["beam_m"]) if barge else None,
        barge_draft=float(geo["draft_m"]) if barge else None,
        # the width facing the waves (they travel along the barge's length)
        width=(float(geo["beam_m"]) if barge else 2 * float(geo["radius_m"])
               if "radius_m" in geo else None))
    out = dataclasses.replace(spec, **{**user, **resolved})
    _PROBLEMS[_key(out)] = p  # the same problem: not built again in this process
    return out


def _fits(spec, waves: float) -> bool:
    """Whether every period bin's record of ``waves`` peak periods fits the hull's size."""
    return all(_fits_bin(spec, j, waves) for j in range(len(spec.period)))


def lengthen(spec, seconds: float):
    """``spec`` with every period bin's record at least ``seconds`` long where the hull's
    solver takes it (``bin_waves``; else the longest it takes, floored to 0.01 peak period, not
    shorter than ``waves``): the default records of 200 peak periods are 18.5 minutes at
    Tp 5.54 s."""
    from .. import limits

    out = []
    for j, tp in enumerate(spec.tp):
        lo = spec.waves
        hi = max(lo, min(seconds / tp, limits.SEA_WAVES_RANGE[1]))
        if hi > lo and not _fits_bin(spec, j, hi):
            if not _fits_bin(spec, j, lo):
                hi = lo  # refused by check_records, naming --waves
            while hi - lo > 0.01:
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if _fits_bin(spec, j, mid) else (lo, mid)
            hi = max(spec.waves, math.floor(lo * 100) / 100)
        out.append(float(hi))
    if all(w == spec.waves for w in out):
        return spec
    return dataclasses.replace(spec, bin_waves=tuple(out))


def _fits_bin(spec, j: int, waves: float) -> bool:
    """Whether period bin ``j``'s record of ``waves`` peak periods fits the hull's size."""
    s = dataclasses.replace(spec, waves=float(waves), bin_waves=None)
    from ..hydro.api import solve_record
    from .buoy_device import wave_of

    try:
        solve_record(problem(spec), wave_of(s, 0, j, 0)[0], None, check_only=True)
    except ParameterError as err:
        return not str(err).startswith("repeat-period:")
    return True


def largest_waves(spec) -> float | None:
    """The largest ``waves`` (to 0.01 peak period) whose records fit every period bin (None
    where not even the shortest does)."""
    from .. import limits

    lo = limits.SEA_WAVES_RANGE[0]
    if not _fits(spec, lo):
        return None
    hi = spec.waves
    while hi - lo > 0.002:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _fits(spec, mid) else (lo, mid)
    best = math.floor(lo * 100) / 100
    while _fits(spec, round(best + 0.01, 2)):  # the bisection's last step, to the 0.01
        best = round(best + 0.01, 2)
    return best


def check_records(spec) -> None:
    """Every period bin's record checked as the hull's code checks it (its size: the harmonics
    it needs, at most ``limits.HULL_MAX_RECORD_HARMONICS`` with an ideal take-off, else
    ``limits.HULL_MAX_PTO_RECORD_HARMONICS``; its band inside the hull's data), before
    any bin runs; refused in one line naming ``--waves`` (and the largest that fits) or the
    period bin. The records of one period bin differ in Hm0 and seed only: the same band
    and, with the amplitudes' shape unchanged, the same size."""
    from ..hydro.api import hull_harmonics_cap, solve_record
    from ..hydro.hull import HARMONICS_PER_TURN
    from .buoy_device import wave_of

    p = problem(spec)
    pk = spec.period_kind
    for j, per in enumerate(spec.period):
        try:
            solve_record(p, wave_of(spec, 0, j, 0)[0], None, check_only=True)
        except ParameterError as err:
            head, _, rest = str(err).partition(": ")
            if head == "repeat-period":
                most = largest_waves(spec)
                cap = hull_harmonics_cap(p["pto"])
                fit = ("no record fits" if most is None
                       else f"at most {most:g} peak periods fit")
                raise ParameterError(
                    f"waves: with --dofs surge,heave,pitch a record is solved with at most "
                    f"{cap} harmonics ({HARMONICS_PER_TURN} per wave, about "
                    f"{cap // HARMONICS_PER_TURN} waves): {fit}, got {spec.waves:g}") from None
            raise ParameterError(f"{pk}: the record of the bin {per:g} s: {rest}") from None


def failure_code(reason: str | None) -> int:
    """The code (:data:`.spec.FAILURES`) of a record's ``headline_reason`` (None: 0)."""
    if not reason:
        return 0
    for name, marks in (("above the radiation bound", ("times the radiation bound",)),
                        ("harmonics unresolved", ("not resolved",)),
                        ("refinement failed", ("refinement to",)),
                        ("no start converged", ("no start converged",
                                                "no mode's search converged"))):
        if any(m in reason for m in marks):
            return FAILURES.index(name)
    return FAILURES.index("other")


#: a record without a resolved answer is solved once more with this many times the default
#: harmonics (other starts on another discretization), within the hull's cap
#: (``limits.HULL_MAX_RECORD_HARMONICS`` for an ideal take-off, else
#: ``HULL_MAX_PTO_RECORD_HARMONICS``)
RETRY_HARMONICS = 1.5


def _retry(spec, wave, info, res):
    """One more solve of a record ``res`` left unresolved, with :data:`RETRY_HARMONICS`
    times the harmonics it had (None where they do not fit the hull's cap or a
    ``harmonics`` was given): its answer when resolved, else ``res`` (whose reason then
    stands)."""
    import logging

    from ..hydro.api import hull_harmonics_cap, solve_record
    from ..hydro.hull import HARMONICS_PER_TURN, waves_in

    p = problem(spec)
    if p["harmonics"] is not None:
        return res
    n = HARMONICS_PER_TURN * max(max(abs(k) for k in p["windings"]), waves_in(wave))
    more = int(math.ceil(RETRY_HARMONICS * n / 2)) * 2
    if more > hull_harmonics_cap(p["pto"]):
        return res
    again = solve_record({**p, "harmonics": more}, wave, info)
    logging.getLogger(__name__).info(
        "hull record Hs %g m, Tp %g s, seed %s: %s; with %d harmonics: %s", info.get("hs"),
        info.get("tp"), info.get("seed"), res.headline_reason, more,
        getattr(again, "headline_reason", None) or "resolved")
    return res if getattr(again, "headline_reason", None) else again


def solve_hull_bin(spec, i: int, j: int, r: int, start: list | None = None) -> dict:
    """The hull's answer to one record: the best mode's power (never below zero), its mode,
    the radiation bound, the one-way power, the mechanical power of a lossy take-off.
    ``start``: a list that receives the causal run's start from the optimum's motion
    (:func:`parapend.hydro.hull_control.start_mode`)."""
    from ..hydro.api import solve_record
    from ..maps.spec import _CODE
    from .buoy_device import wave_of

    wave, info = wave_of(spec, i, j, r)
    res = solve_record(problem(spec), wave, info)
    if getattr(res, "headline_reason", None):
        res = _retry(spec, wave, info, res)
    if start is not None:
        from ..hydro.hull_control import start_mode

        start.append(start_mode(res.winding, res.mean_angle_deg, res.swing_amplitude_deg))
    def num(v):
        return math.nan if v is None else float(v)
    p = num(res.power_w)  # None: no resolved answer (headline_reason), kept as NaN
    reason = getattr(res, "headline_reason", None)
    out = {"power": p, "failure": failure_code(reason)}
    if not reason:  # the generator's rating: located on the optimum's motion
        out.update(peak_torque=num(getattr(res, "peak_torque_nm", None)),
                   peak_pivot_force=num(getattr(res, "peak_pivot_force_n", None)))
    if spec.lossy:
        # the store keeps the mechanical power as "power" (the heave buoy's layout; the
        # Dataset shows the electrical one as power)
        out.update(power=num(res.mechanical_power_w), electrical_power=p)
    # the record's answer is what parapend buoy answers alone: its headline power (a mode
    # that did not converge beside a resolved best one is a note there, not a failure)
    if getattr(res, "headline_reason", None):  # no resolved answer: NaN, not a success
        bad = [m for m in res.modes if not m["success"]]
        head = str(bad[0]["status"]).split(";")[0].strip() if bad else ""
        status = head if head in _CODE and head not in ("converged", "no_power") else "other"
    else:
        status = "no_power" if res.mode == "rest" else "converged"
    owp = res.one_way_power_w
    return {**out, "radiation_bound_power": float(res.radiation_bound_w),
            "one_way_power": math.nan if owp is None else float(owp),
            "mode": mode_code(res), "status": status}
