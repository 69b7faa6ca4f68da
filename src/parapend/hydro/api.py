"""``parapend.buoy``: the coupled optimum of a pendulum inside a floating buoy (docs/buoy.md).

One function, :func:`buoy`, with the options of ``parapend buoy`` as keyword arguments,
returning a frozen :class:`BuoyResult` (one wave) or :class:`BuoySweepResult` (power against
wave period, ``wave_period="FROM:TO:N"``). Everything is in SI units; the field names carry
the unit (``power_w``, ``heave_amplitude_m``, ``peak_torque_nm``).

The work is done by :mod:`.bem` (the body's coefficients), :mod:`.optimum` (the coupled
optimum) and :mod:`.result` (the results, and what a designer reads: the radiation bound and
the fraction of it reached, the capture width, the one-way answer, the free buoy's
response); this module checks the input and builds the wave, the body and the pendulum.
"""

from __future__ import annotations

import math
import os

import numpy as np

from .. import limits
from ..defaults import BUOY, HULL, given
from ..errors import ParameterError, check_int, check_nonnegative, check_positive, check_range
from .declared import check, default_of, expand_inputs, has_inputs
from .hull import HullPTO, waves_in
from .inputs import _irregular_wave, _pendulum, _period, parse_periods
from .result import _solve, optimum

__all__ = ["buoy", "hull_buoy", "hull_problem", "parse_dofs", "parse_periods", "refuse_hull",
           "solve_record"]

#: pendulum parameters ``--optimize-design`` may vary
DESIGN_VARIABLES = ("mass", "length", "inertia", "damping_coefficient")


def _hydro(body, radius, draft, mesh, hydro, wave_direction=None):
    """The body's coefficients on the body's own frequency grid (:func:`.bem.body_frequencies`:
    one mesh and one grid per body, whatever the waves of the call), and its width."""
    from . import bem as hy

    given = [n for n, v in (("mesh", mesh), ("hydro", hydro)) if v is not None]
    if len(given) > 1:
        raise ParameterError("hydro: give either --mesh or --hydro, not both")
    if given and body not in (None, "cylinder"):
        raise ParameterError(f"body: the body comes from --{given[0]}; drop --body")
    if body is None:
        body = "cylinder"
    if given and (radius is not None or draft is not None):
        raise ParameterError(f"{'radius' if radius is not None else 'draft'}: the body comes "
                             f"from --{given[0]}; drop it")
    if hydro is not None:
        return hy.load(hydro, wave_direction=wave_direction), None
    if mesh is not None:
        return hy.from_mesh(mesh, omega="body"), None
    r, d = _dimensions(body, radius, draft)
    if body == "sphere":
        return hy.sphere(r, omega="body"), 2 * r
    return hy.cylinder(r, d, omega="body"), 2 * r


def _heave_hydro(barge, body, radius, draft, mesh, hydro, wave_direction):
    """:func:`_hydro`, or the barge's heave alone (``barge``: :func:`_hull_body`'s builder and
    geometry; its width the beam, across the waves)."""
    if barge is None:
        return _hydro(body, radius, draft, mesh, hydro, wave_direction)
    return barge[0]().heave(), barge[1]["beam_m"]


def _check_kinds(**opts):
    """Refuse, in one line naming the option, a value of the wrong kind where a name, a list
    of names or a path is expected (a number for ``dofs``, ``optimize_design`` or ``mesh``
    raised a bare TypeError)."""
    for name, v in opts.items():
        if v is None:
            continue
        if name == "mesh":
            ok = isinstance(v, (str, os.PathLike))
            want = "a path (str or os.PathLike)"
        else:
            ok = isinstance(v, str) or (isinstance(v, (list, tuple))
                                        and all(isinstance(x, str) for x in v))
            want = "a comma list of names (str) or a list of them"
        if not ok:
            raise ParameterError(f"{name.replace('_', '-')}: expected {want}, got "
                                 f"{type(v).__name__}")


def _dimensions(body, radius, draft):
    """Radius and draft (m) of a parametric body (a sphere's draft is its radius)."""
    body = "cylinder" if body is None else body
    if body == "barge":
        raise ParameterError("body: expected cylinder or sphere here; the barge is taken by "
                             "parapend buoy (heave alone or --dofs surge,heave,pitch)")
    if body not in ("cylinder", "sphere"):
        raise ParameterError(f"body: expected cylinder or sphere, got {body!r:.40}")
    r = check("radius", default_of("radius", radius, "buoy"))
    if body == "sphere":
        if draft is not None:
            raise ParameterError("draft: a sphere floats at its centre (draft = radius); "
                                 "drop --draft")
        return r, r
    d = check("draft", default_of("draft", draft, "buoy"))
    _check_bem_size(r, d)
    return r, d


def _check_bem_size(radius, draft):
    """Refuse a cylinder whose BEM would not finish in about a minute: the influence
    coefficients of its mesh (:func:`.bem.cylinder_work` at the panel radius
    :func:`.bem.cylinder` uses) against ``parapend.limits.BUOY_MAX_BEM_WORK``. A wide,
    shallow body's panels follow the shortest wave solved (:func:`.bem.cylinder_scale`), so
    only a tall one (its panels follow the radius) is refused."""
    from .bem import GEOMETRY_PANELS, cylinder_scale, cylinder_work

    def work(r, d):
        return cylinder_work(r, d, cylinder_scale(r, d) / GEOMETRY_PANELS)

    cap = limits.BUOY_MAX_BEM_WORK
    if work(radius, draft) <= cap:
        return
    # the largest draft that fits, the radius held (a wide body is never refused)
    a, b = radius, draft
    for _ in range(60):
        mid = math.sqrt(a * b)
        a, b = (mid, b) if work(radius, mid) <= cap else (a, mid)
    raise ParameterError(f"draft: a cylinder of radius {radius:g} m and draft {draft:g} m "
                         f"needs a BEM of about {work(radius, draft):.3g} influence "
                         f"coefficients per frequency, more than the {cap:.3g} that finish in "
                         f"about a minute (the panels follow the smaller dimension); use "
                         f"--draft at most {a:.3g} m")


def _parametric_top(body, radius, draft) -> float:
    """The highest frequency (rad/s) of a parametric body's own grid, without its BEM: the
    wave whose length is 12 panel radii (:func:`.bem.body_frequencies`)."""
    from . import bem as hy

    r, d = _dimensions(body, radius, draft)
    scale = r if body == "sphere" else hy.cylinder_scale(r, d)
    return float(hy.body_frequencies(scale / hy.GEOMETRY_PANELS)[-1])


def _check_short(top, periods, body=None, radius=None) -> None:
    """Refuse waves shorter than the body's grid reaches (``top``, rad/s) in one line."""
    if float(np.max(2 * math.pi / periods)) > top * (1 + 1e-9):
        what = "" if radius is None else f" ({body or 'cylinder'} of radius {radius:g} m)"
        raise ParameterError(f"wave-period: the waves are too short for the body's "
                             f"mesh{what}; its frequencies cover periods from "
                             f"{2 * math.pi / top:.4g} s up, got {float(np.min(periods)):g} s")


def _check_harmonics(harmonics, winding, pto):
    """Refuse a regular wave's motion of more harmonics than finish in about two minutes
    (:data:`parapend.limits.BUOY_MAX_HARMONICS`, ``BUOY_MAX_PTO_HARMONICS`` with a power
    take-off), naming the option that set them."""
    from .optimum import HARMONICS_PER_TURN

    cap = limits.BUOY_MAX_PTO_HARMONICS if pto else limits.BUOY_MAX_HARMONICS
    why = "with --efficiency or --torque-limit, " if pto else ""
    if harmonics is not None:
        if harmonics > cap:
            raise ParameterError(f"harmonics: expected at most {cap} ({why}the most that "
                                 f"finish in about two minutes), got {harmonics}")
        return
    n = HARMONICS_PER_TURN * winding
    if n > cap:
        raise ParameterError(f"winding: {winding} turns need {n} harmonics ("
                             f"{HARMONICS_PER_TURN} per turn), more than the {cap} that "
                             f"finish in about two minutes ({why or 'regular wave, '}"
                             f"at most {max(1, cap // HARMONICS_PER_TURN)} turns); or give "
                             f"--harmonics, at least 2 per turn")


def _check_sweep(count, harmonics, winding, pto, time_limit=None):
    """Refuse a sweep over ``count`` wave periods whose estimated time (the periods times one
    period's, :data:`parapend.limits.BUOY_PERIOD_SECONDS` or ``BUOY_PTO_PERIOD_SECONDS``)
    exceeds :data:`parapend.limits.BUOY_MAX_SWEEP_SECONDS`, naming ``--wave-period`` and the
    most periods that fit; with ``time_limit`` the sweep runs under it instead
    (:mod:`parapend.deadline`)."""
    from .optimum import HARMONICS_PER_TURN

    n = harmonics if harmonics is not None else HARMONICS_PER_TURN * winding
    if pto:
        each = limits.BUOY_PTO_PERIOD_SECONDS
    else:
        a, b = limits.BUOY_PERIOD_SECONDS
        each = a + b * (n / 512) ** 2
    cap = limits.BUOY_MAX_SWEEP_SECONDS
    if count * each <= cap or time_limit is not None:
        return
    most = int(cap // each)
    what = "with --efficiency or --torque-limit" if pto else f"of {n} harmonics"
    fix = (f"give at most {most} periods" if most >= 2 else "solve one period at a time")
    if harmonics is not None and not pto:
        fix += " or fewer --harmonics"
    raise ParameterError(f"wave-period: {count} periods {what} need about {count * each:.0f} "
                         f"s ({each:.3g} s each), more than the {cap:g} s a sweep may take "
                         f"without a time limit; {fix}, or give --time-limit SECONDS (a "
                         "partial result, marked time_limit)")


#: a design search estimated longer than this announces its estimate (as horizon and track)
DESIGN_ANNOUNCE_SECONDS = 30.0


def _check_design(count, pto, time_limit=None):
    """Refuse a design search whose estimated time (its solves, :func:`.design.design_solves`,
    times one solve's, :data:`parapend.limits.BUOY_DESIGN_SOLVE_SECONDS`) exceeds
    :data:`parapend.limits.BUOY_MAX_DESIGN_SECONDS`, naming the most variables that fit;
    with ``time_limit`` the search runs under it instead (:mod:`parapend.deadline`)."""
    from .design import design_solves

    each = limits.BUOY_DESIGN_SOLVE_SECONDS[1 if pto else 0]
    cap = limits.BUOY_MAX_DESIGN_SECONDS
    est = design_solves(count) * each
    if est <= cap or time_limit is not None:
        if est > DESIGN_ANNOUNCE_SECONDS:  # long legitimate work: its estimate first
            import logging

            logging.getLogger("parapend.hydro").info(
                "buoy: optimize-design over %d variables: up to %d solves of about %g s, "
                "roughly %.0f s%s (Ctrl-C stops it)", count, design_solves(count), each, est,
                "" if time_limit is None else f", stopped after the time limit {time_limit:g} s")
        return
    fits = [k for k in range(1, count) if design_solves(k) * each <= cap]
    what = " with --efficiency or --torque-limit" if pto else ""
    fix = (f"choose at most {fits[-1]} of them" if fits else
           "drop --efficiency and --torque-limit from the search")
    plural = "s" if count != 1 else ""
    raise ParameterError(f"optimize-design: {count} variable{plural}{what} need up to "
                         f"{design_solves(count)} solves of about {each:g} s "
                         f"({design_solves(count) * each:.0f} s), more than the {cap:g} s a "
                         f"design search may take without a time limit; {fix}, or give "
                         "--time-limit SECONDS (a partial result, marked time_limit)")


def _check_record_harmonics(h, wave, harmonics, winding, record, pto=True):
    """Refuse an optimum over an irregular record whose motion needs more harmonics than
    finish in about two minutes (:data:`parapend.limits.BUOY_MAX_PTO_RECORD_HARMONICS` with
    a power take-off, ``BUOY_MAX_RECORD_HARMONICS`` without; the default is
    :func:`.optimum._default_harmonics`'s), naming the option."""
    from .optimum import HARMONICS_PER_WAVE

    cap = limits.BUOY_MAX_PTO_RECORD_HARMONICS if pto else limits.BUOY_MAX_RECORD_HARMONICS
    with_pto = "with --efficiency or --torque-limit " if pto else ""
    if harmonics is not None:
        if harmonics > cap:
            raise ParameterError(f"harmonics: expected at most {cap} over a record "
                                 f"{with_pto}(the most that finish in about two minutes), "
                                 f"got {harmonics}")
        return
    kk = np.arange(1, np.asarray(wave.amplitudes).size + 1)
    _, _, f = h.coefficients(kk * wave.omega)
    e = np.abs(f * np.asarray(wave.amplitudes) / h.impedance(kk * wave.omega)) ** 2
    km = max(1, int(round(float(np.sum(kk * e) / np.sum(e))))) if np.sum(e) > 0 else 1
    n = min(HARMONICS_PER_WAVE * max(km, winding), 8192)
    if n > cap:
        name = "winding" if winding >= km else ("record" if record is not None
                                                 else "repeat-period")
        raise ParameterError(f"{name}: {with_pto}this record needs {n} harmonics "
                             f"({HARMONICS_PER_WAVE} per wave, {max(km, winding)} "
                             f"waves or turns), more than the {cap} that finish in about two "
                             f"minutes; use a record of at most {cap // HARMONICS_PER_WAVE} "
                             "waves and turns, or give --harmonics")


def _coarse_hydro(body, radius, draft, mesh, hydro):
    """The same body on a mesh of panels :data:`.bem.COARSE` times larger, on the same
    frequencies (the error estimate's second mesh); None for a mesh file or a dataset."""
    if mesh is not None or hydro is not None:
        return None
    from . import bem as hy

    body = body or "cylinder"

    r, d = _dimensions(body, radius, draft)
    if body == "sphere":
        return hy.sphere(r, omega="body", refine=1 / hy.COARSE)
    return hy.cylinder(r, d, omega="body", refine=1 / hy.COARSE)


def _geometry(body, radius, draft, mesh, hydro) -> dict | None:
    """Draft and freeboard (m) of a parametric body (its mesh: a cylinder of length twice
    the draft, a whole sphere, centred on the free surface); None otherwise."""
    if mesh is not None or hydro is not None:
        return None
    r, d = _dimensions(body or "cylinder", radius, draft)
    return {"draft_m": d, "freeboard_m": d}


def _check_floats(h, pendulum):
    if not pendulum.mass < h.mass:
        raise ParameterError(f"mass: the pendulum's {pendulum.mass:g} kg is not less than the "
                             f"floating mass M = {h.mass:.6g} kg (rho x displaced volume, "
                             "which includes the pendulum); use a lighter pendulum or a "
                             "larger body")


# --- the command ------------------------------------------------------------------------------
def buoy(*, wave_height=None, wave_period=None, hs=None, tp=None, spectrum=None,
         gamma_peak=None, repeat_period=None, seed=None, cutoff=None, record=None, taper=None,
         mass=None, length=None, inertia=None, damping_coefficient=None, body=None, radius=None,
         draft=None, mesh=None, hydro=None, winding=None, harmonics=None, torque_limit=None,
         efficiency=None, optimize_design=None, mass_bounds=None, length_bounds=None,
         inertia_bounds=None, damping_coefficient_bounds=None, controller="optimum",
         horizon=None, update_interval=None, forecast=None, planner=None, wave_direction=None,
         dofs="heave",
         pivot_height=None, pivot_offset=None, hull_pitch_inertia=None, barge_length=None,
         barge_beam=None, barge_draft=None, copper_loss=None, realizations=None,
         time_limit=None, progress=None, sea=None, pendulum=None, pto=None, device=None):
    """The coupled optimum of a pendulum inside a floating buoy (command ``buoy``).

    Parameters
    ----------
    sea, pendulum, body, pto, controller, device : the input objects
        (:mod:`parapend.hydro.device`: ``Sea``, ``Pendulum``, ``Body``, ``PowerTakeOff``,
        ``Controller``, or a ``Device`` for the body, the pendulum and the take-off): their
        fields are the keywords below, checked and defaulted as those are. ``body`` and
        ``controller`` also take the plain names below; a field given twice is refused.
    wave_height, wave_period : float
        A regular wave: height ``H`` (m, crest to trough) and period (s); ``wave_period``
        as ``"FROM:TO:N"`` gives power against period
        (:class:`~parapend.hydro.result.BuoySweepResult`). Default the embedded design's
        wave (``parapend.defaults.BUOY``).
    hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff : an irregular sea state, as
        ``parapend.sea`` takes it (a periodic record of ``repeat_period`` s, default 100 tp).
    record, taper : a measured surface-elevation record at the body, CSV ``t,z`` (s, m),
        made periodic as ``parapend.sea`` does.
    mass, length, inertia, damping_coefficient : the pendulum: kg, m (pivot to centre of
        mass), kg m^2 about the pivot (at least ``m l^2``; default ``m l^2``), N m s/rad.
    body, radius, draft : a vertical ``"cylinder"`` (radius, draft, m) or a ``"sphere"``
        (radius; floats at its centre), meshed and solved by Capytaine, cached on disk.
    mesh : a mesh file Capytaine reads (the body floats as meshed, z = 0 the free surface).
    hydro : a NetCDF dataset of a Capytaine run (docs/buoy.md: bring your own).
    winding : turns of the pendulum per wave (per record for an irregular sea); default 1.
    harmonics : N of the motion (default chosen from the problem and checked).
    torque_limit : N m.
    efficiency : float, pair or str
        Of the power take-off: a number in (0, 1] (both ways), a pair ``(eta_g, eta_m)``
        or the text ``"ETA_G,ETA_M"``: the motion maximizes the electrical power
        (docs/buoy.md), within ``torque_limit`` if given.
    optimize_design : comma list of pendulum parameters to choose (``"length,inertia"``)
        for the largest coupled power, each within ``<name>_bounds`` ``"LO:HI"``.

    controller, horizon, update_interval, forecast : ``"optimum"`` (the non-causal coupled optimum),
        or a causal receding-horizon controller run on the coupled time-domain plant in an
        irregular sea (:mod:`parapend.hydro.control`): ``"mpc"`` (planned on the coupled model) or
        ``"one-way-mpc"`` (planned on the free buoy's heave); horizon (default 2 with
        ``"mpc"``, 1 with ``"one-way-mpc"``) and update interval in peak periods;
        ``forecast`` ``"perfect"`` (default: the record's own excitation force over the
        horizon) or ``"ar"`` (autoregressive, fitted on the force measured
        so far), with ``"mpc"``.
    planner : with ``"mpc"``, the horizon's solver. The heaving buoy: ``"plan"`` (the
        pendulum's motion as the unknown; the default) or ``"coupled"`` (the held torques;
        the default with ``efficiency``), as ``parapend horizon --planner``. The hull
        (``dofs="surge,heave,pitch"``): ``"collocation"`` (the default: the motion as the
        unknown, a compiled interior point on its exact Hessian; on the default barge's
        20-minute record 98.0 % of the record optimum with a perfect forecast) or
        ``"lbfgsb"`` (L-BFGS-B on the held torques shot through the model: faster, 25.6 %
        there; docs/hull.md).

    dofs : ``"heave"`` (default: the heaving buoy) or ``"surge,heave,pitch"``: a hull that
        surges, heaves and pitches, with a pendulum that rotates or swings (docs/hull.md;
        ``hull_buoy``). Then ``body`` is ``"barge"`` (default; its
        ``barge_length``, ``barge_beam``, ``barge_draft``, m), ``"cylinder"`` or
        ``"sphere"``, or ``mesh``/``hydro`` with these DOFs; ``pivot_height`` and
        ``pivot_offset`` place the pivot from the rotation centre O (a built-in
        body's waterplane centre, a mesh's origin, a dataset's rotation centre), m;
        ``hull_pitch_inertia`` (kg m^2, about it; default the dataset's, else a
        homogeneous immersed hull); ``winding`` None reports rotation
        (one turn per wave) both ways (``winding=1``, and ``-1`` against the sense of a
        positive pitch) and swinging (``winding=0``) side by side. Options not given
        take the embedded hull design's values (``parapend.defaults.HULL``).
        ``copper_loss`` ``r`` (W per (N m)^2; hull only) subtracts the winding loss ``r
        tau^2`` from the power: holding an angle then costs what it costs a generator.
    realizations : int or None
        A hull (``dofs="surge,heave,pitch"``) in a sea state (``hs``, ``tp``): solve ``R``
        records of it, seeded ``seed, seed + 1, ...`` (each exactly the record ``buoy``
        solves alone with that seed), and report their mean power with its 95 %
        t-interval (:mod:`parapend.confidence`): ``realization_powers_w``,
        ``mean_power_w``, ``power_ci_w``; the other fields are the first record's. Work
        estimated past :data:`parapend.limits.MAX_UNTIMED_SECONDS` needs ``time_limit``
        (the realizations finished by then, marked ``time_limit``).
    time_limit : float or None
        Seconds for the long work (``optimize_design``, a period sweep, ``controller``,
        ``realizations``):
        without it, work estimated above ``parapend.limits.MAX_UNTIMED_SECONDS`` is refused;
        with it, the work stops at the first design evaluation, period or update after the
        limit and the result is partial: ``status`` ``"time_limit"``, ``success`` False, and
        what was done (:mod:`parapend.deadline`).
    progress : callable or None
        With ``optimize_design``: called ``progress(done, total)`` after every inner solve
        of the search (the command line draws it as a bar on a terminal).

    Returns
    -------
    result : BuoyResult, BuoySweepResult or BuoyMPCResult
        One design; a period sweep; a receding-horizon run (``controller``, the result of
        :func:`parapend.hydro.control.buoy_mpc`). The result types are those of every DOF set
        (:func:`parapend.hydro.result.optimum`); their JSON holds their set's fields.
    """
    if has_inputs(locals()):
        return buoy(**expand_inputs(buoy, locals()))
    from .coupled import Wave

    opts = dict(locals())
    from ..deadline import check_time_limit, deadline

    _check_kinds(dofs=dofs, optimize_design=optimize_design, mesh=mesh)
    time_limit = check_time_limit(time_limit)
    until = deadline(time_limit)  # the limit counts from the call (the BEM included)
    if parse_dofs(dofs) != ("heave",):
        if time_limit is not None and parse_periods(wave_period) is None and \
                realizations is None:
            raise ParameterError("time-limit: bounds long work only: with --dofs "
                                 "surge,heave,pitch a period sweep (--wave-period FROM:TO:N) "
                                 "or --realizations; one wave's work is bounded by its "
                                 "harmonics")
        return hull_buoy(**{k: v for k, v in opts.items() if k not in (
            "dofs", "Wave", "time_limit", "sea", "pendulum", "pto", "device")},
            deadline=until, time_limit=time_limit)
    if realizations is not None:
        raise ParameterError("realizations: the mean over seeded records is the hull's "
                             "(--dofs surge,heave,pitch with --hs and --tp); drop it")
    for name in ("pivot_height", "pivot_offset", "hull_pitch_inertia", "barge_length",
                 "barge_beam", "barge_draft", "copper_loss"):
        if opts[name] is not None and not (isinstance(body, str) and body == "barge"
                                           and name.startswith("barge_")):
            raise ParameterError(f"{name.replace('_', '-')}: a hull's option; needs --dofs "
                                 "surge,heave,pitch")
    # the barge in heave alone: the hull's coefficients, their heave entries
    barge = _hull_body(opts) if isinstance(body, str) and body == "barge" else None
    for name, v in (("body", body), ("controller", controller), ("spectrum", spectrum)):
        if v is not None and not isinstance(v, str):
            raise ParameterError(f"{name}: expected a name (str), got {type(v).__name__}")
    if controller not in ("optimum", "mpc", "one-way-mpc"):
        raise ParameterError(f"controller: expected optimum, mpc or one-way-mpc, got "
                             f"{controller!r:.40}")
    periods = parse_periods(wave_period)
    if time_limit is not None and controller == "optimum" and periods is None and not (
            optimize_design is not None and str(optimize_design).strip()):
        raise ParameterError("time-limit: bounds long work only: needs --optimize-design, a "
                             "period sweep (--wave-period FROM:TO:N) or --controller mpc")
    if controller != "optimum" and wave_period is not None and any(
            v is not None for v in (hs, tp, record, repeat_period, seed)):
        raise ParameterError("wave-period: a regular wave or an irregular sea (--hs, --tp, "
                             "--record), not both")
    if controller != "optimum" and (periods is not None or not any(
            v is not None for v in (hs, tp, repeat_period, seed))):
        raise ParameterError("controller: mpc runs in an irregular sea state: give --hs and "
                             "--tp (and --repeat-period, --seed)")
    irregular = any(v is not None for v in (hs, tp, record, repeat_period, seed))
    # options that would be accepted and ignored: refused with what they need
    _check_planner(planner, controller, "heave", efficiency)
    if controller == "optimum":
        for name, v in (("horizon", horizon), ("update-interval", update_interval),
                        ("forecast", forecast)):
            if v is not None:
                raise ParameterError(f"{name}: needs --controller mpc"
                                     + ("" if name == "forecast" else " (or one-way-mpc)"))
    horizon = default_of("horizon", horizon, controller)
    update_interval = default_of("update_interval", update_interval)
    forecast = default_of("forecast", forecast)
    sea_opts = (("spectrum", spectrum), ("gamma-peak", gamma_peak), ("cutoff", cutoff),
                ("taper", taper))
    for name, v in sea_opts:
        if v is None:
            continue
        if not irregular:
            raise ParameterError(f"{name}: an irregular sea's option; needs --hs and --tp "
                                 f"(or --record)")
        if name == "taper" and record is None:
            raise ParameterError("taper: needs --record")
        if name in ("spectrum", "gamma-peak") and record is not None:
            raise ParameterError(f"{name}: not used with --record; drop it")
    spectrum, gamma_peak, cutoff, taper = (default_of(k, v) for k, v in (
        ("spectrum", spectrum), ("gamma_peak", gamma_peak), ("cutoff", cutoff),
        ("taper", taper)))
    if wave_direction is not None:
        wave_direction = check("wave_direction", wave_direction, absolute=True)
        if hydro is None:
            raise ParameterError("wave-direction: needs --hydro (a dataset with several "
                                 "wave directions)")
    if irregular:
        bad = [n for n, v in (("wave-height", wave_height), ("wave-period", wave_period))
               if v is not None]
        if bad:
            raise ParameterError(f"{bad[0]}: a regular wave or an irregular sea (--hs, --tp, "
                                 "--record), not both")
    pend = _pendulum(mass, length, inertia, damping_coefficient)
    winding = 1 if winding is None else check_int("winding", winding, 1, 64)
    if harmonics is not None:
        harmonics = check_int("harmonics", harmonics, 2, 4096)
    if torque_limit is not None:
        mgl = pend.mass * 9.81 * pend.length
        lo, hi = limits.MIN_TORQUE_LIMIT * mgl, limits.MAX_TORQUE_LIMIT * mgl
        torque_limit = check_range("torque-limit", torque_limit, lo, hi,
                                   why=f"N m: {limits.MIN_TORQUE_LIMIT:g} to "
                                       f"{limits.MAX_TORQUE_LIMIT:g} x m g l")
    if efficiency is not None:
        from .pto import efficiency_pair

        efficiency = efficiency_pair(efficiency)
        if efficiency == (1.0, 1.0):
            efficiency = None  # lossless: the ideal problem
    if not irregular:
        pto = torque_limit is not None or efficiency is not None
        _check_harmonics(harmonics, winding, pto)
        if periods is not None:
            _check_sweep(periods.size, harmonics, winding, pto, time_limit)
    variables, bounds = _design_request(optimize_design, pend, mass_bounds=mass_bounds,
                                        length_bounds=length_bounds,
                                        inertia_bounds=inertia_bounds,
                                        damping_coefficient_bounds=damping_coefficient_bounds)
    height = check("wave_height", default_of("wave_height", wave_height, "buoy"),
                   why="regular wave height, m")
    if periods is not None and variables:
        raise ParameterError("optimize-design: one wave period at a time (drop FROM:TO:N)")
    if variables:
        _check_design(len(variables), torque_limit is not None or efficiency is not None,
                      time_limit)
    if irregular:
        from ..units import Units

        wave, info = _irregular_wave(hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff,
                                     record, taper, Units(pend.length, pend.mass, 9.81,
                                                          pend.inertia))
        amps = np.abs(np.asarray(wave.amplitudes))
        sig = np.nonzero(amps >= 1e-3 * amps.max())[0]  # the components that matter
        h, width = _heave_hydro(barge, body, radius, draft, mesh, hydro, wave_direction)
        h.check_covers(wave.omega * (sig[0] + 1), wave.omega * (sig[-1] + 1),
                       name="tp" if record is None else "record")
        # the causal controllers' yardstick is the record's mechanical optimum (mpc_command:
        # no torque limit or efficiency); the power take-off's cap refused their records
        if controller == "optimum" and (torque_limit is not None or efficiency is not None):
            _check_record_harmonics(h, wave, harmonics, winding, record)
        elif controller == "optimum":
            _check_record_harmonics(h, wave, harmonics, winding, record, pto=False)
    else:
        if periods is None:
            period = _period(default_of("wave_period", wave_period, "buoy"))
            periods_all = np.array([period])
        else:
            periods_all = np.array([_period(p) for p in periods])
        if mesh is None and hydro is None and barge is None:  # refused before the BEM
            _check_short(_parametric_top(body, radius, draft), periods_all, body, radius)
        check_steepness(height, periods_all)  # a wave past breaking, before the BEM too
        h, width = _heave_hydro(barge, body, radius, draft, mesh, hydro, wave_direction)
        w = 2 * math.pi / periods_all
        if hydro is None:
            _check_short(float(np.max(h.omega)), periods_all)
        h.check_covers(float(np.min(w)), float(np.max(w)), name="wave-period")
    _check_floats(h, pend)
    # the body on a second, coarser mesh: the estimate of the discretization error
    coarse = (_coarse_hydro(body, radius, draft, mesh, hydro)
              if controller == "optimum" and barge is None else None)
    geometry = (_geometry(body, radius, draft, mesh, hydro) if barge is None else
                {k: barge[1][k] for k in ("draft_m", "freeboard_m")})
    if not irregular and periods is not None:
        from .design import period_sweep

        return period_sweep(h, width, pend, height, periods_all, winding=winding,
                            harmonics=harmonics, torque_limit=torque_limit,
                            efficiency=efficiency, coarse=coarse, geometry=geometry,
                            deadline=until)
    if not irregular:
        wave = Wave.regular(height, float(periods_all[0]))
        info = {"kind": "regular", "height_m": height, "period_s": float(periods_all[0]),
                "omega_rad_per_s": 2 * math.pi / float(periods_all[0])}
    if controller != "optimum":
        from .control import mpc_command

        return mpc_command(h, pend, wave, info, controller=controller, horizon=horizon,
                           update_interval=update_interval, winding=winding,
                           harmonics=harmonics, torque_limit=torque_limit,
                           efficiency=efficiency, irregular=irregular,
                           design=bool(variables), time_limit=time_limit, deadline=until,
                           forecast=forecast, planner=planner)
    opts = {"winding": winding, "harmonics": harmonics, "torque_limit": torque_limit,
            "efficiency": efficiency}
    design = None
    if variables:
        from .design import optimize_design as _outer

        found = _outer(lambda p: _solve(h, p, wave, one_way=False, **opts)[0], pend,
                       variables, bounds, check=lambda p: _check_floats(h, p),
                       progress=progress, deadline=until)
        pend, design = found.pendulum, found.to_dict()
    res = optimum(h, pend, wave, wave_info=info, winding=winding, harmonics=harmonics,
                  pto=HullPTO(efficiency=efficiency, torque_limit=torque_limit),
                  geometry=geometry, width=width, coarse=coarse, design=design)
    if design is not None and design["status"] == "time_limit":
        import dataclasses

        # the best design evaluated, solved in full; the search itself is unfinished
        res = dataclasses.replace(res, success=False, status="time_limit",
                                  message=f"optimize-design: {design['message']} "
                                          f"(time limit {time_limit:g} s)")
    return res


def _bounds(name, text, value):
    if text is None:
        lo, hi = BUOY["design_bounds"][name]
        return (lo * value, hi * value) if name != "damping_coefficient" else (lo, hi)
    if isinstance(text, (tuple, list)) and len(text) == 2:
        lo, hi = text
    else:
        parts = str(text).split(":")
        if len(parts) != 2:
            raise ParameterError(f"{name.replace('_', '-')}-bounds: expected LO:HI, got "
                                 f"{text!r:.40}")
        try:
            lo, hi = float(parts[0]), float(parts[1])
        except ValueError:
            raise ParameterError(f"{name.replace('_', '-')}-bounds: expected two numbers "
                                 f"LO:HI, got {text!r:.40}") from None
    opt = f"{name.replace('_', '-')}-bounds"
    lo = (check_nonnegative if name == "damping_coefficient" else check_positive)(opt, lo)
    hi = check_positive(opt, hi)
    if not hi > lo:
        raise ParameterError(f"{opt}: expected LO < HI, got {lo:g}:{hi:g}")
    return float(lo), float(hi)


def _design_request(text, pend, **given):
    if text is None or (isinstance(text, str) and not text.strip()):
        extra = [k for k, v in given.items() if v is not None]
        if extra:
            raise ParameterError(f"{extra[0].replace('_', '-')}: only used with "
                                 "--optimize-design")
        return (), {}
    names = ([s.strip().replace("-", "_") for s in text.split(",")] if isinstance(text, str)
             else [str(s).replace("-", "_") for s in text])
    bad = [n for n in names if n not in DESIGN_VARIABLES]
    if bad or not names or len(set(names)) != len(names):
        raise ParameterError(f"optimize-design: expected distinct names from "
                             f"{', '.join(n.replace('_', '-') for n in DESIGN_VARIABLES)}, "
                             f"got {text!r:.60}")
    for k, v in given.items():
        if v is not None and k.removesuffix("_bounds") not in names:
            raise ParameterError(f"{k.replace('_', '-')}: {k.removesuffix('_bounds')} is not "
                                 "in --optimize-design")
    bounds = {n: _bounds(n, given[f"{n}_bounds"], getattr(pend, n)) for n in names}
    return tuple(names), bounds


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


def refuse_hull(dofs, where: str) -> None:
    """Refuse, in one line naming the missing capability, a hull's ``dofs`` where only the
    heaving buoy is taken (``where``: the command, e.g. ``"horizon --device buoy"``)."""
    if dofs is not None and parse_dofs(dofs) != ("heave",):
        raise ParameterError(f"dofs: {where} takes a hull (surge,heave,pitch) by its keywords "
                             "only (dofs=, the embedded barge's defaults), not as a Body "
                             "object")


#: the receding-horizon planners a buoy's controller takes, per model
PLANNERS = {"heave": ("plan", "coupled"), "hull": ("lbfgsb", "collocation")}


def _check_planner(planner, controller, kind: str, efficiency=None) -> None:
    """``planner`` (None: the model's default) against the controller and the model
    (``"heave"``, ``"hull"``): one line naming what it needs or takes."""
    if planner is None:
        return
    if not isinstance(planner, str):
        raise ParameterError(f"planner: expected a name (str), got {type(planner).__name__}")
    if controller != "mpc":
        raise ParameterError("planner: needs --controller mpc")
    if planner not in PLANNERS[kind]:
        where, other, whose = (("--dofs heave", "hull", "the hull's") if kind == "heave"
                               else ("--dofs surge,heave,pitch", "heave", "the heaving "
                                     "buoy's"))
        raise ParameterError(f"planner: with {where} expected {' or '.join(PLANNERS[kind])} "
                             f"({' and '.join(PLANNERS[other])} are {whose}), got "
                             f"{planner!r:.40}")
    if planner == "plan" and efficiency is not None:
        raise ParameterError("efficiency: not with --planner plan (it plans the mechanical "
                             "work)")


def _refuse_unsupported(opts: dict) -> None:
    """The heave-only command's options this problem does not take (yet): one line each."""
    later = {"optimize_design": "optimize-design", "mass_bounds": "mass-bounds",
             "length_bounds": "length-bounds", "inertia_bounds": "inertia-bounds",
             "damping_coefficient_bounds": "damping-coefficient-bounds",
             "horizon": "horizon", "update_interval": "update-interval",
             "forecast": "forecast"}
    mpc = opts.get("controller") == "mpc"
    for key, name in later.items():
        if opts.get(key) is not None and not (mpc and key in (
                "horizon", "update_interval", "forecast")):
            raise ParameterError(f"{name}: not available with --dofs surge,heave,pitch"
                                 + (" yet; drop it" if key not in (
                                     "horizon", "update_interval", "forecast")
                                    else "; needs --controller mpc"))
    if opts.get("controller") not in (None, "optimum", "mpc"):
        raise ParameterError("controller: a hull (--dofs surge,heave,pitch) takes optimum or "
                             f"mpc, got {opts.get('controller')!r:.40}")
    _check_planner(opts.get("planner"), opts.get("controller"), "hull")


def _hull_pto(opts):
    """The hull's power take-off (:meth:`.declared.PowerTakeOff.hull`) of the keywords
    ``torque_limit`` (N m), ``efficiency`` and ``copper_loss`` (W per (N m)^2)."""
    from .declared import PowerTakeOff

    return PowerTakeOff(**{k: opts.get(k) for k in ("torque_limit", "efficiency",
                                                     "copper_loss")}).hull()


def _hull_value(opts, name):
    """The option, or the hull's declared default when the caller did not give it (the
    heave-only command's defaults are for a 1 m buoy, not a 10 m hull)."""
    v = opts.get(name)
    return default_of(name, v if given(v) else None, "hull")


def _hull_pendulum(opts):
    from .inputs import _pendulum as build

    return build(*(opts.get(k) if given(opts.get(k)) else None
                   for k in ("mass", "length", "inertia", "damping_coefficient")), kind="hull")


def _hull_body(opts):
    """How to build the hull's coefficients (a callable: the BEM runs when it is called,
    after the checks) and the geometry a check can use (or None)."""
    from . import bem as hd

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
    if body == "barge":
        for k in ("radius", "draft"):
            if opts.get(k) is not None:
                raise ParameterError(f"{k}: the barge takes --barge-length, --barge-beam and "
                                     "--barge-draft; drop it")
        length, beam, draft = (check(k, _hull_value(opts, k)) for k in (
            "barge_length", "barge_beam", "barge_draft"))
        _check_barge_size(length, beam, draft)  # an estimate before long work
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
    if body not in ("cylinder", "sphere"):
        raise ParameterError(f"body: expected barge, cylinder or sphere, got {body!r:.40}")
    r = check("radius", _hull_value(opts, "radius"))
    if body == "sphere":
        # a sphere floating at its centre has no pitch stiffness about its waterplane
        # centre: a hull that pitches floats higher (default: half its radius immersed)
        d = check("draft", 0.5 * r if opts.get("draft") is None else opts["draft"])
        top = 2 * r - d
        def build():
            return (hd.sphere_hull(r, draft=d, omega="body"))
    else:
        d = check("draft", _hull_value(opts, "draft"))
        top = d  # its mesh: a cylinder of length twice the draft
        def build():
            return (hd.cylinder_hull(r, d, omega="body"))
    return build, {"draft_m": d, "freeboard_m": top, "half_length_m": r, "half_beam_m": r,
                   "body": body, "radius_m": r}


def _hull_pivot(opts, geometry):
    d = _hull_value(opts, "pivot_offset")
    h = _hull_value(opts, "pivot_height")
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


def barge_panels(length, beam, draft) -> float:
    """The panels (and the lid's) of the barge's BEM, estimated: its immersed surface and
    waterplane over the area ``2 h^2`` of a panel of radius ``h = min(L, B) / 12``
    (:data:`.bem.GEOMETRY_PANELS`; the default 10 x 4 x 1 m: 486 against its 412 and 120)."""
    from .bem import GEOMETRY_PANELS

    h = min(length, beam) / GEOMETRY_PANELS
    return (2 * length * beam + 2 * draft * (length + beam)) / (2 * h * h)


def _check_barge_size(length, beam, draft) -> None:
    """Refuse a barge whose BEM would take hours: more than
    :data:`parapend.limits.HULL_MAX_BEM_PANELS` panels estimated (:func:`barge_panels`)."""
    cap = limits.HULL_MAX_BEM_PANELS
    n = barge_panels(length, beam, draft)
    if n <= cap:
        return
    name, small = ("barge-beam", beam) if beam <= length else ("barge-length", length)
    a, b = small, max(length, beam)  # the smaller side that fits: bisection
    for _ in range(60):
        mid = math.sqrt(a * b)
        fits = barge_panels(*((length, mid) if name == "barge-beam" else (mid, beam)),
                            draft) <= cap
        a, b = (a, mid) if fits else (mid, b)
    raise ParameterError(f"{name}: a {length:g} x {beam:g} x {draft:g} m barge needs a BEM of "
                         f"about {n:.3g} panels (they follow its smaller side), more than the "
                         f"{cap:g} that finish in minutes; expected {name} of at least "
                         f"{b:.3g} m")


def _check_fits(pend, pivot, geometry) -> None:
    """Before the BEM: refuse a pendulum at or above the floating mass ``rho V`` (``rho`` =
    1025 kg/m^3, the BEM's; ``V`` the body's analytic displaced volume: a box ``L B D``, a
    cylinder ``pi r^2 d``, a sphere's cap ``pi d^2 (3 r - d) / 3``), and one whose circle
    about the pivot reaches beyond the hull's ends (``|d_p| + l`` above its half-length)."""
    if geometry is None:
        return
    d = geometry["draft_m"]
    if geometry["body"] == "barge":
        volume = geometry["length_m"] * geometry["beam_m"] * d
    elif geometry["body"] == "cylinder":
        volume = math.pi * geometry["radius_m"] ** 2 * d
    else:
        volume = math.pi * d * d * (3 * geometry["radius_m"] - d) / 3
    mass = 1025.0 * volume
    if not pend.mass < mass:
        raise ParameterError(f"mass: the pendulum's {pend.mass:g} kg is not less than the "
                             f"floating mass {mass:.6g} kg (rho x displaced volume "
                             f"{volume:.6g} m^3, which includes the pendulum); expected less")
    room = geometry["half_length_m"] - abs(pivot[0])
    if pend.length > room:
        raise ParameterError(f"length: a {pend.length:g} m pendulum on a pivot "
                             f"{pivot[0]:g} m from the centre turns beyond the hull's ends "
                             f"(+-{geometry['half_length_m']:g} m); expected at most "
                             f"{room:g} m")


def hull_problem(**opts) -> dict:
    """Everything but the wave, checked, and the hull's coefficients built once (the BEM runs
    after the checks): the pieces :func:`solve_record` solves a wave with (the power matrix
    builds them once per process and solves each bin's record)."""
    _refuse_unsupported(opts)
    pto = _hull_pto(opts)
    pend = _hull_pendulum(opts)
    build, geometry = _hull_body(opts)
    pivot = _hull_pivot(opts, geometry)  # before the BEM: a pivot outside the hull is refused
    _check_fits(pend, pivot, geometry)  # and a pendulum too heavy or too long for it
    hull = build()
    if not pend.mass < hull.mass:
        raise ParameterError(f"mass: the pendulum's {pend.mass:g} kg is not less than the "
                             f"floating mass {hull.mass:.6g} kg (rho x displaced volume, "
                             "which includes the pendulum)")
    inertia = opts.get("hull_pitch_inertia")
    if inertia is not None:
        inertia = check("hull_pitch_inertia", inertia)
    winding = opts.get("winding")
    windings = ((1, -1, 0) if winding is None
                else (check_int("winding", winding, -16, 16),))
    harmonics = opts.get("harmonics")
    if harmonics is not None:
        harmonics = check_int("harmonics", harmonics, 2, hull_harmonics_cap(pto))
    return {"hull": hull, "pendulum": pend, "pivot": pivot, "pitch_inertia": inertia,
            "winding": winding, "windings": windings, "harmonics": harmonics,
            "geometry": geometry, "pto": pto}


def solve_record(problem: dict, wave, info, *, check_only: bool = False):
    """One irregular record ``wave`` (described by ``info``) of :func:`hull_problem`'s
    ``problem``: its size and frequencies checked, then solved (rotation one turn per wave
    both ways and swinging unless a winding was given, and on a record of
    ``WINDING_SEARCH_WAVES`` or more the windings between them, on a shorter one through an
    ideal take-off the rotation's other turns: :func:`parapend.hydro.result.hull_answer`'s
    search and climb);
    ``check_only``: the checks alone."""
    from .hull import HARMONICS_PER_TURN
    from .result import WINDING_SEARCH_WAVES

    windings = problem["windings"]
    search, climb = False, 0
    if problem["winding"] is None:
        k = waves_in(wave)
        windings = (k, -k, 0)
        search = k >= WINDING_SEARCH_WAVES
        if not search and not problem["pto"].active:
            # a short record: the rotation's other turns, within the size cap (an ideal
            # take-off's: a lossy record's solves are not screened; the default sea's
            # 4-peak-period record with an efficiency takes 525 s of CPU without the climb,
            # each further turn count a rotation's 140 to 180 s)
            cap = problem.get("max_harmonics") or hull_harmonics_cap(problem["pto"])
            climb = (problem["harmonics"] or cap) // HARMONICS_PER_TURN
    _check_hull_size(wave, windings, problem["harmonics"], problem["pto"],
                     problem.get("max_harmonics"))
    amps = np.abs(np.asarray(wave.amplitudes))
    sig = np.nonzero(amps >= 1e-3 * amps.max())[0]
    problem["hull"].check_covers(wave.omega * (sig[0] + 1), wave.omega * (sig[-1] + 1),
                                 name="tp")
    if check_only:
        return None
    return optimum(problem["hull"], problem["pendulum"], wave, wave_info=info,
                   winding=windings, harmonics=problem["harmonics"], pto=problem["pto"],
                   pivot=problem["pivot"], pitch_inertia=problem["pitch_inertia"],
                   geometry=problem["geometry"], winding_search=search,
                   winding_climb=climb)


def hull_buoy(deadline=None, time_limit=None, **opts):
    """The optimum of a pendulum in a surging, heaving, pitching hull (see
    :func:`parapend.buoy`, ``dofs="surge,heave,pitch"``); ``deadline`` (a
    :func:`parapend.deadline.deadline` time): a period sweep stops once it has passed, the
    periods not begun left out (the first always solved); so do ``realizations``
    (``parapend.hydro.realizations``), ``time_limit`` the seconds it stands for."""
    from ..deadline import expired
    from .coupled import Wave
    from .inputs import _irregular_wave, _period, parse_periods

    _check_wave_kind(opts)  # before the BEM
    progress, realizations = opts.pop("progress", None), opts.pop("realizations", None)
    if realizations is not None:
        from .realizations import check_realizations

        realizations = check_realizations(realizations, opts, time_limit)
    regular = not any(opts.get(k) is not None for k in ("hs", "tp", "record",
                                                        "repeat_period", "seed"))
    if regular and opts.get("controller") == "mpc":
        raise ParameterError("controller: mpc runs the hull in an irregular sea state: give "
                             "--hs and --tp (and --repeat-period, --seed)")
    if regular:  # the wave's checks before the BEM too
        height = check("wave_height", _hull_value(opts, "wave_height"),
                       why="regular wave height, m")
        periods = parse_periods(opts.get("wave_period"))
        if periods is None:
            periods = np.array([_period(_hull_value(opts, "wave_period"))])
        check_steepness(height, periods)
        _check_grid(_hull_body(opts)[1], periods)
    elif opts.get("record") is None:  # a sea state past breaking, before the BEM too
        from ..seas import check_sea_state

        check_sea_state(_hull_value(opts, "hs"), _hull_value(opts, "tp"))
    p = hull_problem(**opts)
    hull, pend, pivot, inertia, geometry, pto, windings, harmonics = (
        p[k] for k in ("hull", "pendulum", "pivot", "pitch_inertia", "geometry", "pto",
                       "windings", "harmonics"))
    irregular = any(opts.get(k) is not None for k in ("hs", "tp", "record", "repeat_period",
                                                      "seed"))
    if irregular:
        from ..units import Units

        if opts.get("repeat_period") is None and opts.get("record") is None:
            tp = default_of("tp", opts.get("tp"), "hull")
            opts = dict(opts, repeat_period=HULL["repeat_periods"] * tp)
        def record(seed):
            return _irregular_wave(
                opts.get("hs"), opts.get("tp"), default_of("spectrum", opts.get("spectrum")),
                default_of("gamma_peak", opts.get("gamma_peak")), opts.get("repeat_period"),
                seed, default_of("cutoff", opts.get("cutoff")), opts.get("record"),
                default_of("taper", opts.get("taper")),
                Units(pend.length, pend.mass, 9.81, pend.inertia), kind="hull")
        if realizations is not None:
            from .realizations import solve_realizations

            return solve_realizations(solve_record, p, record, opts.get("seed"), realizations,
                                      time_limit=time_limit, deadline=deadline,
                                      progress=progress)
        wave, info = record(opts.get("seed"))
        if opts.get("controller") == "mpc":
            from .hull_control import hull_mpc_command

            if "tp" not in info:
                raise ParameterError("controller: mpc runs in an irregular sea state: give "
                                     "--hs and --tp")
            return hull_mpc_command(
                p, wave, info, solve_record(p, wave, info), deadline=deadline,
                horizon=default_of("horizon", opts.get("horizon"), "mpc"),
                update_interval=default_of("update_interval", opts.get("update_interval")),
                forecast=default_of("forecast", opts.get("forecast")),
                planner=opts.get("planner"))
        return solve_record(p, wave, info)
    w = 2 * math.pi / periods
    hull.check_covers(float(np.min(w)), float(np.max(w)), name="wave-period")
    results = []
    for t in periods:
        if results and expired(deadline):
            break
        wave = Wave.regular(height, float(t))
        info = {"kind": "regular", "height_m": height, "period_s": float(t)}
        results.append(optimum(hull, pend, wave, wave_info=info, winding=windings,
                               harmonics=harmonics, pto=pto, pivot=pivot,
                               pitch_inertia=inertia, geometry=geometry))
    if parse_periods(opts.get("wave_period")) is None:
        return results[0]
    from .result import BuoySweepResult

    return BuoySweepResult.from_results(periods, results, height)


def _check_grid(geometry, periods) -> None:
    """Before the BEM: refuse periods outside a parametric hull's own frequency grid
    (:func:`.bem.body_frequencies` at the panel radius its builder uses, the smaller of its
    sizes over ``GEOMETRY_PANELS``); the BEM may leave a few of its top frequencies out, so
    :meth:`.bem.HullHydro.check_covers` checks again after it."""
    from . import bem as hy

    if geometry is None:
        return
    if geometry["body"] == "barge":
        scale = min(geometry["length_m"], geometry["beam_m"])
    else:
        scale = min(geometry["radius_m"], geometry["draft_m"])
    grid = hy.body_frequencies(scale / hy.GEOMETRY_PANELS)
    w = 2 * math.pi / np.asarray(periods, dtype=float)
    if float(w.max()) > grid[-1] * (1 + 1e-9) or float(w.min()) < grid[0] * (1 - 1e-9):
        lo, hi = float(np.min(periods)), float(np.max(periods))
        asked = f"{lo:g} s" if lo == hi else f"{lo:g} to {hi:g} s"
        raise ParameterError(f"wave-period: {asked} lies outside the {geometry['body']}'s "
                             f"frequencies, which cover periods from {2 * math.pi / grid[-1]:.4g} "
                             f"s to {2 * math.pi / grid[0]:.4g} s (its mesh resolves no shorter "
                             "wave)")


def check_steepness(height, periods) -> None:
    """Refuse a regular wave past breaking, ``H / lambda > 1/7`` (Michell's limit; ``lambda``
    the deep-water ``g T^2 / (2 pi)``, the longest a period has: a finite depth's wave is
    shorter and steeper), before any work; the result warns past 1/20."""
    from .result import BREAKING_STEEPNESS

    lam = 9.81 * np.asarray(periods, dtype=float) ** 2 / (2 * math.pi)
    steep = float(np.max(height / lam))
    if steep > BREAKING_STEEPNESS:
        t = float(np.asarray(periods).ravel()[int(np.argmax(height / lam))])
        raise ParameterError(f"wave-height: H = {height:g} m in a {t:g} s wave (wavelength "
                             f"{height / steep:.4g} m) is steepness H / lambda = {steep:.3g}, "
                             f"past breaking (1/7); expected at most "
                             f"{t * t * 9.81 / (14 * math.pi):.4g} m")


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


def hull_harmonics_cap(pto) -> int:
    """The most harmonics of the hull's motion: every take-off's problem is matrix-free
    from ``hull.KRYLOV_HARMONICS`` on (an efficiency's from ``hull.KINK_KRYLOV_HARMONICS``,
    past its record's cap and refinement: dense); an ideal one's up to
    ``limits.HULL_MAX_RECORD_HARMONICS``, a torque limit's or a copper loss's (the limit's
    augmented Lagrangian: several climbs per record) up to
    ``limits.HULL_MAX_PTO_RECORD_HARMONICS``, an efficiency's (its smoothing's continuation,
    whose last widths cost the most: the barge's 10-peak-period record did not finish in 25
    minutes) up to ``limits.HULL_MAX_HARMONICS``, as before."""
    if pto is None or not pto.active:
        return limits.HULL_MAX_RECORD_HARMONICS
    return limits.HULL_MAX_HARMONICS if pto.smoothed else limits.HULL_MAX_PTO_RECORD_HARMONICS


def _check_hull_size(wave, windings, harmonics, pto=None, cap=None):
    """Refuse a record whose motion needs more harmonics than the matrix-free solver takes
    in time and memory (:func:`hull_harmonics_cap`: ``limits.HULL_MAX_RECORD_HARMONICS``
    for an ideal take-off, ``limits.HULL_MAX_PTO_RECORD_HARMONICS`` or
    ``limits.HULL_MAX_HARMONICS`` for a real one);
    ``cap``: another limit (the power matrix's)."""
    from .hull import HARMONICS_PER_TURN

    n = harmonics or HARMONICS_PER_TURN * max(max(abs(k) for k in windings), waves_in(wave))
    ideal = pto is None or not pto.active
    if cap is None:
        cap = hull_harmonics_cap(pto)
    if n > cap:
        why = ("that the matrix-free solver takes (time and memory)" if cap in (
               limits.HULL_MAX_RECORD_HARMONICS, limits.HULL_MAX_PTO_RECORD_HARMONICS)
               else "that finish in bounded time") + ("" if ideal else
                                                      " with a power take-off")
        raise ParameterError(f"repeat-period: the record holds about {waves_in(wave)} waves "
                             f"and needs {n} harmonics ({HARMONICS_PER_TURN} per wave or "
                             f"turn), more than the {cap} {why}; use a record of at most "
                             f"{cap // HARMONICS_PER_TURN} waves")
