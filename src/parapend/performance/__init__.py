r"""Performance as the field reports it (IEC TS 62600-100): the power matrix over sea states,
the wave energy flux and capture width of each bin, and the mean annual energy production
at a site; the Dataset follows MHKiT's ``wave.performance`` (docs/performance.md).

Flow: :func:`power_matrix` checks the bins and builds a :class:`.spec.MatrixSpec`; the
design-map engine (:func:`parapend.maps.run.run_spec`: Zarr store, resume, local processes
or Dask) computes every bin (:mod:`.solve`: ``parapend sea`` per realization); then
:func:`matrix_dataset` draws the statistics, the resource (:mod:`.resource`) and the annual
energy (:mod:`.annual`); :mod:`.figures` draws the three figures.
"""

from __future__ import annotations

import logging
import math
import os
import time

import numpy as np

from .. import limits
from ..errors import ParameterError, check_int, check_positive, check_range
from .annual import HOURS_PER_YEAR
from .resource import bin_edges, energy_flux, record_spectrum, te_over_tp
from .spec import DEVICES, UNITS, MatrixSpec

__all__ = ["HOURS_PER_YEAR", "STATISTICS", "MatrixSpec", "annual_interval", "breaking_bins",
           "matrix_dataset", "matrix_extremes", "matrix_quantities", "matrix_spec", "parse_bins",
           "power_matrix", "to_mhkit"]

log = logging.getLogger(__name__)

#: the statistics of each bin over its realizations (IEC TS 62600-100; std with ddof 0)
STATISTICS = ("mean", "std", "min", "max", "count")


#: depth-limited breaking: Hm0 / depth above this (the breaker index of a solitary wave,
#: 0.78) is a sea state that cannot exist; the flux of linear theory there is meaningless
BREAKING = 0.78


def check_depth(value) -> float:
    """A water depth in m: positive and at least 1e-3 m (below, the dispersion relation's
    wave numbers leave the floating-point range: 5e-324 gave a NaN flux); the check
    against the waves' height is :func:`power_matrix`'s."""
    x = check_positive("depth", value)
    if x < 1e-3:
        raise ParameterError(f"depth: expected a water depth of at least 0.001 m, got {x:g}")
    return x


def parse_bins(name: str, value) -> tuple:
    """Bin centres: ``FROM:TO:N`` (N values, ends included), ``A,B,C`` or a sequence;
    positive, increasing, at least two (the edges need a step)."""
    if isinstance(value, str):
        text = value.strip()
        if text.count(":") == 2:
            a, b, c = text.split(":")
            try:
                lo, hi, n = float(a), float(b), int(c)
            except ValueError:
                raise ParameterError(f"{name}: expected FROM:TO:N with numbers and an integer "
                                     f"N, got {value!r:.60}") from None
            if n < 2:
                raise ParameterError(f"{name}: expected at least 2 bins, got {n}")
            vals = np.linspace(lo, hi, n)
        elif ":" in text:
            raise ParameterError(f"{name}: expected FROM:TO:N or a comma list, got "
                                 f"{value!r:.60}")
        else:
            try:
                vals = np.array([float(p) for p in text.split(",")]) if text else np.array([])
            except ValueError:
                raise ParameterError(f"{name}: expected numbers separated by commas, got "
                                     f"{value!r:.60}") from None
    else:
        try:
            vals = np.atleast_1d(np.asarray(value, dtype=float))
        except (TypeError, ValueError):
            raise ParameterError(f"{name}: expected FROM:TO:N, a comma list or numbers") \
                from None
    if vals.ndim != 1 or vals.size < 2:
        raise ParameterError(f"{name}: expected at least 2 bin centres, got {vals.size}")
    if vals.size > 1000:
        raise ParameterError(f"{name}: expected at most 1000 bins, got {vals.size}")
    if not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ParameterError(f"{name}: expected positive bin centres, got "
                             f"{', '.join(f'{v:g}' for v in vals[:6])}")
    if np.any(np.diff(vals) <= 0):
        raise ParameterError(f"{name}: expected increasing bin centres (empty bins otherwise)")
    return tuple(float(v) for v in vals)


def matrix_spec(*, hs="1:3:3", te=None, tp=None, realizations: int = 3, waves=None,
                seed: int = 0, spectrum: str = "jonswap", gamma_peak: float = 3.3,
                cutoff: float = 3.0, response=None, device: str = "prescribed-heave",
                horizon=None, length=None, mass=None, inertia=None,
                gravity: float = 9.81, gamma=None, damping_coefficient=None, winding=1,
                harmonics=None, efficiency=None, torque_limit=None, body=None, radius=None,
                draft=None, mesh=None, hydro=None, density: float = 1025.0,
                depth=None, dofs="heave", pivot_height=None, pivot_offset=None,
                hull_pitch_inertia=None, barge_length=None, barge_beam=None,
                barge_draft=None, copper_loss=None, controller=None, forecast=None,
                update_interval=None, warm_up=None, plan_samples=None,
                speed_limit=None, planner=None) -> MatrixSpec:
    """Check everything a matrix's bins depend on (one line naming the parameter).
    ``length``, ``mass``: None is the device's default (``parapend.defaults.SEA`` for the
    prescribed-heave pendulum, ``BUOY`` for the buoy); ``body, radius, draft, mesh, hydro``
    are the buoy's body as ``parapend buoy`` takes them; ``density`` (kg/m^3) and ``depth``
    (m, None deep water) the water the buoy's body is solved in (a ``hydro`` dataset's
    own otherwise; the prescribed device's record does not depend on them). ``dofs``
    ``"surge,heave,pitch"`` (with ``device="buoy"``): a pendulum in a hull that surges,
    heaves and pitches, ``pivot_height ... copper_loss`` and ``torque_limit`` as
    ``parapend.buoy`` takes them (``parapend.performance.hull_device``). ``controller``
    ``"mpc"`` (``device="prescribed-heave"`` or ``"buoy"``, the hull too): the causal column,
    ``horizon``, ``forecast``, ``update_interval``, ``warm_up``, ``plan_samples`` and
    ``speed_limit`` as ``parapend.performance.causal.check_causal`` takes them (None:
    ``CAUSAL``, the buoy's ``BUOY_CAUSAL``), and ``planner`` (``device="buoy"``: the
    heaving buoy's ``plan`` or ``coupled``, the hull's ``lbfgsb`` or ``collocation``)."""
    from ..hydro.api import parse_dofs
    from ..seas import _check_sea, check_response, read_response
    from ..units import Units
    from .causal import check_causal

    if not isinstance(device, str) or device not in DEVICES:
        raise ParameterError(f"device: expected one of {', '.join(DEVICES)}, got "
                             f"{device!r:.60}")
    hull = {"pivot_height": pivot_height, "pivot_offset": pivot_offset,
            "hull_pitch_inertia": hull_pitch_inertia, "barge_length": barge_length,
            "barge_beam": barge_beam, "barge_draft": barge_draft, "copper_loss": copper_loss}
    heave = parse_dofs(dofs) == ("heave",)
    if not heave and device != "buoy":
        raise ParameterError("dofs: a hull that surges, heaves and pitches needs --device buoy")
    if heave:
        for name, v in hull.items():
            if v is not None:
                raise ParameterError(f"{name.replace('_', '-')}: a hull's option; needs --dofs "
                                     "surge,heave,pitch (with --device buoy)")
    if device != "buoy":
        given = [n for n, v in (("body", body), ("radius", radius), ("draft", draft),
                                ("mesh", mesh), ("hydro", hydro)) if v is not None]
        if given:
            raise ParameterError(f"{given[0]}: a body is only used with --device buoy")
        from ..defaults import SEA

        length = SEA["length"] if length is None else length
        mass = SEA["mass"] if mass is None else mass
    causal = check_causal(controller=controller, horizon=horizon, forecast=forecast,
                          update_interval=update_interval, warm_up=warm_up,
                          plan_samples=plan_samples, speed_limit=speed_limit,
                          device=device, heave=heave, planner=planner,
                          lossy=efficiency is not None and efficiency != 1.0)
    if torque_limit is not None and heave:
        raise ParameterError("torque-limit: not supported over a sea record (parapend sea "
                             "solves the unconstrained optimum); drop --torque-limit")
    # None: the default bins, as te (parse_bins(None) read as one centre: "got 1")
    hm0 = parse_bins("hs", "1:3:3" if hs is None else hs)
    if te is not None and tp is not None:
        raise ParameterError("te, tp: give the period bins as one of --te or --tp")
    kind, per = ("tp", tp) if tp is not None else ("te", "6:10:3" if te is None else te)
    period = parse_bins(kind, per)
    # the spectrum's options first (a valid sea state stands in for the bins, checked below)
    _, _, gamma_peak, _, cutoff = _check_sea(1.0, 8.0, spectrum, gamma_peak, None, cutoff)
    ratio = te_over_tp(spectrum, gamma_peak)
    tps = tuple(p / ratio for p in period) if kind == "te" else period
    realizations = check_int("realizations", realizations, 1, 1000)
    min_record = None
    if waves is None:  # the device's record: the hull's own (its solver's reach)
        from ..defaults import HULL, POWER_MATRIX

        # the hull: 20-minute records where they are solved matrix-free (an ideal take-off)
        ideal = efficiency in (None, 1.0) and copper_loss in (None, 0.0) and \
            torque_limit is None
        waves = POWER_MATRIX["waves"] if heave else HULL[
            "matrix_waves" if ideal else "matrix_waves_lossy"]
        if ideal and not heave:
            min_record = HULL["matrix_record_s"]
    waves = check_range("waves", waves, *limits.SEA_WAVES_RANGE,
                        why="record length in peak periods")
    seed = check_int("seed", seed, 0, 2**62)
    for h in (hm0[0], hm0[-1]):
        if h > limits.SEA_MAX_HS:
            raise ParameterError(f"hs: expected bin centres up to {limits.SEA_MAX_HS:g} m, "
                                 f"got {h:g}")
        if h < limits.SEA_MIN_HS:  # sea's floor: every bin below it failed alone
            raise ParameterError(f"hs: expected bin centres of at least "
                                 f"{limits.SEA_MIN_HS:g} m, got {h:g}")
    for t in (tps[0], tps[-1]):
        if not limits.SEA_TP_RANGE[0] <= t <= limits.SEA_TP_RANGE[1]:
            raise ParameterError(f"{kind}: expected peak periods from "
                                 f"{limits.SEA_TP_RANGE[0]:g} to {limits.SEA_TP_RANGE[1]:g} s, "
                                 f"got {t:g} s" + (f" (Te {t * ratio:g} s)" if kind == "te"
                                                   else ""))
    if not heave:
        return _hull_spec(hm0, period, kind, tps, realizations, waves, seed, spectrum,
                          gamma_peak, cutoff, response=response, length=length, mass=mass,
                          inertia=inertia, gravity=gravity, gamma=gamma,
                          damping_coefficient=damping_coefficient, winding=winding,
                          harmonics=harmonics, efficiency=efficiency,
                          torque_limit=torque_limit, body=body, radius=radius, draft=draft,
                          mesh=mesh, hydro=hydro, density=density, depth=depth,
                          causal=causal, min_record=min_record, **hull)
    if device == "buoy":
        return _buoy_spec(hm0, period, kind, tps, realizations, waves, seed, spectrum,
                          gamma_peak, cutoff, response=response, length=length, mass=mass,
                          inertia=inertia, gravity=gravity, gamma=gamma,
                          damping_coefficient=damping_coefficient, winding=winding,
                          harmonics=harmonics, efficiency=efficiency, body=body,
                          radius=radius, draft=draft, mesh=mesh, hydro=hydro,
                          density=density, depth=depth, causal=causal)
    units = Units(length, mass, gravity, inertia)
    if gamma is not None and damping_coefficient is not None:
        raise ParameterError("gamma: give either gamma or damping-coefficient, not both")
    if damping_coefficient is not None:
        gamma = units.gamma(damping_coefficient)
    gamma = check_range("gamma", 0.01 if gamma is None else gamma, 0.0, limits.MAX_GAMMA)
    if efficiency is not None:
        from .check import check_efficiency

        efficiency = check_efficiency(efficiency)
    if response is not None:
        if isinstance(response, (str, os.PathLike)):
            rf, rg, rp = read_response(response)
        else:
            try:
                rf, rg, rp = response
            except (TypeError, ValueError):
                raise ParameterError("response: expected a CSV path or three arrays (f, gain, "
                                     "phase)") from None
            rf, rg, rp = check_response(rf, rg, rp)
        response = tuple(tuple(float(v) for v in c) for c in (rf, rg, rp))
    if harmonics is not None:
        harmonics = check_int("harmonics", harmonics, 1, limits.SEA_MAX_HARMONICS // 2)
    if not isinstance(winding, str):
        winding = check_int("winding", winding, 1, limits.SEA_MAX_HARMONICS // 8)
    elif winding != "auto":
        raise ParameterError(f"winding: expected a positive integer or 'auto', got "
                             f"{winding!r:.60}")
    return MatrixSpec(hm0, period, kind, tps, realizations, float(waves), seed, spectrum,
                      float(gamma_peak), float(cutoff), response, float(length), float(mass),
                      None if inertia is None else float(inertia), float(gravity),
                      float(gamma), winding, harmonics,
                      None if efficiency is None else float(efficiency), device,
                      **(causal or {}))


def _buoy_spec(hm0, period, kind, tps, realizations, waves, seed, spectrum, gamma_peak,
               cutoff, *, body, radius, draft, mesh, hydro, density=1025.0, depth=None,
               causal=None, **pendulum) -> MatrixSpec:
    """The coupled buoy's spec: the pendulum and the body checked as ``parapend buoy`` checks
    them, the BEM solved (or loaded) once over every bin's band, every bin checked to lie
    in the data."""
    import dataclasses
    import os

    from . import buoy_device

    pend, winding, harmonics, efficiency = buoy_device.check_buoy(**pendulum)
    density = check_range("density", density, 500.0, 2000.0, why="kg/m^3")
    depth = None if depth is None else check_depth(depth)
    _check_breaking(hm0, depth)  # before the body's BEM
    body = "cylinder" if body is None else body
    if body == "barge":
        raise ParameterError("body: the barge is a hull that pitches: give --dofs "
                             "surge,heave,pitch")
    if not isinstance(body, str) or body not in ("cylinder", "sphere"):
        raise ParameterError(f"body: expected cylinder or sphere, got {body!r:.40}")
    radius = None if radius is None else check_positive("radius", radius)
    draft = None if draft is None else check_positive("draft", draft)
    mesh = None if mesh is None else buoy_device.check_file(mesh, "mesh")
    hydro = None if hydro is None else buoy_device.check_file(hydro, "hydro")
    spec = MatrixSpec(hm0, period, kind, tps, realizations, float(waves), seed, spectrum,
                      float(gamma_peak), float(cutoff), None, float(pend.length),
                      float(pend.mass), float(pend.inertia), 9.81, 0.0, winding, harmonics,
                      efficiency, "buoy", body=body,
                      radius=None if radius is None else float(radius),
                      draft=None if draft is None else float(draft),
                      mesh=None if mesh is None else os.path.abspath(mesh),
                      hydro=None if hydro is None else os.path.abspath(hydro),
                      damping_coefficient=float(pend.damping_coefficient),
                      # a dataset was solved in its own water (water_of reads it back)
                      water_density=1025.0 if hydro is not None else float(density),
                      water_depth=None if hydro is not None or depth is None
                      else float(depth), **(causal or {}))
    spec = dataclasses.replace(spec, band=buoy_device.band(spec),
                               digest=buoy_device.file_digest(mesh if hydro is None
                                                              else hydro))
    width = buoy_device.prepare(spec)
    return dataclasses.replace(spec, width=width)


def _record_lengths(spec) -> str:
    """The records' length in peak periods for the announcement: ``200``, or ``200- to 216.8``
    where the bins' differ."""
    lengths = [spec.record_waves(j) for j in range(len(spec.tp))]
    lo, hi = min(lengths), max(lengths)
    return f"{lo:g}" if lo == hi else f"{lo:g}- to {hi:.4g}"


def _hull_spec(hm0, period, kind, tps, realizations, waves, seed, spectrum, gamma_peak,
               cutoff, *, response, gamma, gravity, winding, harmonics, efficiency,
               torque_limit, length, mass, inertia, damping_coefficient, body, radius, draft,
               mesh, hydro, density, depth, causal=None, min_record=None,
               **hull) -> MatrixSpec:
    """The hull's spec (``dofs="surge,heave,pitch"``): the options the hull does not take
    refused, the rest checked and resolved by the hull's own code (its defaults,
    ``parapend.defaults.HULL``), the hull built once (its BEM), every bin's record checked."""
    from . import buoy_device, hull_device

    buoy_device.refuse_for_buoy(response=response, gamma=gamma, gravity=gravity)
    if winding != 1:
        raise ParameterError("winding: with --dofs surge,heave,pitch each record compares "
                             "rotation (one turn per wave), swinging and rest; drop --winding")
    if hydro is None:
        for name, bad in (("density", density != 1025.0), ("depth", depth is not None)):
            if bad:
                raise ParameterError(f"{name}: the hull's BEM is solved in deep water at 1025 "
                                     f"kg/m^3; drop --{name} with --dofs surge,heave,pitch (or "
                                     "give a --hydro dataset solved in that water)")
    if efficiency is not None:
        from .check import check_efficiency

        efficiency = float(check_efficiency(efficiency))
    mesh = None if mesh is None else buoy_device.check_file(mesh, "mesh")
    hydro = None if hydro is None else buoy_device.check_file(hydro, "hydro")
    spec = MatrixSpec(hm0, period, kind, tps, realizations, float(waves), seed, spectrum,
                      float(gamma_peak), float(cutoff), None, length, mass, inertia, 9.81,
                      0.0, 1, harmonics, efficiency, "buoy",
                      digest=buoy_device.file_digest(mesh if hydro is None else hydro),
                      damping_coefficient=damping_coefficient, dofs="surge,heave,pitch",
                      **(causal or {}))
    spec = hull_device.resolve(spec, dict(body=body, radius=radius, draft=draft, mesh=mesh,
                                          hydro=hydro, torque_limit=torque_limit, **hull))
    if min_record is not None:
        spec = hull_device.lengthen(spec, min_record)
    hull_device.check_records(spec)
    return spec


def _stats(x: np.ndarray, ok: np.ndarray) -> dict:
    """Statistics over the last axis of ``x`` where ``ok``; NaN where nothing is."""
    v = np.where(ok, x, np.nan)
    n = ok.sum(axis=-1)
    import warnings

    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN bins: NaN, count 0
        out = {"mean": np.nanmean(v, axis=-1), "std": np.nanstd(v, axis=-1),
               "min": np.nanmin(v, axis=-1), "max": np.nanmax(v, axis=-1)}
    out = {k: np.where(n > 0, a, np.nan) for k, a in out.items()}
    out["count"] = n.astype(np.int64)
    return out


#: the quantities of the optimum's solve: their statistics count only its successes
_SOLVED = ("power", "mechanical_power", "electrical_power", "peak_torque", "peak_pivot_force")
#: a causal run above its record's non-causal optimum by more than this (relative) is not an
#: answer: no causal controller beats the omniscient one on the same record, and the
#: time-domain plant and the frequency-domain optimum agree far closer than this
CAUSAL_SLACK = 0.01


def matrix_quantities(spec: MatrixSpec) -> tuple:
    """The per-realization quantities of the full Dataset (W), the headline ``power`` first:
    the store's, and with an efficiency ``mechanical_power`` (``_headline``)."""
    q = _stored(spec)
    return (q[0], "mechanical_power", *q[1:]) if spec.lossy else q


def _stored(spec: MatrixSpec) -> tuple:
    """The store's per-realization powers (W): its variables but the status and the mode."""
    return tuple(v for v in spec.variables if v not in ("status", "mode", "failure"))


def _headline(ds, spec: MatrixSpec):
    """The store's per-realization Dataset as the user reads it (the electrical headline,
    as ``parapend buoy`` and ``optimize``): with an efficiency, ``power`` is the electrical
    power (what the take-off delivers: the power matrix, capture width and annual energy
    are of it) and ``mechanical_power`` the same motion's mechanical power; the store keeps
    its own names (``power`` mechanical), so a store resumes whatever reads it."""
    names = spec.long_names()
    for q in _stored(spec):
        ds[q].attrs["long_name"] = names[q]
    if not spec.lossy:
        return ds
    mech, elec = ds["power"].copy(), ds["electrical_power"]
    mech.attrs = {"long_name": "mechanical power -<T theta'> of the motion whose electrical "
                               "power is the power", "units": "W"}
    ds["mechanical_power"] = mech
    ds["power"] = elec.copy()
    ds["power"].attrs = {
        "long_name": ("coupled electrical optimum (the take-off's output)"
                      if spec.device == "buoy" else
                      "electrical power of the ideal optimum's motion through the take-off "
                      "(a lower bound on the electrical optimum)"), "units": "W",
        "efficiency": spec.efficiency}
    return ds


def matrix_dataset(raw, spec: MatrixSpec, *, depth=None, density: float = 1025.0,
                   width=None, frequency=None, outside=None, rated_power=None):
    """The full Dataset from the engine's per-realization Dataset ``raw``: statistics,
    resource, capture width, and with ``frequency`` the annual energy."""
    from ..maps.spec import _CODE
    from .annual import annual_energy, bin_power, capacity_factor

    pk = spec.period_kind
    ds = _headline(raw.copy(), spec)
    status = ds["status"].values
    done = ds["done"].values.astype(bool)
    # a solve counts where it succeeded: converged, or no_power (no motion harvests: the
    # device rests in that record, its optimum's power <= 0 kept as solved)
    solved = done & np.isin(status, [_CODE["converged"], _CODE["no_power"]])
    dims2 = ("hm0", pk)
    if spec.controller is not None:
        _causal_above_optimum(ds, spec, solved)
    for q in matrix_quantities(spec):
        solve_q = q in _SOLVED
        ok = (solved if solve_q else done) & np.isfinite(ds[q].values)
        st = _stats(ds[q].values, ok)
        unit = ds[q].attrs.get("units", "W")
        for s in STATISTICS:
            ds[f"{q}_{s}"] = (dims2, st[s], {
                "long_name": f"{s} over the realizations of the {ds[q].attrs['long_name']}"
                             + (" (successful solves only)" if solve_q else ""),
                **({"units": unit} if s != "count" else {})})
    _bin_intervals(ds, spec, solved, dims2)
    # the resource of each bin
    j = np.empty((len(spec.hm0), len(spec.period)))
    te_rec = np.empty_like(j)
    for a, h in enumerate(spec.hm0):
        for b, tp in enumerate(spec.tp):
            f, s = record_spectrum(h, tp, spec.repeat_period(b), spectrum=spec.spectrum,
                                   gamma_peak=spec.gamma_peak, cutoff=spec.cutoff)
            j[a, b] = energy_flux(f, s, depth=depth, density=density, gravity=spec.gravity)
            te_rec[a, b] = float(np.sum(s / f) / np.sum(s))
    ds["wave_energy_flux_matrix"] = (dims2, j, {
        "long_name": "omnidirectional wave energy flux J = rho g sum S c_g df of the record's "
                     "spectrum", "units": "W/m",
        "depth": "deep water" if depth is None else f"{depth:g} m", "density": density})
    ds["te_record"] = (dims2, te_rec, {"long_name": "energy period m_-1/m0 of the record's "
                                                    "(cut) spectrum", "units": "s"})
    _mark_breaking(ds, spec, dims2)
    # the device's power in each bin: the mean optimum, or 0 where that is negative (a
    # real device stops the pendulum there: "rest"), never a loss (docs/performance.md)
    pm = bin_power(ds["power_mean"].values)
    ds["power_matrix"] = (dims2, pm, {
        "long_name": "power matrix: the bin's power max(power_mean, 0) (0: the pendulum at "
                     "rest, where the mean optimum is negative)", "units": "W"})
    mean = ds["power_mean"].values
    with np.errstate(invalid="ignore"):
        mode = np.where(~np.isfinite(mean), -1, np.where(mean > 0, 1, 0)).astype(np.int8)
    mode_attrs = {"long_name": "the device's mode in the bin", "flag_values": [-1, 0, 1],
                  "flag_meanings": "no_result rest rotation"}
    if "mode" in ds:
        # the hull: rotation (either sense) or swinging, whichever more of the bin's
        # solved records chose (on a tie rotation, then reversed rotation, then swinging);
        # rest where the mean is not positive
        m = ds["mode"].values
        votes = np.stack([((m == c) & solved).sum(axis=-1) for c in (1, 3, 2)])
        chosen = np.array([1, 3, 2])[np.argmax(votes, axis=0)]  # argmax: the first of a tie
        mode = np.where(mode == 1, chosen, mode).astype(np.int8)
        mode_attrs = {"long_name": "the device's mode in the bin: rotation (in the sense of "
                                   "a positive pitch), reversed rotation or swinging, "
                                   "whichever more of its solved records chose (in that "
                                   "order on a tie); rest where the mean power is not "
                                   "positive",
                      "flag_values": [-1, 0, 1, 2, 3],
                      "flag_meanings": "no_result rest rotation swinging rotation_reversed"}
    ds["operating_mode"] = (dims2, mode, mode_attrs)
    if spec.controller is not None:
        _causal_matrix(ds, spec)
    ds["capture_width_matrix"] = (dims2, pm / j, {
        "long_name": "capture width P / J of the power matrix", "units": "m"})
    # over the realizations, each record's power as the device delivers it: max(P, 0) (at
    # rest where its optimum is negative), so no capture width is negative and
    # min <= capture_width_matrix <= max
    rec = bin_power(ds["power"].values)
    st = _stats(rec, solved & np.isfinite(rec))
    for s in ("std", "min", "max"):
        ds[f"capture_width_{s}"] = (dims2, st[s] / j, {
            "long_name": f"capture width max(P, 0) / J, {s} over the realizations",
            "units": "m"})
    if width is not None:
        ds["capture_width_ratio_matrix"] = (dims2, pm / j / width, {
            "long_name": f"capture width ratio P / (J w), w = {width:g} m", "units": "1",
            "width": width})
    ds = ds.assign_coords({
        "hm0_edges": ("hm0_edge", bin_edges(spec.hm0), {"long_name": "Hm0 bin edges (MHKiT)",
                                                         "units": "m"}),
        f"{pk}_edges": (f"{pk}_edge", bin_edges(spec.period),
                        {"long_name": f"{pk} bin edges (MHKiT)", "units": "s"})})
    annual = None
    if frequency is not None:
        ds["frequency"] = (dims2, frequency, {"long_name": "share of the year of the bin"})
        annual = {}
        need = (np.asarray(frequency) > 0) & np.any(
            [~np.isfinite(ds[f"{q}_mean"].values) for q in matrix_quantities(spec)], axis=0)
        bound, bound_name = (_bin_bounds(ds, spec, need) if need.any() and not outside
                             else (None, "bound"))
        for q in matrix_quantities(spec):
            if q.endswith("_harvested_power") or q in UNITS:
                continue  # without its storage correction (or not a power): no annual energy
            a = annual_energy(ds[f"{q}_mean"].values, frequency,
                              outside["frequency"] if outside else 0.0, bound=bound,
                              bound_name=bound_name)
            a["bins_without_power"] = [{"hm0": spec.hm0[i], pk: spec.period[k],
                                        "frequency": float(frequency[i, k])}
                                       for i, k in a.pop("missing")]
            if outside:
                a["outside_frequency"] = outside
            if rated_power is not None:
                # incomplete: no plain number, only its bounds
                a["capacity_factor"] = (capacity_factor(a["wh"], rated_power)
                                        if a["complete"] else None)
                if not a["complete"]:
                    a["capacity_factor_bounds"] = [
                        None if w is None else capacity_factor(w, rated_power)
                        for w in a["wh_bounds"]]
            if q == "power":
                a.update(annual_interval(ds, frequency, solved))
            annual[q] = a
        # the completeness in the file too (NetCDF has no boolean attribute: 1 or 0)
        ds.attrs["annual_energy_complete"] = int(annual["power"]["complete"])
        ds.attrs["annual_energy_ci_method"] = (annual["power"]["ci_method"]
                                               or "none: fewer than 2 solved realizations")
        ds.attrs["annual_energy_mwh_ci"] = [_nan_none(v) for v in
                                            (annual["power"]["mwh_ci"] or [None, None])]
        if annual["power"]["complete"]:
            ds.attrs["annual_energy_mwh"] = annual["power"]["mwh"]
        else:
            # NaN: no upper bound (a NetCDF attribute holds no None)
            ds.attrs["annual_energy_mwh_bounds"] = [_nan_none(b) for b in
                                                    annual["power"]["mwh_bounds"]]
            ds.attrs["annual_energy_uncounted_frequency"] = \
                annual["power"]["uncounted_frequency"]
        if spec.controller is not None:
            _annual_columns(ds, spec, annual)
    ds.attrs["hours_per_year"] = HOURS_PER_YEAR
    return ds, annual


def _mark_breaking(ds, spec: MatrixSpec, dims2) -> None:
    """Each bin's significant steepness ``Hs / lambda_p`` (``lambda_p = g Tp^2 / (2 pi)``,
    :func:`parapend.seas.sea_steepness`) and whether it is past breaking (``> 1/7``). A
    matrix is a rectangle: its steep corners are solved as the linear seas they describe,
    which no real sea reaches; they are marked, not refused."""
    from ..seas import BREAKING_STEEPNESS, sea_steepness

    steep = np.array([[sea_steepness(h, tp, spec.gravity) for tp in spec.tp]
                      for h in spec.hm0])
    ds["steepness"] = (dims2, steep, {
        "long_name": "significant steepness Hs / lambda_p of the bin (lambda_p the deep-water "
                     "wavelength of its peak period)", "units": "1"})
    ds["past_breaking"] = (dims2, (steep > BREAKING_STEEPNESS).astype(np.int8), {
        "long_name": "the bin's sea is past breaking (Hs / lambda_p > 1/7): solved as a "
                     "linear sea, which no real sea reaches", "flag_values": [0, 1],
        "flag_meanings": "sea past_breaking"})


def breaking_bins(ds, pk: str, annual=None) -> dict:
    """The bins past breaking for the JSON: ``bins_past_breaking`` (each bin's Hm0, period,
    steepness and share of the year) and, with a site, ``past_breaking_frequency`` (their
    share of the year) and ``past_breaking_mwh`` (the annual energy they contribute)."""
    if "past_breaking" not in ds:
        return {}
    flag = ds["past_breaking"].values.astype(bool)
    f = ds["frequency"].values if "frequency" in ds else None
    out = {"bins_past_breaking": [
        {"hm0": float(ds["hm0"].values[i]), pk: float(ds[pk].values[j]),
         "steepness": float(ds["steepness"].values[i, j]),
         "frequency": None if f is None else float(f[i, j])} for i, j in np.argwhere(flag)]}
    if f is not None:
        out["past_breaking_frequency"] = float(f[flag].sum())
        pm = ds["power_matrix"].values
        ok = flag & np.isfinite(pm)
        out["past_breaking_mwh"] = float(HOURS_PER_YEAR * np.sum(f[ok] * pm[ok]) / 1e6)
    return out


def _bin_intervals(ds, spec: MatrixSpec, solved, dims2) -> None:
    """Each bin's 95 % t-interval of its mean power over its solved realizations
    (:func:`parapend.confidence.t_interval`: ``power_ci_low``, ``power_ci_high``; NaN below
    two), and for the hull the reason of each bin's unsolved records (``failed_solves``,
    ``failure``: the commonest reason among them, -1 where none failed)."""
    from ..confidence import METHOD, t_interval

    p = ds["power"].values
    lo = np.full(p.shape[:2], np.nan)
    hi = np.full(p.shape[:2], np.nan)
    for i, j in np.ndindex(*p.shape[:2]):
        ci = t_interval(p[i, j][solved[i, j] & np.isfinite(p[i, j])])
        if ci["low"] is not None:
            lo[i, j], hi[i, j] = ci["low"], ci["high"]
    for name, v, end in (("power_ci_low", lo, "lower"), ("power_ci_high", hi, "upper")):
        ds[name] = (dims2, v, {"long_name": f"{end} end of the 95 % interval of the bin's mean "
                                            "power (NaN: fewer than 2 solved realizations)",
                               "units": "W", "method": METHOD})
    if "failure" not in ds:
        return
    from .hull_device import FAILURES

    done = ds["done"].values.astype(bool)
    f = ds["failure"].values
    bad = done & ~solved
    count = bad.sum(axis=-1)
    common = np.full(count.shape, -1, dtype=np.int8)
    for i, j in np.argwhere(count > 0):
        codes = f[i, j][bad[i, j]]
        codes = np.where(codes < 0, FAILURES.index("other"), codes)
        common[i, j] = int(np.bincount(codes, minlength=len(FAILURES)).argmax())
    ds["failed_solves"] = (dims2, count.astype(np.int64), {
        "long_name": "realizations of the bin without a resolved answer (left out of its "
                     "mean, and the bin out of the annual energy when none is left)"})
    ds["bin_failure"] = (dims2, common, {
        "long_name": "the commonest reason among the bin's unresolved realizations",
        "flag_values": [-1, *range(len(FAILURES))],
        "flag_meanings": " ".join(["none_failed", *(x.replace(" ", "_") for x in FAILURES)])})


#: how the annual energy's interval is formed, by case
AEP_CI_PAIRED = ("paired: the annual energy of each realization r, 8766 h sum_b f_b P_b,r "
                 "(realization r has seed seed + r in every bin: common random numbers), "
                 "its Student t-interval over the realizations (95 %, R - 1 degrees of "
                 "freedom)")
AEP_CI_SUMMED = ("summed: 8766 h sum_b f_b h_b, h_b each counted bin's half-width (95 % "
                 "t-interval over its solved realizations): the bins share their seeds, so "
                 "their errors are correlated; the sum of the half-widths holds whatever the "
                 "correlation (conservative)")


def annual_interval(ds, frequency, solved) -> dict:
    """The 95 % interval (``mwh_ci``, MWh, and ``ci_method``) of the annual energy counted
    (``8766 h sum_b f_b max(mean_b, 0)`` over the bins with a frequency and a power).

    Every counted bin with a positive mean solved in every realization: the paired
    interval (``AEP_CI_PAIRED``; a bin at rest counts 0 in each). Otherwise the
    half-widths summed (``AEP_CI_SUMMED``). None where a counted bin with a positive
    mean has fewer than two solved realizations (no interval). The lower end is at least 0
    (the annual energy is never negative: the interval cut to where it can lie keeps its
    coverage)."""
    from ..confidence import t_interval
    from .annual import bin_power

    f = np.asarray(frequency, dtype=float)
    p = ds["power"].values
    mean = bin_power(ds["power_mean"].values)
    counted = (f > 0) & np.isfinite(mean) & (mean > 0)
    none = {"mwh_ci": None, "ci_method": None}
    if not counted.any():
        return none
    ok = solved & np.isfinite(p)
    if ok[counted].all() and p.shape[-1] >= 2:
        per = HOURS_PER_YEAR * np.einsum("ij,ijr->r", np.where(counted, f, 0.0),
                                         np.where(counted[..., None], p, 0.0))
        ci = t_interval(per)
        return {"mwh_ci": [max(ci["low"], 0.0) / 1e6, ci["high"] / 1e6],
                "ci_method": AEP_CI_PAIRED,
                "realization_mwh": [float(v) / 1e6 for v in per]}
    half = 0.0
    for i, j in np.argwhere(counted):
        ci = t_interval(p[i, j][ok[i, j]])
        if ci["half_width"] is None:
            return none
        half += HOURS_PER_YEAR * f[i, j] * ci["half_width"]
    wh = HOURS_PER_YEAR * float(np.sum(np.where(counted, f * mean, 0.0)))
    return {"mwh_ci": [max(wh - half, 0.0) / 1e6, (wh + half) / 1e6],
            "ci_method": AEP_CI_SUMMED}


def matrix_extremes(ds, pk: str) -> dict:
    """The hull's generator rating and its unresolved bins, for the JSON (empty for the
    other devices): ``peak_torque_nm`` and ``peak_pivot_force_n`` (each bin's largest over
    its solved realizations; null where none), the site's largest (``site_peak_torque_nm``,
    ``site_peak_pivot_force_n``: over the bins with a share of the year when a site is
    given, else over all) and where it lies, and ``bin_failures``: each bin with an
    unresolved realization, how many and why."""
    if "peak_torque_max" not in ds:
        return {}
    from .hull_device import FAILURES

    out = {}
    share = ds["frequency"].values > 0 if "frequency" in ds else None
    for q, key in (("peak_torque", "peak_torque_nm"), ("peak_pivot_force", "peak_pivot_force_n")):
        v = ds[f"{q}_max"].values
        out[key] = [[_finite(float(x)) for x in row] for row in v]
        w = np.where(np.isfinite(v) & (True if share is None else share), v, -np.inf)
        if np.isfinite(w).any():
            i, j = np.unravel_index(int(np.argmax(w)), w.shape)
            out[f"site_{key}"] = float(v[i, j])
            out[f"site_{key.rsplit('_', 1)[0]}_bin"] = {"hm0": float(ds["hm0"].values[i]),
                                                        pk: float(ds[pk].values[j])}
        else:
            out[f"site_{key}"] = None
            out[f"site_{key.rsplit('_', 1)[0]}_bin"] = None
    fails = []
    if "failed_solves" in ds:
        codes = ds["failure"].values
        done = ds["done"].values.astype(bool)
        for i, j in np.argwhere(ds["failed_solves"].values > 0):
            st = ds["status"].values[i, j]
            bad = done[i, j] & ~np.isin(st, [0, 1])
            reasons = sorted({FAILURES[c] if c >= 0 else "other" for c in codes[i, j][bad]})
            fails.append({"hm0": float(ds["hm0"].values[i]), pk: float(ds[pk].values[j]),
                          "failed": int(bad.sum()), "realizations": int(codes.shape[-1]),
                          "reasons": reasons,
                          "frequency": (float(ds["frequency"].values[i, j])
                                        if "frequency" in ds else None)})
    out["bin_failures"] = fails
    return out


def annual_columns(spec: MatrixSpec) -> dict:
    """The power columns whose annual energies stand side by side: the non-causal
    optimum, then each forecast's causal column: label -> quantity."""
    return {"optimum": "power", **{f"causal_{f}": f"causal_{f}_power"
                                   for f in spec.forecasts}}


#: the fewest bins a matrix has: two centres on each axis
MIN_BINS = 4


def untimed_advice(most: int, bins: int, realizations: int, period_kind: str):
    """``(option, advice)`` for a matrix of ``bins`` x ``realizations`` solves of which
    ``most`` fit in the untimed cap: fewer realizations where they suffice, else fewer bins
    where at least :data:`MIN_BINS` fit (the command refuses fewer: two centres an axis),
    else shorter records (``--waves``): never a change the command itself refuses."""
    if most >= bins:
        return "realizations", f"use --realizations at most {most // bins}"
    if most // realizations >= MIN_BINS:
        return "hs", (f"use at most {most // realizations} bins (--hs times --{period_kind} "
                      f"centres) at {realizations} realizations")
    if most >= MIN_BINS:
        return "hs", (f"use --realizations 1 and at most {most} bins (--hs times "
                      f"--{period_kind} centres)")
    return "waves", (f"not even {MIN_BINS} bins (2 --hs and 2 --{period_kind} centres) of one "
                     "realization fit: use fewer --waves")


def _nan_none(x) -> float:
    """``x`` as a float, NaN for None (no bound)."""
    return math.nan if x is None else float(x)


def _record_bound(spec: MatrixSpec, i: int, j: int, r: int) -> float:
    """A true upper bound (W) of any power of realization ``r`` of bin ``(i, j)``, from its
    record alone (no solve, no BEM beyond the body's one): the gamma -> 0 limit
    ``omega_r TV(q) / 2 pi`` (prescribed heave), the radiation bound ``sum_k |F_k a_k|^2 /
    (8 B_k)`` (the heaving buoy); NaN for the hull (its bound is not computed here)."""
    if spec.device == "buoy" and spec.dofs != "heave":
        return math.nan
    if spec.device == "buoy":
        from ..hydro.optimum import radiation_bound
        from .buoy_device import body_hydro, wave_of

        return radiation_bound(body_hydro(spec)[0], wave_of(spec, i, j, r)[0])
    from ..optimal.limit import limit
    from .check import _record, _units

    units = _units(spec)
    return units.to_watts(limit(_record(spec, units, i, j, r)).power)


def _bin_bounds(ds, spec: MatrixSpec, need):
    """``(bound, name)``: each bin's upper bound of its mean power (W) where ``need`` (NaN
    elsewhere, and where none is known): the largest over its realizations of the bound
    its solves stored (``limit_power``, ``radiation_bound_power``; each the record's own,
    computed before the solve), else of :func:`_record_bound`. The mean over any of the
    realizations, and each causal run's (a causal run cannot beat the optimum), is at most
    it."""
    name = "radiation_bound_power" if spec.device == "buoy" else "limit_power"
    label = ("radiation bound" if spec.device == "buoy" else "gamma -> 0 limit")
    out = np.full(need.shape, np.nan)
    stored = ds[name].values if name in ds else None
    for i, j in np.argwhere(need):
        vals = (np.full(spec.realizations, np.nan) if stored is None
                else np.array(stored[i, j], dtype=float))
        for r in np.flatnonzero(~np.isfinite(vals)):
            try:
                vals[r] = _record_bound(spec, int(i), int(j), int(r))
            except Exception as err:  # noqa: BLE001 - no bound: the upper end is not given
                log.warning("power matrix bin hm0=%g %s=%g: no %s (%s: %s)", spec.hm0[i],
                            spec.period_kind, spec.period[j], label, type(err).__name__, err)
        out[i, j] = float(np.max(vals)) if np.all(np.isfinite(vals)) else np.nan
    return out, label


def _causal_above_optimum(ds, spec: MatrixSpec, solved) -> None:
    """Leave out (NaN) each causal run above its own record's non-causal optimum by more
    than ``CAUSAL_SLACK``: a causal controller cannot beat the omniscient one on the same
    record, so such a mean is not an answer (a storage correction larger than the work, a
    reference short of the optimum); their count per forecast is the attribute
    ``above_optimum`` of ``causal_<forecast>_power``."""
    opt = np.where(solved, ds["power"].values, np.nan)
    for f in spec.forecasts:
        v = ds[f"causal_{f}_power"].values
        with np.errstate(invalid="ignore"):
            above = np.isfinite(v) & (opt > 0) & (v > opt * (1 + CAUSAL_SLACK))
        for q in (f"causal_{f}_power", f"causal_{f}_harvested_power"):
            if q in ds:
                ds[q] = (ds[q].dims, np.where(above, np.nan, ds[q].values),
                         {**ds[q].attrs, "above_optimum": int(above.sum())})


def _causal_matrix(ds, spec: MatrixSpec) -> None:
    """Each forecast's causal power matrix (the bin's best of the controller's run and
    rest) and the choice, and the controller's settings in the attributes."""
    from .annual import bin_power
    from .causal import HULL_PLANNERS

    dims2 = ("hm0", spec.period_kind)
    for f in spec.forecasts:
        mean = ds[f"causal_{f}_power_mean"].values
        ds[f"causal_{f}_power_matrix"] = (dims2, bin_power(mean), {
            "long_name": f"causal power matrix, {f} forecast: the bin's best of the "
                         "controller's run and rest, max(causal mean power, 0)",
            "units": "W"})
        with np.errstate(invalid="ignore"):
            mode = np.where(~np.isfinite(mean), -1, np.where(mean > 0, 1, 0)).astype(np.int8)
        ds[f"causal_{f}_mode"] = (dims2, mode, {
            "long_name": f"the causal device's choice in the bin, {f} forecast: the "
                         "controller where its mean power is positive, else rest",
            "flag_values": [-1, 0, 1], "flag_meanings": "no_result rest controller"})
    ds.attrs.update({"controller": spec.controller,
                     "causal_forecasts": ",".join(spec.forecasts),
                     "causal_horizon_peak_periods": spec.horizon,
                     "causal_update_interval_peak_periods": spec.update_interval,
                     "causal_warm_up_peak_periods": spec.warm_up,
                     "causal_convention": "from the hanging rest, 64 torque samples a peak "
                                          "period; the mean over one repeat of the record "
                                          "after the warm-up, (W_e + eta_g dE) / tau"})
    if spec.device == "buoy":
        # the buoy's controller (parapend.hydro.control.buoy_mpc): dE the mechanical energy
        # of buoy and pendulum; no planner samples or speed penalty (the pendulum's)
        ds.attrs["causal_buoy_controller"] = spec.buoy_controller
        ds.attrs["causal_convention"] = (
            "parapend.hydro.control.buoy_mpc, controller " + spec.buoy_controller + ": from "
            "the hanging rest, the buoy in its free periodic motion, 64 torque samples a peak "
            "period; the mean over one repeat of the record after the warm-up, "
            "(W_e + eta_g dE) / tau, E the mechanical energy of buoy and pendulum")
        if spec.buoy_controller in HULL_PLANNERS:
            planner = HULL_PLANNERS[spec.buoy_controller]
            ds.attrs["causal_convention"] = (
                f"parapend.hydro.hull_control.hull_mpc, planner {planner}: from the hanging "
                "rest, the hull in its "
                "free periodic motion, 24 torque samples a peak period, started from the "
                "motion of the record's optimum; the mean over one repeat of the record "
                "after the warm-up, (W_e + eta_g dE) / tau, E the mechanical energy of hull "
                "and pendulum")
    else:
        ds.attrs["causal_plan_samples"] = spec.plan_samples
        ds.attrs["causal_speed_limit"] = ("none" if spec.speed_limit is None
                                          else spec.speed_limit)


def _annual_columns(ds, spec: MatrixSpec, annual: dict) -> None:
    """The annual energy of each column side by side as variables over ``column``
    (MWh; NaN where incomplete, its bounds beside it), the capacity factors likewise."""
    cols = annual_columns(spec)
    recs = [annual[q] for q in cols.values()]
    nan = float("nan")
    # an integer coordinate with CF flag meanings: a string one is not in Zarr 3's
    # specification (zarr warns that other readers may not read it)
    ds.coords["column"] = ("column", np.arange(len(cols), dtype=np.int8), {
        "long_name": "power column: the non-causal optimum, the causal controller with "
                     "each forecast", "flag_values": list(range(len(cols))),
        "flag_meanings": " ".join(cols)})
    ds["annual_energy"] = ("column", [a["mwh"] if a["complete"] else nan for a in recs], {
        "long_name": "mean annual energy production 8766 h sum P f (NaN: incomplete, see "
                     "the bounds)", "units": "MWh"})
    ds["annual_energy_lower"] = ("column", [a.get("mwh_bounds", [a["mwh"]] * 2)[0]
                                            for a in recs], {
        "long_name": "annual energy, the uncounted share of the year at 0 W", "units": "MWh"})
    ds["annual_energy_upper"] = ("column", [
        _nan_none(a.get("mwh_bounds", [a["mwh"]] * 2)[1]) for a in recs], {
        "long_name": "annual energy, the bins without power at their bound (radiation "
                     "bound or gamma -> 0 limit; NaN: no upper bound)", "units": "MWh"})
    ds["annual_energy_complete"] = ("column", np.array([int(a["complete"]) for a in recs],
                                                       dtype=np.int8), {
        "long_name": "every sea state of the site in a bin with a result (1) or not (0)"})
    if recs[0].get("capacity_factor") is not None or recs[0].get("capacity_factor_bounds"):
        ds["capacity_factor"] = ("column", [nan if a.get("capacity_factor") is None
                                            else a["capacity_factor"] for a in recs], {
            "long_name": "capacity factor AEP / (8766 h x rated power) (NaN: incomplete)",
            "units": "1"})
        for k, name in ((0, "lower"), (1, "upper")):
            ds[f"capacity_factor_{name}"] = ("column", [
                _nan_none(a["capacity_factor_bounds"][k]) if a.get("capacity_factor_bounds")
                else a["capacity_factor"] for a in recs], {
                "long_name": f"capacity factor, {name} bound", "units": "1"})


def _check_breaking(hm0, depth) -> None:
    """The largest of the Hm0 bins ``hm0`` must not break in ``depth`` (m; None deep)."""
    if depth is not None and depth < hm0[-1] / BREAKING:
        raise ParameterError(f"depth: expected at least Hm0 / {BREAKING:g} = "
                             f"{hm0[-1] / BREAKING:.4g} m for the largest Hm0 bin "
                             f"({hm0[-1]:g} m: waves that high break in shallower "
                             f"water), got {depth:g} m")


#: work estimated above this many seconds is announced before it starts
_ANNOUNCE_SECONDS = 120.0


def to_mhkit(da):
    """A matrix variable with MHKiT's dimension names (``x_centers``, ``y_centers``), for
    ``mhkit.wave.performance`` (e.g. ``mean_annual_energy_production_matrix``)."""
    return da.rename({da.dims[0]: "x_centers", da.dims[1]: "y_centers"})


def power_matrix(*, hs="1:3:3", te=None, tp=None, realizations: int = 3, waves=None,
                 seed: int = 0, spectrum: str = "jonswap", gamma_peak: float = 3.3,
                 cutoff: float = 3.0, response=None, device: str = "prescribed-heave",
                 horizon=None, length=None, mass=None, inertia=None,
                 gravity: float = 9.81, gamma=None, damping_coefficient=None, winding=1,
                 harmonics=None, efficiency=None, torque_limit=None, body=None, radius=None,
                 draft=None, mesh=None, hydro=None, depth=None,
                 density: float = 1025.0, width=None, scatter=None, timeseries=None,
                 rated_power=None, store=None, overwrite: bool = False, workers=None,
                 scheduler=None, netcdf=None, zarr=None, csv=None, command=None,
                 progress=None, dofs="heave", pivot_height=None, pivot_offset=None,
                 hull_pitch_inertia=None, barge_length=None, barge_beam=None,
                 barge_draft=None, copper_loss=None, controller=None, forecast=None,
                 update_interval=None, warm_up=None, plan_samples=None, speed_limit=None,
                 planner=None, time_limit=None, pendulum=None, pto=None):
    """The power matrix of a device over bins of ``Hs x Te`` (or ``Tp``); see the module
    text and docs/performance.md. Returns ``(dataset, annual, run)``. ``dofs``
    ``"surge,heave,pitch"`` with ``device="buoy"``: a pendulum in a hull that surges, heaves
    and pitches (``pivot_height ... copper_loss`` as :func:`parapend.buoy` takes them).
    ``time_limit`` (s): no bin is started after it (:mod:`parapend.deadline`); the matrix
    then holds the bins finished (the rest NaN, count 0), its attributes say ``status``
    ``"time_limit"`` and ``bins_finished`` of ``bins``, and with ``store`` a rerun computes
    the rest. Without ``time_limit`` or ``store`` a matrix estimated above
    ``parapend.limits.MAX_UNTIMED_SECONDS`` is refused.

    ``controller="mpc"`` (``device="prescribed-heave"``): beside the non-causal optimum, the
    causal column of each ``forecast`` (``"perfect"``, ``"ar"`` or ``"perfect,ar"``; default
    ``"perfect"``): the receding-horizon controller on the same records, its
    storage-corrected mean electrical power after ``warm_up`` peak periods (default 4), with
    a ``horizon`` (peak periods, default 1), an ``update_interval`` (peak periods, default
    1/32) and ``plan_samples`` torque samples per Hermite interval of the plan (default 2,
    as ``horizon``), and ``speed_limit`` the plans' rated-speed penalty (units
    ``sqrt(g / l)``, default 4; ``inf``: none, ``horizon``'s default);
    ``parapend.performance.causal``. With ``device="buoy"`` (heave only) the column is the
    buoy's causal controller (``parapend.hydro.control.buoy_mpc`` with each ``forecast``,
    ``horizon`` 1 and ``update_interval`` 1/8 by default; no ``plan_samples`` or
    ``speed_limit``), the controller named in ``causal.buoy_controller``; ``planner`` its
    horizon solver as ``parapend buoy --controller mpc --planner`` takes it (the heaving
    buoy's ``plan`` or ``coupled``; with ``dofs="surge,heave,pitch"`` the hull's ``lbfgsb``,
    the default, or ``collocation``), named in ``causal.planner``.

    ``pendulum``, ``body``, ``pto``, ``controller``, ``device``: the input objects of
    :mod:`parapend.hydro.device` (a ``Device``: ``device="buoy"`` with its body, pendulum and
    take-off), as :func:`parapend.buoy` takes them; their fields are the keywords here."""
    from ..hydro.declared import expand_inputs, has_inputs

    if has_inputs(locals()):
        return power_matrix(**expand_inputs(power_matrix, locals()))
    from ..maps.run import run_spec
    from ..maps.store import check_resumable, stored_points
    from .annual import bin_series, read_scatter, read_series
    from .check import check_bins, check_size

    # everything checked before any bin runs (and, for the buoy, before its BEM): the plain
    # options, the output paths, the bins' sizes, every bin's record, the site's file
    if depth is not None:
        depth = check_depth(depth)
    density = check_range("density", density, 500.0, 2000.0, why="kg/m^3")
    if not isinstance(device, str) or device not in DEVICES:
        raise ParameterError(f"device: expected one of {', '.join(DEVICES)}, got "
                             f"{device!r:.60}")
    if width is not None:
        width = check_positive("width", width)
    if rated_power is not None:
        rated_power = check_positive("rated-power", rated_power)
    if scatter is not None and timeseries is not None:
        raise ParameterError("scatter, timeseries: give the site as one of them")
    if rated_power is not None and scatter is None and timeseries is None:
        raise ParameterError("rated-power: the capacity factor needs a site: give --scatter "
                             "or --timeseries")
    from .. import fileio
    from ..deadline import check_time_limit, deadline, duration, refuse_untimed

    time_limit = check_time_limit(time_limit)
    until = deadline(time_limit)
    for path, flag, sfx in ((netcdf, "netcdf", ".nc"), (csv, "csv", ".csv")):
        if path is not None:
            fileio.check_target(path, flag, (sfx,))
    if zarr is not None:
        _check_zarr(zarr)
    if workers is not None:
        workers = check_int("workers", workers, 1, 256)
    # the site's file: its kind and size now (a FIFO or a device refused unread), before a
    # buoy's BEM; its rows once the bins are known
    from .annual import _read_rows

    for path, name in ((scatter, "scatter"), (timeseries, "timeseries")):
        if path is not None:
            _read_rows(path, name, "of sea states")
    spec = matrix_spec(hs=hs, te=te, tp=tp, realizations=realizations, waves=waves, seed=seed,
                       spectrum=spectrum, gamma_peak=gamma_peak, cutoff=cutoff,
                       response=response, device=device, horizon=horizon, length=length,
                       mass=mass, inertia=inertia, gravity=gravity, gamma=gamma,
                       damping_coefficient=damping_coefficient, winding=winding,
                       harmonics=harmonics, efficiency=efficiency, torque_limit=torque_limit,
                       body=body, radius=radius, draft=draft, mesh=mesh, hydro=hydro,
                       density=density, depth=depth, dofs=dofs, pivot_height=pivot_height,
                       pivot_offset=pivot_offset, hull_pitch_inertia=hull_pitch_inertia,
                       barge_length=barge_length, barge_beam=barge_beam,
                       barge_draft=barge_draft, copper_loss=copper_loss,
                       controller=controller, forecast=forecast,
                       update_interval=update_interval, warm_up=warm_up,
                       plan_samples=plan_samples, speed_limit=speed_limit,
                       planner=planner)
    _check_breaking(spec.hm0, depth)
    if spec.device == "buoy":
        from .buoy_device import water_of

        # the flux of the water the body was solved in (the matrix's --density and
        # --depth, or a --hydro dataset's own rho and depth), never another: the capture
        # widths would be off by the ratio. Options that contradict the dataset: refused
        body = None
        if spec.dofs != "heave":
            from .hull_device import hull_of

            body = hull_of(spec)
        rho, h = water_of(spec, body)
        if spec.hydro is not None:
            if density != 1025.0 and not math.isclose(density, rho, rel_tol=1e-9):
                raise ParameterError(f"density: the dataset {spec.hydro} was solved at rho = "
                                     f"{rho:g} kg/m^3, got {density:g}; drop --density (the "
                                     "dataset's own is used) or solve the body in that water")
            if depth is not None and not (h is not None
                                          and math.isclose(depth, h, rel_tol=1e-9)):
                raise ParameterError(f"depth: the dataset {spec.hydro} was solved in "
                                     + ("deep water" if h is None else f"{h:g} m of water")
                                     + f", got {depth:g} m; drop --depth (the dataset's own "
                                     "is used) or solve the body at that depth")
            _check_breaking(spec.hm0, h)
        density, depth = rho, h
        if width is None:
            width = spec.width  # the body's diameter (None for a mesh or a dataset)
    est = check_size(spec, workers, scheduler)
    if scheduler is None:
        workers = est["processes"]
    check_bins(spec)
    if est["seconds"] is not None and store is None:
        # resumable work (--store) is announced and runs; in memory it must fit the cap
        each = est["seconds"] / est["solves"]  # one solve's share of the wall time
        most = int(limits.MAX_UNTIMED_SECONDS / each)
        name, advice = untimed_advice(most, est["bins"], spec.realizations, spec.period_kind)
        refuse_untimed(name,
                       f"a power matrix of {est['bins']} bins x {spec.realizations} "
                       f"realizations ({est['solves']} solves on "
                       f"{est['processes']} process(es))", est["seconds"],
                       advice + " or --store (resumable work: a rerun resumes)", time_limit)
    frequency, outside = None, None
    pk = spec.period_kind
    if scatter is not None:
        frequency = read_scatter(scatter, spec.hm0, spec.period, pk)
    elif timeseries is not None:
        hs_t, per_t = read_series(timeseries, pk)
        counts, out = bin_series(hs_t, per_t, bin_edges(spec.hm0), bin_edges(spec.period))
        frequency = counts / hs_t.size
        outside = {"sea_states": out, "frequency": out / hs_t.size} if out else None
    check_resumable(spec, store, overwrite)  # a store the run would refuse
    # announced once nothing is left to refuse
    # a resume runs what the store does not hold
    stored = (stored_points(spec, store, overwrite) if est["seconds"] is not None
              and est["seconds"] > _ANNOUNCE_SECONDS else 0)
    left = (est["seconds"] * (spec.points - stored) / spec.points
            if est["seconds"] is not None else None)
    if left is not None and left > _ANNOUNCE_SECONDS:
        procs = est["processes"]
        log.info("power matrix: %d bins x %d realization%s = %d solves of %s-wave records%s "
                 "on %s: roughly %s (about %s; the progress bar gives the rate)",
                 est["bins"], spec.realizations, "" if spec.realizations == 1 else "s",
                 est["solves"], _record_lengths(spec),
                 f" ({stored} of them in the store)" if stored else "",
                 (f"{procs} process{'' if procs == 1 else 'es'}" if procs
                  else "the cluster"),
                 duration(left) + ("" if est["processes"] else " of one core"),
                 ("3 s a 50-wave solve" if spec.controller is None else
                  f"3 s a 50-wave solve and {est['causal_seconds']:.0f} s its causal runs")
                 if spec.dofs == "heave" else
                 f"{est['seconds'] * max(1, est['processes']) / est['solves']:.0f} s of CPU "
                 "a hull record")
    t0 = time.monotonic()
    run = run_spec(spec, store, workers=workers, scheduler=scheduler, overwrite=overwrite,
                   command=command, progress=progress, deadline=until)
    ds, annual = matrix_dataset(run.dataset, spec, depth=depth, density=density, width=width,
                                frequency=frequency, outside=outside, rated_power=rated_power)
    if run.stopped:
        # a partial matrix says so, in the Dataset and every file written from it
        done = np.asarray(run.dataset["done"].values, dtype=bool)
        finished = int(done.reshape(len(spec.hm0), len(spec.period), -1).all(axis=-1).sum())
        ds.attrs.update(status="time_limit", bins=int(len(spec.hm0) * len(spec.period)),
                        bins_finished=finished, time_limit_s=float(time_limit),
                        partial=("time limit reached: the bins not finished are NaN (count "
                                 "0)" + ("; run the same command again to compute them"
                                         if store is not None else "")))
    seconds = time.monotonic() - t0
    if netcdf is not None:
        fileio.write_dataset(ds, netcdf)
    if zarr is not None:
        _write_zarr(ds, zarr)
    if csv is not None:
        fileio.write_text(csv, matrix_csv(ds, spec))
    return ds, annual, run, seconds


#: the root attribute ``export`` of a Dataset written by ``--zarr``
_EXPORT = "parapend power matrix dataset"


def _check_zarr(path):
    """The ``--zarr`` destination, checked before the work: a directory that can be created
    beside, and only an earlier export of a power matrix replaced (never a ``--store``,
    whose raw results it would destroy, nor any other directory or file)."""
    import json
    from pathlib import Path

    from .. import fileio

    path = fileio.check_target(path, "zarr", directory=True)
    if path.exists() or path.is_symlink():
        try:
            attrs = json.loads((path / "zarr.json").read_text())["attributes"]
            ours = attrs.get("export") == _EXPORT
        except (OSError, ValueError, KeyError, TypeError):
            ours = False
        if not ours or path.is_symlink():
            raise ParameterError(f"zarr: {str(path)!r} exists and is not an export of a power "
                                 "matrix (parapend replaces only those); choose another name")
    return Path(path)


def _write_zarr(ds, path) -> None:
    """The full Dataset as a Zarr 3 store written beside, then moved in (atomic rename)."""
    import os
    import shutil
    import tempfile
    from pathlib import Path

    from ..errors import OutputError

    path = _check_zarr(path)
    tmp = Path(tempfile.mkdtemp(prefix=".parapend-", dir=path.parent if str(path.parent)
                                else "."))
    try:
        out = ds.copy()
        out.attrs["export"] = _EXPORT
        for v in out.variables.values():
            v.encoding = {}
        out.to_zarr(tmp / "s", mode="w", zarr_format=3, consolidated=False)
        if path.exists():
            shutil.rmtree(path)
        os.replace(tmp / "s", path)
    except OSError as exc:
        raise OutputError(f"cannot write {str(path)!r}: {exc.strerror or exc}") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def matrix_csv(ds, spec: MatrixSpec | None = None) -> str:
    """The matrix as a table, one row per bin: centres, J, the statistics of each quantity,
    the capture width (and ratio), the frequency. Without ``spec`` the bins and quantities
    are the Dataset's own (``PowerMatrixResult.save("m.csv")``: the same table)."""
    if spec is None:
        pk = "tp" if "tp" in ds.dims else "te"
        hm0 = [float(v) for v in ds["hm0"].values]
        period = [float(v) for v in ds[pk].values]
        quantities = [str(v)[:-5] for v in ds.data_vars if str(v).endswith("_mean")]
    else:
        pk, hm0, period = spec.period_kind, spec.hm0, spec.period
        quantities = matrix_quantities(spec)
    cols = ["wave_energy_flux_matrix", "capture_width_matrix"]
    if "capture_width_ratio_matrix" in ds:
        cols.append("capture_width_ratio_matrix")
    for q in quantities:
        cols += [f"{q}_{s}" for s in STATISTICS]
    if "frequency" in ds:
        cols.append("frequency")
    lines = [",".join(["hm0", pk, "tp" if pk == "te" else "te", *cols])]
    other = ds["tp" if pk == "te" else "te"].values
    for i, h in enumerate(hm0):
        for k, t in enumerate(period):
            vals = [ds[c].values[i, k] for c in cols]
            lines.append(",".join([repr(h), repr(t), repr(float(other[k])),
                                   *(str(int(v)) if c.endswith("count") else repr(float(v))
                                     for c, v in zip(cols, vals))]))
    return "\n".join(lines) + "\n"


def _finite(x):
    return None if x is None or not math.isfinite(x) else x
