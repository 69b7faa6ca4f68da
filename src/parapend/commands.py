"""One Python function per command of the ``parapend`` program: the public surface.

``parapend.<command>(...)`` (dashes become underscores: ``damping-sweep`` is
:func:`damping_sweep`) takes every option of the command under the option's name (the
``dest`` of ``parapend <command> --help``: ``--from`` and ``--to`` of ``harmonics`` are
``n_from`` and ``n_to``) with the same defaults (:mod:`parapend.defaults`), and returns a
frozen result whose fields are the keys of the command's ``--json`` object:

- a result dataclass (``OptimizeResult``, ``ThresholdResult``, ``SeaResult``,
  ``TrackResult``, ``RobustnessResult``) where the command prints its ``to_dict()``;
- an ``xarray.Dataset`` where the result is a table over one parameter (``damping_sweep``,
  ``harmonics``, ``pto_curve``): the JSON keys are its coordinate, data variables and
  attributes;
- otherwise a :class:`parapend.results.Record` (``figure``, ``reproduce``, ``simulate``,
  ``basins``, ``rotations``, ``sweep``, ``map``, ``power_matrix``, ``optimize`` with
  ``method="all"``): its fields are the JSON keys; the objects behind it (the Dataset, the
  motion, a sweep's run) are its public attributes ``dataset``, ``source``, ``run``.

Each parameter is declared once: in the signature (and the docstring's Parameters) of the
function that answers the command. ``sea``, ``buoy`` and ``horizon`` are that function itself
(:data:`IMPLEMENTED`: :func:`parapend.irregular.sea`, :func:`parapend.hydro.api.buoy`,
:func:`parapend.control.horizon.horizon_curve`); ``sweep`` and ``power_matrix`` take the
signature of theirs as it is and shape its answer into the command's result
(:data:`FORWARDED`: :func:`parapend.maps.sweep`, :func:`parapend.performance.power_matrix`);
the others here convert units, check or shape the result around the modules that answer
them. The command line is a thin shell over
these functions: each command parses its options, whose defaults it reads from the
function's signature (:meth:`parapend.cli._common._Parser.declare_defaults`), calls the
function and formats the result. Options that only choose how the result is presented are
not parameters: they are :data:`PRESENTATION`. Progress bars are the ``progress`` parameter
(a callable ``progress(done, total)``) where a command has one.
"""

from __future__ import annotations

import dataclasses
import math

from . import limits
from .defaults import DELTA, DYNAMICS, GAMMA, OMEGA, SEA, given  # noqa: F401
from .errors import OutputError, ParameterError, check_int, check_positive, check_range
from .results import Record

__all__ = ["PRESENTATION", "basins", "damping_sweep", "figure", "harmonics", "map",
           "optimize", "pto_curve", "reproduce", "rotations", "simulate", "threshold",
           "track"]

#: command-line options that are not parameters of the functions: how to show or where to
#: write a result (``figure`` and ``map`` keep ``plot``: the figure file is their product)
PRESENTATION = {"json": "print the result as JSON (the result's to_dict())",
                "plot": "draw the result to a file (the functions' result holds the data)",
                "save": "write the result's table or curve to a file"}

_PRODUCT = {"figure": {"plot"}, "map": {"plot"}}


def presentation(command: str) -> set:
    """The options of ``command`` that its function does not take."""
    return set(PRESENTATION) - _PRODUCT.get(command, set())


def _excitation(excitation, omega, delta, square_alpha, fourier, file) -> dict:
    return {"excitation": excitation, "omega": omega, "delta": delta,
            "square_alpha": square_alpha, "fourier": fourier, "file": file}


def _physical(kw: dict, *, length=None, mass=None, inertia=None, gravity=None,
              frequency=None, amplitude=None, damping_coefficient=None,
              torque_limit=None, torque_limit_nm=None):
    """Units from the physical options, ``kw`` with omega, delta, gamma replaced by the
    physical ones, and the torque limit (from N m where given); refuses a non-dimensional
    value given beside its physical counterpart."""
    from .units import from_options

    units, params = from_options(length=length, mass=mass, gravity=gravity, inertia=inertia,
                                 frequency=frequency, amplitude=amplitude,
                                 damping_coefficient=damping_coefficient)
    kw = dict(kw)
    if "omega" in params and given(kw.get("omega")):
        raise ParameterError("frequency: give either --frequency or --omega, not both")
    if "delta" in params and kw.get("delta") is not None:
        raise ParameterError("amplitude: give either --amplitude or --delta, not both")
    if "gamma" in params and given(kw.get("gamma")):
        raise ParameterError("damping-coefficient: give either --damping-coefficient or "
                             "--gamma, not both")
    kw.update(params)
    if torque_limit_nm is not None:
        if units is None:
            raise ParameterError("torque-limit-nm: needs --length and --mass")
        if torque_limit is not None:
            raise ParameterError("torque-limit-nm: give either --torque-limit or "
                                 "--torque-limit-nm, not both")
        torque_limit = units.from_newton_metres(
            check_positive("torque-limit-nm", torque_limit_nm))
    return units, kw, torque_limit


def _table(command: str, ds, module: str, function: str):
    """A table result (:class:`~parapend.results.Table`) drawn by
    ``parapend.<module>.<function>``."""
    import importlib

    from .results import Table

    def draw(data):
        return getattr(importlib.import_module(f".{module}", __package__), function)(data)

    return Table(command, ds, draw)


def _units_attrs(ds, units) -> None:
    """The pendulum's scales as Dataset attributes (NetCDF takes no nested dict)."""
    ds.attrs.update(units.describe())


# --- optimize, threshold, damping-sweep, harmonics ----------------------------------------
def optimize(*, excitation=None, omega=OMEGA, delta=None, square_alpha=None, fourier=None,
             file=None, gamma=GAMMA["optimize"], harmonics: int = 24, method: str = "fourier",
             winding: int = 1, torque_limit=None, torque_limit_nm=None, efficiency=None,
             efficiency_generating=None, efficiency_motoring=None, copper_loss: float = 0.0,
             length=None, mass=None, inertia=None, gravity=None, frequency=None,
             amplitude=None, damping_coefficient=None, warm=None, throw: bool = False):
    """The optimal rotation (command ``optimize``).

    Ideal (:func:`parapend.api.optimize`: Fourier Eq. 10 or the BVP of Eq. 22), or through
    a power take-off (:func:`parapend.pto.optimize_pto`) when a torque limit, an efficiency
    or a copper loss is given; through a lossy one (an efficiency or a copper loss)
    ``power`` and ``power_w`` are the electrical power and ``mechanical_power``,
    ``mechanical_power_w`` the mechanical one. With ``length`` and ``mass`` (and optionally
    ``frequency``, ``amplitude``, ``damping_coefficient``, ``gravity``, ``inertia``,
    ``torque_limit_nm``: docs/units.md) the result adds watts, N m and joules.
    ``method="all"`` compares the uniform rotation, Fourier, BVP and limit (a
    :class:`~parapend.results.Record`).
    Beyond the command's options: ``copper_loss`` (a winding loss ``r T^2``, a take-off),
    ``warm`` (a packed start) and ``throw`` (raise SolverError when not converged).

    Returns
    -------
    OptimizeResult or Record
    """
    from .api import optimize as _ideal

    kw = {"gamma": gamma, "harmonics": harmonics,
          **_excitation(excitation, omega, delta, square_alpha, fourier, file)}
    units, kw, torque_limit = _physical(
        kw, length=length, mass=mass, inertia=inertia, gravity=gravity, frequency=frequency,
        amplitude=amplitude, damping_coefficient=damping_coefficient,
        torque_limit=torque_limit, torque_limit_nm=torque_limit_nm)
    pto = any(v is not None for v in (torque_limit, efficiency, efficiency_generating,
                                      efficiency_motoring)) or copper_loss != 0.0
    if winding != 1:
        if method == "all":
            raise ParameterError("winding: K > 1 works with method fourier or bvp (and the "
                                 "power take-off options); drop --winding or use one method")
        kw["winding"] = winding
    if method == "all":
        if pto or units is not None:
            raise ParameterError("method: 'all' compares the ideal methods; the power "
                                 "take-off and unit options need fourier (or bvp for units)")
        from .plotting import plot_optimum

        f = dataclasses.replace(_ideal(method="fourier", **kw), _draw=plot_optimum)
        b = _ideal(method="bvp", **kw) if f.gamma >= limits.MIN_BVP_GAMMA else None
        return Record("optimize", {
            "uniform_power": f.uniform_power, "limit_power": f.limit_power, "gamma": f.gamma,
            "omega": f.omega, "excitation": f.excitation, "fourier": f.to_dict(),
            "bvp": None if b is None else b.to_dict()}, fourier_result=f, bvp_result=b,
            draw=lambda rec: rec.fourier_result.plot(),
            series=lambda rec: rec.fourier_result._series())
    if pto:
        from .pto import electrical_headline, optimize_pto, plot_pto_profile

        r = optimize_pto(units=units, method=method, torque_limit=torque_limit,
                         efficiency=efficiency, efficiency_generating=efficiency_generating,
                         efficiency_motoring=efficiency_motoring, copper_loss=copper_loss,
                         warm=warm, throw=throw, **kw)
        if r.efficiency_generating is not None or copper_loss != 0.0:
            r = electrical_headline(r)  # lossy: power is the electrical power
        return dataclasses.replace(r, _draw=plot_pto_profile)
    from .plotting import plot_optimum

    r = _ideal(method=method, warm=warm, throw=throw, **kw)
    if units is not None:
        from .pto import physical_fields

        r = dataclasses.replace(r, **physical_fields(r, units))
    return dataclasses.replace(r, _draw=plot_optimum)


def threshold(*, excitation=None, omega=OMEGA, delta=None, square_alpha=None, fourier=None,
              file=None, harmonics=None, length=None, mass=None, inertia=None, gravity=None,
              frequency=None, amplitude=None, throw: bool = False):
    """The damping threshold gamma* (command ``threshold``; paper Fig. 6).

    With ``length`` and ``mass`` the result adds both thresholds as damping coefficients in
    N m s/rad (``c = gamma I / t0``; ``m g l sqrt(l/g) gamma`` for a point mass).
    """
    from .api import threshold as _threshold

    kw = _excitation(excitation, omega, delta, square_alpha, fourier, file)
    units, kw, _ = _physical(kw, length=length, mass=mass, inertia=inertia, gravity=gravity,
                             frequency=frequency, amplitude=amplitude)
    r = _threshold(harmonics=harmonics, throw=throw, **kw)
    if units is not None:
        r = dataclasses.replace(
            r, units=units.describe(),
            damping_threshold_coefficient=units.damping_coefficient(r.damping_threshold),
            uniform_threshold_coefficient=units.damping_coefficient(r.uniform_threshold))
    si = {} if units is None else {"length": units.length, "mass": units.mass,
                                   "gravity": units.gravity, "inertia": units.inertia}

    def draw(res):  # the damping sweep around gamma*, as damping-sweep draws it
        return damping_sweep(excitation=res.excitation_function, points=13,
                             harmonics=res.harmonics or None,
                             gamma_max=max(1.25 * res.damping_threshold, 1e-3), **si).plot()

    return dataclasses.replace(r, _draw=draw)


def damping_sweep(*, excitation=None, omega=OMEGA, delta=None, square_alpha=None,
                  fourier=None, file=None, harmonics=None, gamma_max=None, points: int = 41,
                  length=None, mass=None, inertia=None, gravity=None, frequency=None,
                  amplitude=None, progress=None):
    """Optimal and uniform power against damping (command ``damping-sweep``; paper Fig. 6).

    A Dataset over ``gamma``; with ``length`` and ``mass`` it adds ``damping_coefficient``
    (N m s/rad), ``power_w``, ``uniform_power_w``, ``peak_torque_nm`` and the attribute
    ``damping_threshold_coefficient``.
    """
    from .api import damping_sweep as _sweep

    kw = _excitation(excitation, omega, delta, square_alpha, fourier, file)
    units, kw, _ = _physical(kw, length=length, mass=mass, inertia=inertia, gravity=gravity,
                             frequency=frequency, amplitude=amplitude)
    ds = _sweep(harmonics=harmonics, gamma_max=gamma_max, points=points, progress=progress,
                **kw)
    if units is not None:
        ds["damping_coefficient"] = ds["gamma"] * units.damping
        ds["power_w"] = ds["power"] * units.power
        ds["uniform_power_w"] = ds["uniform_power"] * units.power
        ds["peak_torque_nm"] = ds["peak_torque"] * units.torque
        ds.attrs["damping_threshold_coefficient"] = units.damping_coefficient(
            ds.attrs["damping_threshold"])
        _units_attrs(ds, units)
    return _table("damping-sweep", ds, "plotting", "plot_damping_sweep")


def harmonics(*, excitation=None, omega=OMEGA, delta=None, square_alpha=None, fourier=None,
              file=None, gamma=GAMMA["harmonics"], n_from: int = 2, n_to: int = 64,
              length=None, mass=None, inertia=None, gravity=None, frequency=None,
              amplitude=None, damping_coefficient=None, progress=None):
    """Optimal power against the number of harmonics N = n_from..n_to (command
    ``harmonics``): a Dataset over ``harmonics`` (:func:`parapend.harmonic_table`); with
    ``length`` and ``mass`` it adds ``power_w`` and the attributes ``uniform_power_w`` and
    ``limit_power_w``."""
    from .api import harmonic_table

    top = limits.MAX_TABLE_HARMONICS
    if not isinstance(n_to, int) or not 1 <= n_to <= top:
        raise ParameterError(f"--to (n_to): expected an integer in [1, {top}] (the continuation to "
                             f"{top} takes about 10 s, to 512 over 10 minutes), got {n_to}")
    if not isinstance(n_from, int) or not 1 <= n_from <= n_to:
        raise ParameterError(f"--from (n_from): expected an integer in [1, --to = {n_to}], "
                             f"got {n_from}")
    kw = {"gamma": gamma, **_excitation(excitation, omega, delta, square_alpha, fourier, file)}
    units, kw, _ = _physical(kw, length=length, mass=mass, inertia=inertia, gravity=gravity,
                             frequency=frequency, amplitude=amplitude,
                             damping_coefficient=damping_coefficient)
    ds = harmonic_table(range(n_from, n_to + 1), progress=progress, **kw)
    if units is not None:
        ds["power_w"] = ds["power"] * units.power
        ds.attrs["uniform_power_w"] = units.to_watts(ds.attrs["uniform_power"])
        ds.attrs["limit_power_w"] = units.to_watts(ds.attrs["limit_power"])
        _units_attrs(ds, units)
    return _table("harmonics", ds, "plotting", "plot_harmonic_table")


# --- pto-curve -----------------------------------------------------------------------------
def pto_curve(*, vary: str = "torque-limit", excitation=None, omega=OMEGA, delta=None,
              square_alpha=None, fourier=None, file=None, gamma=GAMMA["pto-curve"],
              harmonics: int = 24, points: int = 10, torque_limit=None, torque_limit_nm=None,
              efficiency=None, efficiency_generating=None, efficiency_motoring=None,
              length=None, mass=None, inertia=None, gravity=None, frequency=None,
              amplitude=None, damping_coefficient=None, progress=None):
    """Optimal power against the torque limit or the efficiency (command ``pto-curve``): a
    Dataset over ``value`` (:func:`parapend.pto.pto_curve`); with ``length`` and ``mass``
    it adds ``power_w``, ``electrical_power_w``, ``peak_torque_nm`` and, when the torque
    limit varies, ``torque_limit_nm``. With an efficiency (given, or varied) ``power`` and
    ``power_w`` are the electrical power and ``mechanical_power``, ``mechanical_power_w``
    the mechanical one."""
    from .pto import pto_curve as _curve

    kw = {"gamma": gamma, "harmonics": harmonics,
          **_excitation(excitation, omega, delta, square_alpha, fourier, file)}
    units, kw, torque_limit = _physical(
        kw, length=length, mass=mass, inertia=inertia, gravity=gravity, frequency=frequency,
        amplitude=amplitude, damping_coefficient=damping_coefficient,
        torque_limit=torque_limit, torque_limit_nm=torque_limit_nm)
    if vary == "torque-limit" and torque_limit is not None:
        raise ParameterError("torque-limit: it is the varied quantity with --vary "
                             "torque-limit; drop it")
    check_int("harmonics", harmonics, 1, limits.MAX_PTO_HARMONICS)
    extra = {"efficiency": efficiency, "efficiency_generating": efficiency_generating,
             "efficiency_motoring": efficiency_motoring}
    if vary != "torque-limit":
        extra["torque_limit"] = torque_limit
    ds = _curve(vary, points=points, units=units, progress=progress, **extra, **kw)
    if units is not None:
        if vary == "torque-limit":
            ds["torque_limit_nm"] = ds["value"] * units.torque
        _units_attrs(ds, units)
    if vary == "efficiency" or any(v is not None for v in (
            efficiency, efficiency_generating, efficiency_motoring)):
        from .pto import electrical_curve

        electrical_curve(ds)  # lossy: power is the electrical power
    return _table("pto-curve", ds, "pto", "plot_pto_curve")


# --- figure, reproduce ---------------------------------------------------------------------
def figure(number: str, *, plot=None):
    """Recompute one of the paper's figures and write it to ``plot`` (default
    ``fig<number>.png``; command ``figure``). Fields ``figure``, ``file``, ``numbers``; the
    matplotlib figure is ``_figure``."""
    from . import fileio
    from .report import paper_figure

    number = str(number)
    path = f"fig{number}.png" if plot is None else plot
    fig, numbers = paper_figure(f"fig{number}")
    fileio.save_figure(fig, path)
    return Record("figure", {"figure": number, "file": path, "numbers": numbers},
                  matplotlib_figure=fig, draw=lambda rec: rec.matplotlib_figure)


def reproduce(*, out: str = "parapend-report", progress=None):
    """Recompute every table and figure of the paper and write the report to ``out``
    (command ``reproduce``); the fields are those of ``results.json``."""
    from pathlib import Path

    from .report import contact_sheet
    from .report import reproduce as _reproduce

    return Record("reproduce", _reproduce(Path(out), progress=progress),
                  directory=Path(out), draw=lambda rec: contact_sheet(rec.directory))


# --- simulate, basins, rotations (paper Eq. 1) ---------------------------------------------
def _check_model(gamma, p, omega=None):
    check_range("gamma", gamma, 0.0, limits.DYN_MAX_GAMMA)
    check_range("p", p, 0.0, limits.DYN_MAX_P, absolute=True)
    if omega is not None:
        check_range("omega", omega, *limits.DYN_OMEGA_RANGE)


def simulate(*, gamma=GAMMA["simulate"], p=DYNAMICS["p"], omega=DYNAMICS["omega"],
             phi0: float = 0.5, dphi0: float = 0.0, periods: int = 200,
             points_per_period: int = 64, length=None, mass=None, inertia=None,
             gravity=None):
    """One motion of the uncontrolled pendulum, paper Eq. 1 (command ``simulate``).

    Fields are the JSON keys (``final``, ``turns``, ...); the time series (``t``, ``phi``,
    ``dphi``, ``energy``) and the rest of :class:`parapend.dynamics.motion.Motion` read
    through from ``_source``. With ``length`` and ``mass`` (the time unit is
    ``t0 = sqrt(I / (m g l))``, ``sqrt(l / g)`` for a point mass) it adds ``units``,
    ``forcing_period_s``, ``forcing_frequency_hz``, ``duration_s`` and ``final_energy_j``
    (the energy ``phi'^2/2 + 1 - cos(phi)`` is in units of m g l).
    """
    from .dynamics.motion import simulate as _simulate

    _check_model(gamma, p, omega)
    check_range("phi0", phi0, 0.0, limits.SIM_MAX_PHI0, absolute=True)
    check_range("dphi0", dphi0, 0.0, limits.SIM_MAX_DPHI0, absolute=True)
    periods = check_int("periods", periods, 1, limits.SIM_MAX_PERIODS)
    work = periods * 2 * math.pi / omega * (math.sqrt(1 + abs(p)) + abs(dphi0))
    if work > limits.SIM_MAX_WORK:
        raise ParameterError(f"periods: expected periods x 2 pi/omega x (sqrt(1 + |p|) + "
                             f"|dphi0|) <= {limits.SIM_MAX_WORK:g}, got {work:.4g}")
    check_int("points-per-period", points_per_period, 2, 1024)
    units, _, _ = _physical({}, length=length, mass=mass, inertia=inertia, gravity=gravity)
    m = _simulate(gamma, p, omega, phi0, dphi0, periods, points_per_period=points_per_period)
    out = m.to_dict()
    if units is not None:
        period = 2 * math.pi / omega
        out.update(units=units.describe(), forcing_period_s=units.to_seconds(period),
                   forcing_frequency_hz=1.0 / units.to_seconds(period),
                   duration_s=units.to_seconds(float(m.t[-1] - m.t[0])),
                   final_energy_j=units.to_joules(float(m.energy[-1])))
    return Record("simulate", out, source=m, physical_units=units, draw=_draw_simulate,
                  series=_simulate_series)


def _draw_simulate(rec):
    from .dynamics.figures import plot_motion
    from .units import si_figure

    return si_figure(plot_motion(rec.source), rec.physical_units)


def _simulate_series(rec):
    """The motion of Eq. 1 over time (SI time and energy with a pendulum's units)."""
    from .results import series

    m, u = rec.source, rec.physical_units
    ds = series({"time": m.t, "phi": m.phi, "phi_dot": m.dphi}, u)
    if u is None:
        ds["energy"] = (ds["phi"].dims, m.energy)
    else:
        ds["energy_j"] = (ds["phi"].dims, m.energy * u.energy)
    ds["phi"].attrs.update(units="rad", long_name="angle from the hanging position (Eq. 1)")
    return ds


def basins_json(ds) -> dict:
    """The JSON object of ``parapend basins`` from a basin Dataset."""
    import json

    import numpy as np

    frac = ds["basin_fraction"].values
    err = (ds["basin_fraction_error"].values if "basin_fraction_error" in ds
           else np.full(frac.shape, np.nan))
    atts = []
    for c in range(ds.sizes["code"]):
        if c == 0 and frac[0] == 0:
            continue
        pp = ds["poincare_phi"].values[c]
        pd = ds["poincare_dphi"].values[c]
        ok = np.isfinite(pp)
        atts.append({"code": c, "name": str(ds["name"].values[c]),
                     "kind": str(ds["kind"].values[c]),
                     "period": int(ds["period"].values[c]),
                     "winding": int(ds["winding"].values[c]),
                     "direction": str(ds["direction"].values[c]),
                     "basin_fraction": float(frac[c]),
                     "basin_fraction_error": float(err[c]),
                     "poincare_phi": [float(x) for x in pp[ok]],
                     "poincare_dphi": [float(x) for x in pd[ok]]})
    keys = ("gamma", "p", "omega", "t0", "periods", "steps_per_period", "tol",
            "capture_radius", "engine", "workers", "elapsed_s", "convention")
    out = {k: ds.attrs[k] for k in keys if k in ds.attrs}
    out.update(resolution=[int(ds.sizes["phi"]), int(ds.sizes["dphi"])],
               phi_range=[float(ds["phi"].values[0]), float(ds["phi"].values[-1])],
               dphi_range=[float(ds["dphi"].values[0]), float(ds["dphi"].values[-1])],
               attractors=atts, stats=json.loads(ds.attrs.get("stats", "{}")),
               accuracy=json.loads(ds.attrs.get("accuracy", "{}")),
               mirror_symmetric=bool(ds.attrs.get("mirror_symmetric", 0)))
    return out


def basins(*, gamma=GAMMA["basins"], p=DYNAMICS["p"], omega=DYNAMICS["omega"],
           resolution: int = 200, phi_range=None, dphi_range=(-3.0, 3.0), periods: int = 300,
           steps_per_period: int = 128, accuracy_sample: int = 1000, accuracy_seed: int = 0,
           split_phases: bool = False, engine: str = "numba", progress=None):
    """Basins of attraction of paper Eq. 1 (command ``basins``; Fig. 2 right); the basin
    Dataset is ``_dataset``."""
    from .dynamics.basins import basin_map

    _check_model(gamma, p, omega)
    n = check_int("resolution", resolution, 2, limits.BASIN_MAX_RESOLUTION)
    periods = check_int("periods", periods, 1, limits.BASIN_MAX_PERIODS)
    steps = check_int("steps-per-period", steps_per_period, *limits.BASIN_STEPS_RANGE)
    sample = check_int("accuracy-sample", accuracy_sample, *limits.BASIN_ACCURACY_RANGE)
    seed = check_int("accuracy-seed", accuracy_seed, 0, 2**63 - 1)
    dphi_range = tuple(dphi_range)
    # the default grid (whole circle, dphi range symmetric about 0) integrates half its
    # columns (symmetry of Eq. 1); the bound is on the trajectories actually integrated,
    # the accuracy check's included (twice at double steps and once: 3 units per point)
    sym = phi_range is None and dphi_range[0] == -dphi_range[1]
    points = n * (n // 2 + 1) if sym else n * n
    work = (points + 3 * min(sample, points)) * periods * steps / 128
    if work > limits.BASIN_MAX_WORK:
        raise ParameterError(f"periods: expected integrated points x periods x steps/128 <= "
                             f"{limits.BASIN_MAX_WORK:g} (1000 x 1000 at 300 periods), got "
                             f"{work:.3g} ({n} x {n}{', half by symmetry' if sym else ''}, "
                             f"{periods} periods, {steps} steps, accuracy sample included)")
    for name, rng, cap in (("phi-range", phi_range, 1e3), ("dphi-range", dphi_range, 1e3)):
        if rng is not None:
            if rng[1] <= rng[0]:
                raise ParameterError(f"{name}: expected LOW < HIGH, got {rng[0]:g}:{rng[1]:g}")
            if max(abs(rng[0]), abs(rng[1])) > cap:
                raise ParameterError(f"{name}: expected values within +-{cap:g}, got "
                                     f"{rng[0]:g}:{rng[1]:g}")
    ds = basin_map(gamma, p, omega, n_phi=n, n_dphi=n, dphi_range=dphi_range,
                   phi_range=phi_range, periods=periods, steps_per_period=steps,
                   split_phases=split_phases, engine=engine, progress=progress,
                   accuracy_sample=sample, accuracy_seed=seed)
    from .results import grid_csv

    return Record("basins", basins_json(ds), dataset=ds,
                  draw=_draw_dataset("dynamics.figures", "plot_basins"),
                  table=lambda r: grid_csv(r.dataset, ["attractor", "phase", "periods_used"]))


def _draw_dataset(module: str, function: str, **kw):
    """``draw(record)``: ``parapend.<module>.<function>(record.dataset, **kw)``."""
    import importlib

    def draw(rec):
        return getattr(importlib.import_module(f".{module}", __package__), function)(
            rec.dataset, **kw)

    return draw


def _omegas(omega):
    import numpy as np

    lo, hi = limits.ROT_OMEGA_RANGE
    if isinstance(omega, (tuple, list)):
        w0, w1, n = omega
        if n != int(n):
            raise ParameterError(f"omega: expected an integer N in FROM:TO:N, got {n:g}")
        n = check_int("omega", int(n), 1, limits.ROT_MAX_OMEGAS)
        check_range("omega", w0, lo, hi)
        check_range("omega", w1, lo, hi)
        if n > 1 and w1 <= w0:
            raise ParameterError(f"omega: expected FROM < TO, got {w0:g}:{w1:g}")
        return np.linspace(w0, w1, n)
    return np.array([check_range("omega", omega, lo, hi)])


def rotations(*, gamma=GAMMA["rotations"], omega=DYNAMICS["omega"], p_max: float = 3.0,
              time_limit: float = limits.ROT_TIME_LIMIT, progress=None):
    """Curves J, G, E of the period-1 rotation of paper Eq. 1 (command ``rotations``; Fig. 2
    left): at one ``omega``, or over ``omega = (FROM, TO, N)``. The Dataset over omega is
    ``_dataset``; at one omega the :class:`~parapend.dynamics.continuation.RotationBoundaries`
    is ``_source``."""
    import numpy as np
    import xarray as xr

    from .dynamics.continuation import rotation_boundaries, rotation_boundaries_at

    check_range("gamma", gamma, 0.0, limits.DYN_MAX_GAMMA)
    if not 0 < p_max <= limits.ROT_MAX_P:
        raise ParameterError(f"p-max: expected a number in (0, {limits.ROT_MAX_P:g}], got "
                             f"{p_max:g}")
    if not 0 < time_limit <= limits.ROT_MAX_TIME_LIMIT:
        raise ParameterError(f"time-limit: expected seconds in (0, "
                             f"{limits.ROT_MAX_TIME_LIMIT:g}], got {time_limit:g}")
    oms = _omegas(omega)
    if not isinstance(omega, (tuple, list)):
        r = rotation_boundaries_at(gamma, float(oms[0]), p_max=p_max, time_limit=time_limit)
        ds = xr.Dataset({k: ("omega", np.array([v])) for k, v in
                         (("p_J", r.lowest_J), ("p_G", r.lowest_G), ("p_E", r.lowest_E),
                          ("p_start", r.p_start), ("p_reached", r.p_reached))},
                        coords={"omega": oms},
                        attrs={"gamma": gamma, "p_max": float(p_max),
                               "convention": "paper Eq. 1 (p, omega)", "status": r.status})
        return Record("rotations", r.to_dict(), source=r, dataset=ds,
                      draw=_draw_dataset("dynamics.figures", "plot_rotation_boundaries"))
    ds = rotation_boundaries(gamma, oms, p_max=p_max, progress=progress,
                             time_limit=time_limit)
    return Record("rotations", draw=_draw_dataset("dynamics.figures",
                                                  "plot_rotation_boundaries"), data={
        "gamma": gamma, "p_max": p_max, "omega": [float(x) for x in ds["omega"].values],
        **{k: [None if math.isnan(x) else float(x) for x in ds[k].values]
           for k in ("p_J", "p_G", "p_E", "p_start", "p_reached")},
        "convention": ds.attrs["convention"], "status": ds.attrs["status"],
        "success": ds.attrs["status"] == "ok"}, dataset=ds)


# --- track ---------------------------------------------------------------------------------
from .defaults import TRACK  # noqa: E402


def track(*, excitation=None, omega=OMEGA, delta=None, square_alpha=None, fourier=None,
          file=None, gamma=GAMMA["track"], harmonics: int = 24, torque_limit=None,
          torque_margin: float = 0.1, r_weight: float = 0.1, lock_tolerance: float = 0.1,
          theta0: float = math.pi, theta_dot0: float = 0.0, periods: int = 100, seed: int = 0,
          runs: int = 1, gamma_error: float = 0.0, delta_error: float = 0.0,
          noise_theta: float = 0.0, noise_speed: float = 0.0, irregular: bool = False,
          length=None, mass=None, inertia=None, gravity=None, frequency=None,
          amplitude=None, damping_coefficient=None, torque_limit_nm=None, progress=None,
          controller: str = TRACK["controller"], horizon: float = TRACK["horizon"],
          update_interval: float = TRACK["update_interval"],
          forecast: str = TRACK["forecast"], speed_limit=TRACK["speed_limit"],
          time_limit=None):
    """Swing up from rest, catch and hold the optimal rotation (command ``track``): a
    :class:`~parapend.control.track.TrackResult` (``runs`` 1) or a
    :class:`~parapend.control.robustness.RobustnessResult` (more seeded runs). With
    ``length`` and ``mass`` the result adds ``mean_power_w``, ``predicted_power_w``,
    ``peak_torque_nm``, ``torque_limit_nm`` and the forcing period ``period_s``.

    ``controller="mpc"``: receding-horizon control instead
    (:func:`parapend.control.mpc.track_mpc`, an
    :class:`~parapend.control.mpc.MPCTrackResult`), with ``horizon`` and
    ``update_interval`` in forcing (peak) periods and the wave ``forecast`` ("perfect" or
    "ar") and the plans' rated ``speed_limit`` (none by default); one run, no model error
    or noise; ``time_limit`` (s) runs it under a time limit (:mod:`parapend.deadline`: a
    run estimated over two minutes is refused without one)."""
    from .control.robustness import track_runs
    from .control.track import track as _track

    if controller not in ("lqr", "mpc"):
        raise ParameterError(f"controller: expected lqr or mpc, got {controller!r:.40}")
    if controller == "mpc":
        return _track_mpc(
            excitation=excitation, omega=omega, delta=delta, square_alpha=square_alpha,
            fourier=fourier, file=file, gamma=gamma, torque_limit=torque_limit,
            theta0=theta0, theta_dot0=theta_dot0, periods=periods, seed=seed, runs=runs,
            errors={"gamma-error": gamma_error, "delta-error": delta_error,
                    "noise-theta": noise_theta, "noise-speed": noise_speed},
            irregular=irregular, units_kw=dict(
                length=length, mass=mass, inertia=inertia, gravity=gravity,
                frequency=frequency, amplitude=amplitude,
                damping_coefficient=damping_coefficient, torque_limit_nm=torque_limit_nm),
            horizon=horizon, update_interval=update_interval, forecast=forecast,
            speed_limit=speed_limit, progress=progress, time_limit=time_limit)
    if time_limit is not None:
        raise ParameterError("time-limit: bounds long work only: needs --controller mpc")
    if (horizon, update_interval, forecast) != (2.0, 0.03125, "perfect"):
        raise ParameterError("horizon: --horizon, --update-interval and --forecast belong to "
                             "--controller mpc")
    if speed_limit is not None:
        raise ParameterError("speed-limit: --speed-limit belongs to --controller mpc")

    kw = {"gamma": gamma, "harmonics": harmonics,
          **_excitation(excitation, omega, delta, square_alpha, fourier, file)}
    units, kw, torque_limit = _physical(
        kw, length=length, mass=mass, inertia=inertia, gravity=gravity, frequency=frequency,
        amplitude=amplitude, damping_coefficient=damping_coefficient,
        torque_limit=torque_limit, torque_limit_nm=torque_limit_nm)
    common = dict(torque_limit=torque_limit, torque_margin=torque_margin, periods=periods,
                  seed=seed, gamma_error=gamma_error, delta_error=delta_error,
                  noise_theta=noise_theta, noise_speed=noise_speed, irregular=irregular,
                  lock_tolerance=lock_tolerance, r_weight=r_weight, **kw)
    if runs != 1:
        if theta0 != math.pi or theta_dot0 != 0.0:
            raise ParameterError("runs: a batch starts from the hanging rest; drop --theta0 "
                                 "and --theta-dot0 or use --runs 1")
        r = track_runs(runs=runs, progress=progress, **common)
    else:
        r = _track(theta0=theta0, theta_dot0=theta_dot0, **common)
    if units is None:
        return r
    return dataclasses.replace(
        r, units=units.describe(), mean_power_w=units.to_watts(r.mean_power),
        predicted_power_w=units.to_watts(r.predicted_power),
        peak_torque_nm=units.to_newton_metres(r.peak_torque),
        torque_limit_nm=None if r.torque_limit is None else
        units.to_newton_metres(r.torque_limit),
        period_s=units.to_seconds(2 * math.pi / r.omega))


def _track_mpc(*, excitation, omega, delta, square_alpha, fourier, file, gamma, torque_limit,
               theta0, theta_dot0, periods, seed, runs, errors, irregular, units_kw, horizon,
               update_interval, forecast, speed_limit=None, progress=None, time_limit=None):
    """``track --controller mpc`` (:func:`parapend.control.mpc.track_mpc`)."""
    from .api import build_excitation
    from .control.mpc import track_mpc

    if check_int("runs", runs, 1) != 1:
        raise ParameterError("runs: --controller mpc runs one record; use parapend horizon "
                             "for seeded batches")
    given = [k for k, v in errors.items() if v != 0.0]
    if given:
        raise ParameterError(f"{given[0]}: not offered with --controller mpc (the plant is "
                             "the model); drop it or use --controller lqr")
    kw = {"gamma": gamma, "harmonics": 24,
          **_excitation(excitation, omega, delta, square_alpha, fourier, file)}
    units, kw, torque_limit = _physical(kw, torque_limit=torque_limit, **units_kw)
    kw.pop("harmonics", None)
    gamma = check_range("gamma", kw.pop("gamma"), 0.0, limits.MAX_GAMMA)
    if torque_limit is not None:
        torque_limit = check_range("torque-limit", torque_limit, 0.0, limits.MAX_TORQUE_LIMIT)
        if not torque_limit > 0:
            raise ParameterError(f"torque-limit: expected a number > 0, got {torque_limit!r}")
    periods = check_int("periods", periods, 20, limits.MAX_TRACK_PERIODS)
    seed = check_int("seed", seed, 0, 2**63 - 1)
    exc = build_excitation(kw.pop("excitation", None), **kw)
    r = track_mpc(exc, gamma=gamma, horizon=horizon, update_interval=update_interval,
                  forecast=forecast, torque_limit=torque_limit, periods=periods, seed=seed,
                  irregular=irregular, theta0=theta0, theta_dot0=theta_dot0,
                  speed_limit=speed_limit, progress=progress, time_limit=time_limit)
    if units is None:
        return r
    tp = 2 * math.pi / r.omega
    return dataclasses.replace(
        r, units=units.describe(), mean_power_w=units.to_watts(r.mean_power),
        record_power_w=None if r.record_power is None else units.to_watts(r.record_power),
        peak_torque_nm=units.to_newton_metres(r.peak_torque),
        torque_limit_nm=None if r.torque_limit is None else
        units.to_newton_metres(r.torque_limit),
        period_s=units.to_seconds(tp), update_interval_s=units.to_seconds(tp)
        * r.update_interval)


# --- sweep, map ----------------------------------------------------------------------------
def _sweep_result(sweep, arguments):
    """A resumable design map (command ``sweep``): :func:`parapend.maps.sweep` (its
    parameters, declared there: axes as one value, ``"START:STOP:COUNT"`` or a comma list,
    or numbers), as a :class:`~parapend.results.Record` whose fields are the JSON keys;
    ``run`` is the :class:`~parapend.maps.SweepRun`, ``dataset`` its Dataset. ``store``
    None (the default here; the command line's is ``map.zarr``) computes in memory and
    writes nothing; ``netcdf`` also exports the finished map. The store is non-dimensional
    (one store serves every pendulum); with ``length`` and ``mass`` the largest power is
    also given in W (``largest_power_w``) and ``parapend.map`` draws it in SI with the same
    options. With an efficiency ``power`` is the electrical power (the headline, as
    ``optimize``): ``largest_power`` is the point of the largest electrical power, with that
    point's ``mechanical_power``.

    Returns
    -------
    Record
    """
    import importlib

    import numpy as np

    sw = importlib.import_module(".maps", __package__)
    run = sweep(*arguments.args, **arguments.kwargs)
    ds, units = run.dataset, run.units
    codes = ds["status"].values[ds["done"].values]
    counts = {s: int(np.sum(codes == i)) for i, s in enumerate(sw.STATUSES)
              if np.any(codes == i)}
    p = ds["power"].values
    ok = ds["done"].values & np.isin(ds["status"].values, [0, 1])
    best = None
    if ok.any():
        k = np.unravel_index(np.nanargmax(np.where(ok, p, -np.inf)), p.shape)
        best = {"power": float(p[k])}
        if "mechanical_power" in ds:
            best["mechanical_power"] = float(ds["mechanical_power"].values[k])
        best.update({d: float(ds[d].values[i]) for d, i in zip(ds["power"].dims, k)})
    out = {
        "store": run.store, "dims": {d: int(ds.sizes[d]) for d in ds["power"].dims},
        "points": run.points, "blocks": run.blocks, "computed_points": run.computed_points,
        "resumed_points": run.resumed_points, "repaired_points": run.repaired_points,
        "seconds": run.seconds, "executor": run.executor, "status_counts": counts,
        "largest_power": best,
        "largest_branch_gap": (float(np.nanmax(ds["branch_gap"].values))
                               if "branch_gap" in ds and ok.any() else None),
        "netcdf": run.netcdf}
    if units is not None:
        out.update(units=units.describe(), largest_power_w=(
            None if best is None else units.to_watts(best["power"])))
        if best is not None and "mechanical_power" in best:
            out["largest_power_mechanical_w"] = units.to_watts(best["mechanical_power"])
    return Record("sweep", out, run=run, dataset=ds,
                  draw=lambda rec: sw.plot_sweep(rec.dataset, units=rec.run.units))


#: a design map's quantities in SI: the Units attribute that scales each (None: a ratio)
MAP_SI = {"power": ("power", "W"), "uniform_power": ("power", "W"),
          "limit_power": ("power", "W"), "electrical_power": ("power", "W"),
          "mechanical_power": ("power", "W"), "branch_gap": ("power", "W"),
          "damping_threshold": ("damping", "N m s/rad"),
          "gain": None}


def map(*, store: str = "map.zarr", variable: str = "power", x=None, y=None, at=(),  # noqa: A001
        plot: str = "map.png", length=None, mass=None, inertia=None, gravity=None):
    """Heat map of a sweep store over two of its axes, written to ``plot`` (command
    ``map``). ``at``: ``{"axis": value}`` or ``["axis=value", ...]`` for further axes.

    With ``length`` and ``mass`` (m, kg; ``inertia``, ``gravity`` optional) the map is of that
    pendulum: the store is non-dimensional (one store serves every size), and the figure gains
    SI scales (the colour bar in W or N m s/rad, omega in Hz, gamma in N m s/rad, the torque
    limit in N m) and the result ``min_si``, ``max_si`` and ``unit_si``."""
    import importlib

    import numpy as np

    from . import fileio

    sw = importlib.import_module(".maps", __package__)
    fixed = {}
    pairs = ([(str(k), v, f"{k}={v}") for k, v in at.items()] if isinstance(at, dict) else
             [(s.partition("=")[0], s.partition("=")[2] if "=" in s else None, s) for s in at])
    for name, value, text in pairs:
        name = name.strip().replace("-", "_")
        if value is None or name not in sw.AXES:
            raise ParameterError(f"at: expected AXIS=VALUE with AXIS one of "
                                 f"{', '.join(sw.AXES)}, got {text!r:.40}")
        try:
            fixed[name] = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"at: expected a number after '=', got {text!r:.40}") \
                from None
    units, _, _ = _physical({}, length=length, mass=mass, inertia=inertia, gravity=gravity)
    ds = sw.open_sweep(store)
    xn = x.replace("-", "_") if x else None
    yn = y.replace("-", "_") if y else None
    z, failed, xs, ys, xn, yn, label, title = sw.map_data(ds, variable, xn, yn, fixed)
    try:
        if units is None:
            sw.plot_map(ds, variable, xn, yn, fixed, plot)
        else:
            from .style import figure_style
            from .units import add_si_axes

            si = MAP_SI.get(variable)
            fig = sw.plot_map(ds, variable, xn, yn, fixed, None, scale=None if si is None else
                              (float(getattr(units, si[0])), si[1]))
            with figure_style():
                add_si_axes(fig, units)
            fileio.save_figure(fig, plot)
    except OutputError:
        raise
    except OSError as exc:
        raise fileio.output_error(plot, exc) from None
    finite = np.isfinite(z)
    out = {"plot": plot, "variable": variable, "x": xn, "y": yn, "fixed": title,
           "points": int(z.size), "failed": int(failed.sum()),
           "not_computed": int(z.size - finite.sum() - failed.sum()),
           "min": float(np.nanmin(z)) if finite.any() else None,
           "max": float(np.nanmax(z)) if finite.any() else None}
    if finite.any():
        i, j = np.unravel_index(np.nanargmax(z), z.shape)
        out["max_at"] = {xn: float(xs[j]), yn: float(ys[i])}
    if units is not None:
        si = MAP_SI.get(variable)
        k = None if si is None else float(getattr(units, si[0]))
        out.update(units=units.describe(), unit_si=None if si is None else si[1],
                   min_si=None if k is None or out["min"] is None else out["min"] * k,
                   max_si=None if k is None or out["max"] is None else out["max"] * k)
    return Record("map", out, dataset=ds, label=label,
                  draw=lambda rec: sw.plot_map(rec.dataset, variable, xn, yn, fixed))


# --- power-matrix ----------------------------------------------------------------------------
def _matrix_waves(ds) -> list:
    """The record length (peak periods) of each period bin a power matrix's Dataset was
    computed with (its ``sweep`` attribute: the device's default resolved)."""
    spec = _matrix_spec(ds)
    return [float(v) for v in (spec.get("bin_waves") or [spec["waves"]] * len(spec["tp"]))]


def _matrix_spec(ds) -> dict:
    """A power matrix's spec as its Dataset's ``sweep`` attribute holds it (JSON)."""
    import json

    return json.loads(ds.attrs["sweep"])


def _power_matrix_result(power_matrix, arguments):
    """Power matrix over sea-state bins, capture width and annual energy (command
    ``power-matrix``): :func:`parapend.performance.power_matrix` (its parameters, declared
    there; docs/performance.md) as a :class:`~parapend.results.Record` whose fields are the
    JSON keys. ``te`` default ``"6:10:3"`` when neither ``te`` nor ``tp`` is given;
    ``dataset`` is the full Dataset (MHKiT's layout), ``run`` the engine's run.
    ``device="buoy"``: the coupled buoy (``body, radius, draft, mesh, hydro`` and the
    pendulum in SI as ``buoy``; ``length``/``mass`` None: the device's default).

    Returns
    -------
    Record
    """
    from .hydro.declared import expand_inputs, has_inputs
    from .performance import STATISTICS
    from .performance.hull_device import MODES

    if has_inputs(arguments.arguments):  # the input objects: their fields, as keywords
        import inspect

        arguments = inspect.signature(power_matrix).bind(
            **expand_inputs(power_matrix, arguments.arguments))
    a = arguments.arguments
    if a["scheduler"] is not None and a["workers"] is not None:
        raise ParameterError("workers: the processes are the cluster's with --scheduler; "
                             "drop --workers")
    ds, annual, run, seconds = power_matrix(*arguments.args, **arguments.kwargs)
    device, depth = a["device"], a["depth"]
    netcdf, zarr, csv = a["netcdf"], a["zarr"], a["csv"]
    pk = "tp" if "tp" in ds.dims else "te"

    def grid(name):
        return [[None if not math.isfinite(float(v)) else float(v) for v in row]
                for row in ds[name].values]

    quantities = [q for q in ("power", "mechanical_power", "limit_power", "uniform_power",
                              "electrical_power", "radiation_bound_power", "one_way_power",
                              *(f"causal_{f}_{k}" for f in ("perfect", "ar")
                                for k in ("power", "harvested_power")))
                  if q in ds]
    stats = {q: {s: (ds[f"{q}_{s}"].values.astype(int).tolist() if s == "count"
                     else grid(f"{q}_{s}")) for s in STATISTICS} for q in quantities}
    codes = ds["status"].values
    failed = int((codes > 1).sum())  # 0, 1: converged, no_power (a raised solve: not done)
    out = {"hm0": [float(v) for v in ds["hm0"].values], pk: [float(v) for v in ds[pk].values],
           "tp" if pk == "te" else "te":
               [float(v) for v in ds["tp" if pk == "te" else "te"].values],
           "hm0_edges": ds["hm0_edges"].values.tolist(),
           f"{pk}_edges": ds[f"{pk}_edges"].values.tolist(),
           "te_over_tp": float(ds.attrs["te_over_tp"]),
           "realizations": int(ds.sizes["realization"]),
           "seeds": ds["seed"].values.tolist(), "waves": float(_matrix_spec(ds)["waves"]),
           "record_s": [w * t for w, t in zip(_matrix_waves(ds), ds["tp"].values.tolist())],
           "device": device, "power_matrix": grid("power_matrix"),
           "wave_energy_flux_matrix": grid("wave_energy_flux_matrix"),
           "capture_width_matrix": grid("capture_width_matrix"),
           "capture_width_ratio_matrix": (grid("capture_width_ratio_matrix")
                                          if "capture_width_ratio_matrix" in ds else None),
           "statistics": stats, "failed_solves": failed,
           "depth": depth, "width": (ds["capture_width_ratio_matrix"].attrs.get("width")
                                     if "capture_width_ratio_matrix" in ds else None),
           # the store's codes (hull_device.MODES; the heaving buoy's are its first two)
           "operating_mode": [[MODES[int(v)] if v >= 0 else None for v in row]
                              for row in ds["operating_mode"].values],
           "frequency": grid("frequency") if "frequency" in ds else None,
           "annual_energy": annual, "hours_per_year": float(ds.attrs["hours_per_year"]),
           # an incomplete AEP is no plain number: its bounds (annual_energy.power)
           "annual_energy_complete": None if annual is None else annual["power"]["complete"],
           "annual_energy_mwh": (None if annual is None or not annual["power"]["complete"]
                                 else annual["power"]["mwh"]),
           "capacity_factor": (None if annual is None
                               else annual["power"].get("capacity_factor")),
           "store": run.store, "computed_bins": run.computed_points // int(a["realizations"]),
           "resumed_bins": run.resumed_points // int(a["realizations"]), "seconds": seconds,
           "executor": run.executor, "netcdf": netcdf, "zarr": zarr, "csv": csv,
           # a time limit may stop the run: a partial matrix (parapend.deadline)
           "status": ds.attrs.get("status", "ok"), "success": not run.stopped,
           "bins_finished": int(ds.attrs.get("bins_finished", ds["hm0"].size
                                             * ds[pk].size)),
           "bins": int(ds["hm0"].size * ds[pk].size)}
    if "controller" in ds.attrs:  # the causal column (parapend.performance.causal)
        from .performance.causal import causal_json

        out["causal"] = causal_json(ds, grid)
    from .performance import breaking_bins, matrix_csv, matrix_extremes

    out["power_ci_low"], out["power_ci_high"] = grid("power_ci_low"), grid("power_ci_high")
    out["power_ci_method"] = ds["power_ci_low"].attrs["method"]
    out.update(matrix_extremes(ds, pk))
    out.update(breaking_bins(ds, pk))

    return Record("power-matrix", out, dataset=ds, run=run,
                  draw=_draw_dataset("performance.figures", "plot_matrix"),
                  table=lambda r: matrix_csv(r.dataset))


# --- sea, buoy, horizon: the implementation is the command's function; sweep, power-matrix:
# --- the implementation's signature ---------------------------------------------------------
#: commands whose function is the implementation itself, imported on first use (its
#: signature and docstring are the command's parameters, declared once): name -> (module,
#: function)
IMPLEMENTED = {"sea": (".irregular", "sea"), "buoy": (".hydro.api", "buoy"),
               "horizon": (".control.horizon", "horizon_curve"),
               "persistence": (".dynamics.persistence", "persistence")}
#: commands whose parameters are declared once, in the signature (and the docstring's
#: Parameters) of the implementing function, whose answer the command's function shapes into
#: the command's result: name -> (module, function, shape). The command's function takes
#: every argument as the implementation does and hands it on unchanged; its signature is
#: the implementation's, read live (``__wrapped__``: :func:`inspect.signature` follows it),
#: so the command line's defaults are the implementation's.
FORWARDED = {"sweep": (".maps.run", "sweep", _sweep_result),
             "power_matrix": (".performance", "power_matrix", _power_matrix_result)}
__all__ += [*IMPLEMENTED, *FORWARDED]


def _forward(name: str, impl, shape):
    """The command's function ``name``: ``shape(impl, arguments)`` with the call's arguments
    bound to ``impl``'s signature (its defaults applied), under ``impl``'s signature and
    ``shape``'s docstring (:data:`FORWARDED`)."""
    import inspect

    def command(*args, **kwargs):
        arguments = inspect.signature(impl).bind(*args, **kwargs)
        arguments.apply_defaults()
        return shape(impl, arguments)

    command.__wrapped__ = impl
    command.__name__ = command.__qualname__ = name
    command.__module__ = __name__
    command.__doc__ = shape.__doc__
    return command


def __getattr__(name: str):
    """``sea``, ``buoy``, ``horizon``: the implementing function (:data:`IMPLEMENTED`);
    ``sweep``, ``power_matrix``: the implementation's parameters, the command's result
    (:data:`FORWARDED`)."""
    import importlib

    if name in FORWARDED:
        module, function, shape = FORWARDED[name]
        fn = _forward(name, getattr(importlib.import_module(module, __package__), function),
                      shape)
    elif name in IMPLEMENTED:
        module, function = IMPLEMENTED[name]
        fn = getattr(importlib.import_module(module, __package__), function)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = fn
    return fn
