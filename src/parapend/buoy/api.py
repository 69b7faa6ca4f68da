"""``parapend.buoy``: the coupled optimum of a pendulum inside a floating buoy (docs/buoy.md).

One function, :func:`buoy`, with the options of ``parapend buoy`` as keyword arguments,
returning a frozen :class:`BuoyResult` (one wave) or :class:`BuoySweepResult` (power against
wave period, ``wave_period="FROM:TO:N"``). Everything is in SI units; the field names carry
the unit (``power_w``, ``heave_amplitude_m``, ``peak_torque_nm``).

The work is done by :mod:`.hydro` (the body's coefficients) and :mod:`.optimum` (the coupled
optimum); this module checks the input, builds the wave, the body and the pendulum, and
derives what a designer reads: the radiation bound and the fraction of it reached, the
capture width (power over the wave's energy flux), the one-way answer (the pendulum's
reaction left out) and the free buoy's response.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..defaults import BUOY
from ..errors import ParameterError, check_int, check_nonnegative, check_positive, check_range
from ..results import _Result

__all__ = ["BuoyResult", "BuoySweepResult", "buoy", "energy_flux", "group_velocity",
           "parse_periods"]

#: pendulum parameters ``--optimize-design`` may vary
DESIGN_VARIABLES = ("mass", "length", "inertia", "damping_coefficient")

#: at most this many periods in a sweep
MAX_PERIODS = 200


@dataclass(frozen=True, eq=False)
class BuoyResult(_Result):
    """The coupled optimum of one design in one sea (field names = JSON keys of ``parapend
    buoy``; SI units, named in each field).

    Attributes
    ----------
    power_w : mean harvested power of the coupled optimum, ``P = -<tau theta'>``.
    heave_amplitude_m : half the buoy's peak-to-peak heave over the period, coupled.
    peak_torque_nm : largest ``|tau|`` of the optimal motion.
    radiation_bound_w : ``sum_k |F_k a_k|^2 / (8 B_k)``: no mechanism inside the buoy absorbs
        more (a heaving body radiates what it does not absorb).
    bound_fraction : ``power_w / radiation_bound_w``.
    limit_w : the coupled undamped supremum (``c = 0``: switching motions approach it).
    capture_width_m : ``power_w / J``, ``J`` the wave's energy flux per metre of crest
        (:func:`~parapend.buoy.api.energy_flux`); capture_width_ratio : over the body's
        width ``2 radius`` (None where the width is not known: a mesh file or a dataset).
    energy_flux_w_per_m : ``J``.
    one_way_power_w : the optimum when the pendulum's reaction is left out (the pivot moves
        as the free buoy): what a one-way model predicts; one_way_ratio : ``one_way_power_w /
        power_w``.
    free_heave_amplitude_m : half the free buoy's peak-to-peak heave (no pendulum).
    energy_balance_residual
        The relative residual of the energy balance
        ``P + c <theta'^2> = <F_exc z'> - sum_k B_k (k w)^2 |Z_k|^2 / 2`` (below 1e-9 when
        the solve is right).
    harmonics : N of the motion; winding : turns per wave (or per record).
    success, status, message : the coupled solve's verdict; "no_power" when no rotation
        harvests anything.
    wave, pendulum, body : what was solved (dicts of SI numbers and descriptions).
    design : the outer search of ``optimize_design`` (None without it).
    warnings : notes on the result (retained harmonics above the dataset's frequencies).
    efficiency : ``[eta_g, eta_m]`` of the power take-off (None: ideal). With it the motion
        maximizes the electrical power, and ``power_w`` is that motion's mechanical power.
    electrical_power_w : ``<e(p)>``, ``e = eta_g p`` generating, ``p / eta_m`` motoring.
    pto_loss_w : ``power_w - electrical_power_w``, the take-off's losses.
    generated_power_w, motoring_power_w : ``<max(p, 0)>`` and ``<max(-p, 0)>``.
    ideal_power_w : the ideal (lossless) coupled optimum
        ``electrical_power_w <= eta_g ideal_power_w``.
    one_way_electrical_power_w : the one-way answer's electrical optimum.
    """

    power_w: float
    heave_amplitude_m: float
    peak_torque_nm: float
    radiation_bound_w: float
    bound_fraction: float | None
    limit_w: float
    capture_width_m: float
    capture_width_ratio: float | None
    energy_flux_w_per_m: float
    one_way_power_w: float | None
    one_way_ratio: float | None
    free_heave_amplitude_m: float
    energy_balance_residual: float
    harmonics: int
    winding: int
    success: bool
    status: str
    message: str
    wave: dict
    pendulum: dict
    body: dict
    torque_limit_nm: float | None
    efficiency: list | None
    design: dict | None
    warnings: list
    electrical_power_w: float | None = None
    pto_loss_w: float | None = None
    generated_power_w: float | None = None
    motoring_power_w: float | None = None
    ideal_power_w: float | None = None
    one_way_electrical_power_w: float | None = None
    _solution: object = field(default=None, repr=False)
    _one_way: object = field(default=None, repr=False)
    _hydro: object = field(default=None, repr=False)
    _wave: object = field(default=None, repr=False)

    @property
    def solution(self):
        """The coupled optimum (:class:`parapend.buoy.optimum.CoupledSolution`)."""
        return self._solution

    def samples(self, points: int = 400) -> dict:
        """One period on a uniform grid: ``t`` (s), ``theta`` (rad), ``theta_dot`` (rad/s),
        ``z`` (m), ``z_dot`` (m/s), ``tau`` (N m), ``power`` (``-tau theta'``, W) of the
        coupled optimum, and ``z_free`` (m), the free buoy's heave."""
        period = 2 * math.pi / self._wave.omega
        t = period * np.arange(points + 1) / points
        s = dict(self._solution.sample(t))
        out = {"t": t, **{k: np.asarray(s[k], dtype=float)
                          for k in ("theta", "theta_dot", "z", "z_dot", "tau")}}
        out["power"] = -out["tau"] * out["theta_dot"]
        out["z_free"] = free_heave(self._hydro, self._wave, t)
        return out

    def to_dataset(self, points: int = 400):
        """The motion over one period as an ``xarray.Dataset`` (variables in SI units, the
        scalar fields as attributes): what ``--save`` writes."""
        import xarray as xr

        s = self.samples(points)
        units = {"theta": "rad", "theta_dot": "rad/s", "z": "m", "z_dot": "m/s", "tau": "N m",
                 "power": "W", "z_free": "m"}
        ds = xr.Dataset({k: ("t", s[k], {"units": u}) for k, u in units.items()},
                        coords={"t": ("t", s["t"], {"units": "s"})})
        for k, v in self.to_dict().items():
            ds.attrs[k] = _attr(v)
        return ds


@dataclass(frozen=True, eq=False)
class BuoySweepResult(_Result):
    """Power of one design against wave period (``wave_period="FROM:TO:N"``), regular waves
    of one height: arrays over ``period_s``, each field named with its unit
    (``electrical_power_w`` with an efficiency, else None)."""

    period_s: np.ndarray
    power_w: np.ndarray
    one_way_power_w: np.ndarray
    radiation_bound_w: np.ndarray
    limit_w: np.ndarray
    bound_fraction: np.ndarray
    capture_width_m: np.ndarray
    heave_amplitude_m: np.ndarray
    free_heave_amplitude_m: np.ndarray
    energy_balance_residual: np.ndarray
    status: list
    success: bool
    wave_height_m: float
    pendulum: dict
    body: dict
    warnings: list
    _results: tuple = field(default=(), repr=False)
    electrical_power_w: np.ndarray | None = None

    def to_dataset(self):
        """The sweep as an ``xarray.Dataset`` over ``period_s`` (what ``--save`` writes)."""
        import xarray as xr

        names = ("power_w", "one_way_power_w", "radiation_bound_w", "limit_w",
                 "bound_fraction", "capture_width_m", "heave_amplitude_m",
                 "free_heave_amplitude_m", "energy_balance_residual")
        ds = xr.Dataset({k: ("period_s", np.asarray(getattr(self, k), dtype=float))
                         for k in names}, coords={"period_s": self.period_s})
        ds["status"] = ("period_s", np.asarray(self.status, dtype=str))
        if self.electrical_power_w is not None:
            ds["electrical_power_w"] = ("period_s", np.asarray(self.electrical_power_w,
                                                               dtype=float))
        for k in ("success", "wave_height_m", "pendulum", "body", "warnings"):
            ds.attrs[k] = _attr(getattr(self, k))
        return ds


def _attr(v):
    """A value NetCDF can hold as an attribute."""
    import json

    if isinstance(v, bool):
        return int(v)
    if v is None:
        return ""
    if isinstance(v, (dict, list, tuple)):
        from ..results import to_jsonable

        return json.dumps(to_jsonable(v))
    return v


# --- the sea ----------------------------------------------------------------------------------
def wavenumber(omega: float, depth: float, g: float) -> float:
    """``k`` of ``omega^2 = g k tanh(k h)`` (deep water where ``h`` is infinite)."""
    k0 = omega * omega / g
    if not math.isfinite(depth):
        return k0
    from scipy.optimize import brentq

    lo, hi = k0 * 0.5, max(k0, omega / math.sqrt(g * depth)) * 2 + 1e-12
    return float(brentq(lambda k: g * k * math.tanh(k * depth) - omega * omega, lo, hi,
                        xtol=1e-14, rtol=1e-14, maxiter=200))


def group_velocity(omega: float, depth: float = math.inf, g: float = 9.81) -> float:
    """Group velocity of linear waves, m/s: ``g / (2 omega)`` in deep water, ``(omega/k) (1 +
    2 k h / sinh(2 k h)) / 2`` in depth ``h``."""
    if not math.isfinite(depth):
        return g / (2 * omega)
    k = wavenumber(omega, depth, g)
    kh2 = 2 * k * depth
    return 0.5 * omega / k * (1 + (kh2 / math.sinh(kh2) if kh2 < 700 else 0.0))


def energy_flux(omega: float, amplitudes, rho: float = 1025.0, g: float = 9.81,
                depth: float = math.inf) -> float:
    """Energy flux per metre of crest, W/m, of the wave ``Re sum_k a_k exp(i k omega t)``:
    ``J = rho g sum_k |a_k|^2 c_g(k omega) / 2``; a regular wave in deep water gives
    ``rho g^2 H^2 T / (32 pi)``."""
    a = np.asarray(amplitudes)
    total = 0.0
    for k, ak in enumerate(a, start=1):
        if ak != 0:
            total += 0.5 * abs(ak) ** 2 * group_velocity(k * omega, depth, g)
    return rho * g * total


def parse_periods(text) -> np.ndarray | None:
    """``"FROM:TO:N"`` -> N periods from FROM to TO (s); a plain number -> None."""
    if not isinstance(text, str) or ":" not in text:
        return None
    parts = text.split(":")
    if len(parts) != 3:
        raise ParameterError(f"wave-period: expected a period in s or FROM:TO:N, got "
                             f"{text!r:.60}")
    try:
        lo, hi = float(parts[0]), float(parts[1])
        n = int(parts[2])
    except ValueError:
        raise ParameterError(f"wave-period: expected FROM:TO:N (two periods in s, a count), "
                             f"got {text!r:.60}") from None
    lo = check_positive("wave-period", lo)
    hi = check_positive("wave-period", hi)
    n = check_int("wave-period", n, 2, MAX_PERIODS)
    if not hi > lo:
        raise ParameterError(f"wave-period: expected FROM < TO, got {text!r:.60}")
    return np.linspace(lo, hi, n)


def _period(value) -> float:
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            raise ParameterError(f"wave-period: expected a period in s or FROM:TO:N, got "
                                 f"{value!r:.60}") from None
    return check_range("wave-period", value, 0.1, 100.0, why="wave period, s")


def free_heave(hydro, wave, t) -> np.ndarray:
    """The free buoy's heave (m) at times ``t`` (s): ``Re sum_k F a_k / D exp(i k w t)``."""
    k = np.arange(1, len(wave.amplitudes) + 1)
    zk = hydro.free_response(k * wave.omega) * np.asarray(wave.amplitudes)
    ph = np.multiply.outer(np.asarray(t, dtype=float) * wave.omega, k)
    return (np.exp(1j * ph) @ zk).real


def _half_range(x) -> float:
    x = np.asarray(x, dtype=float)
    return 0.5 * float(np.max(x) - np.min(x))


# --- the pieces -----------------------------------------------------------------------------
def _pendulum(mass, length, inertia, damping_coefficient):
    from .coupled import Pendulum

    mass = check_positive("mass", mass)
    length = check_positive("length", length)
    ml2 = mass * length * length
    if inertia is None:
        inertia = ml2
    inertia = check_positive("inertia", inertia)
    if inertia < ml2 * (1 - 1e-12):
        raise ParameterError(f"inertia: expected at least m l^2 = {ml2:.6g} kg m^2 (the "
                             f"inertia about the pivot of a mass {mass:g} kg at {length:g} m), "
                             f"got {inertia:g}")
    c = check_nonnegative("damping-coefficient", damping_coefficient)
    return Pendulum(mass=mass, length=length, inertia=inertia, damping_coefficient=c)


def _irregular_wave(hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff, record, taper,
                    units):
    """The Wave of a periodic irregular record (``sea``'s parsing and checks) and its
    description."""
    from ..seas import measured_record, sea_record
    from .coupled import Wave

    if record is not None:
        bad = [n for n, v in (("hs", hs), ("tp", tp), ("seed", seed),
                              ("repeat-period", repeat_period)) if v is not None]
        if bad:
            raise ParameterError(f"{', '.join(bad)}: not used with --record; drop it")
        exc = measured_record(units, record, taper=taper, cutoff=cutoff)
    else:
        exc = sea_record(units, hs=BUOY["hs"] if hs is None else hs,
                         tp=BUOY["tp"] if tp is None else tp, spectrum=spectrum,
                         gamma_peak=gamma_peak, repeat_period=repeat_period,
                         seed=0 if seed is None else seed, cutoff=cutoff)
    info = dict(exc.info)
    info.pop("response", None)
    tr = float(info["repeat_period"])
    # the record's own components (an FFT of samples would add round-off at every harmonic)
    wave = Wave(2 * math.pi / tr, np.asarray(exc.heave[1:], dtype=complex))
    info = {"kind": "irregular", **info}
    return wave, info


def _hydro(body, radius, draft, mesh, hydro, omegas, harmonics):
    """The body's coefficients over the frequencies the problem needs (the wave's
    ``omegas`` up to ``harmonics`` times the highest, rad/s), and the body's width."""
    from . import hydro as hy

    given = [n for n, v in (("mesh", mesh), ("hydro", hydro)) if v is not None]
    if len(given) > 1:
        raise ParameterError("hydro: give either --mesh or --hydro, not both")
    if given and (radius is not None or draft is not None):
        raise ParameterError(f"{'radius' if radius is not None else 'draft'}: the body comes "
                             f"from --{given[0]}; drop it")
    if hydro is not None:
        return hy.load(hydro), None
    omega = hy.frequencies_for(np.asarray(omegas, dtype=float), harmonics)
    try:
        return _solve_hydro(hy, body, radius, draft, mesh, omega)
    except ParameterError as e:
        # the user gave wave periods, not the BEM's frequencies
        if str(e).startswith("omega: every frequency is too high"):
            raise ParameterError("wave-period: the waves are too short for the body's mesh; "
                                 + str(e).split(": ", 1)[1]) from None
        raise


def _solve_hydro(hy, body, radius, draft, mesh, omega):
    if mesh is not None:
        return hy.from_mesh(mesh, omega=omega), None
    if body not in ("cylinder", "sphere"):
        raise ParameterError(f"body: expected cylinder or sphere, got {body!r:.40}")
    r = check_positive("radius", BUOY["radius"] if radius is None else radius)
    if body == "sphere":
        if draft is not None:
            raise ParameterError("draft: a sphere floats at its centre (draft = radius); "
                                 "drop --draft")
        return hy.sphere(r, omega=omega), 2 * r
    d = check_positive("draft", BUOY["draft"] if draft is None else draft)
    return hy.cylinder(r, d, omega=omega), 2 * r


def _body_info(h, width) -> dict:
    out = {"description": getattr(h, "description", ""), "mass_kg": float(h.mass),
           "hydrostatic_stiffness_n_per_m": float(h.hydrostatic_stiffness),
           "rho_kg_per_m3": float(h.rho), "water_depth_m": float(h.water_depth),
           "frequencies": int(np.size(h.omega)),
           "omega_range_rad_per_s": [float(np.min(h.omega)), float(np.max(h.omega))]}
    if width is not None:
        out["width_m"] = width
    return out


def _check_floats(h, pendulum):
    if not pendulum.mass < h.mass:
        raise ParameterError(f"mass: the pendulum's {pendulum.mass:g} kg is not less than the "
                             f"floating mass M = {h.mass:.6g} kg (rho x displaced volume, "
                             "which includes the pendulum); use a lighter pendulum or a "
                             "larger body")


def _solve(h, pendulum, wave, *, winding, harmonics, torque_limit, efficiency, one_way=True):
    """The coupled optimum, the one-way one (``one_way``), and the solver's warnings as
    notes for the result (never as Python warnings)."""
    import warnings

    from .optimum import coupled_optimum

    kw = {"winding": winding, "harmonics": harmonics}
    if torque_limit is not None:
        kw["torque_limit"] = torque_limit
    if efficiency is not None:
        kw["efficiency"] = efficiency
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = coupled_optimum(h, pendulum, wave, **kw)
        ow = coupled_optimum(h, pendulum, wave, one_way=True, **kw) if one_way else None
    notes = list(dict.fromkeys(str(w.message) for w in caught))
    return sol, ow, notes


def _result(h, width, pendulum, wave, wave_info, sol, ow, *, torque_limit, efficiency,
            winding, design=None, notes=()) -> BuoyResult:
    period = 2 * math.pi / wave.omega
    t = period * np.arange(801) / 800
    s = sol.sample(t)
    amps = np.asarray(wave.amplitudes)
    flux = energy_flux(wave.omega, amps, h.rho, h.g, h.water_depth)
    p = float(sol.power)
    bound = float(sol.radiation_bound)
    cw = p / flux if flux > 0 else math.nan
    notes = list(notes)
    n = int(sol.harmonics)
    above = np.asarray(h.above_range(wave.omega * np.arange(1, n + 1)))
    if above.any():
        k = int(np.argmax(above)) + 1
        notes.append(f"harmonics {k} to {n} of the motion ({k * wave.omega:.4g} rad/s and "
                     f"above) lie above the dataset's highest frequency "
                     f"{float(np.max(h.omega)):.4g} rad/s: there A is held and B = F = 0")
    owp = None if ow is None else float(ow.power)
    ep = sol.electrical_power
    harvest = p if ep is None else float(ep)  # what the design delivers
    eff = None if sol.efficiency is None else [float(v) for v in sol.efficiency]
    efields = {} if ep is None else {
        "electrical_power_w": float(ep), "pto_loss_w": p - float(ep),
        "generated_power_w": float(sol.generated_power),
        "motoring_power_w": float(sol.motoring_power),
        "ideal_power_w": float(sol.ideal_power),
        "one_way_electrical_power_w": None if ow is None or ow.electrical_power is None
        else float(ow.electrical_power)}
    return BuoyResult(
        power_w=p, heave_amplitude_m=_half_range(s["z"]), peak_torque_nm=float(sol.peak_torque()),
        radiation_bound_w=bound, bound_fraction=p / bound if bound > 0 else None,
        limit_w=float(sol.limit), capture_width_m=cw,
        capture_width_ratio=cw / width if width else None, energy_flux_w_per_m=flux,
        one_way_power_w=owp, one_way_ratio=owp / p if owp is not None and p > 0 else None,
        free_heave_amplitude_m=_half_range(free_heave(h, wave, t)),
        energy_balance_residual=float(sol.energy_balance_residual), harmonics=n,
        winding=int(winding), success=bool(sol.success) and harvest > 0,
        status=str(sol.status) if harvest > 0 else "no_power",
        message=_message(sol, p, pendulum, ep), wave=wave_info,
        pendulum={"mass_kg": pendulum.mass, "length_m": pendulum.length,
                  "inertia_kg_m2": pendulum.inertia,
                  "damping_coefficient_nm_s_per_rad": pendulum.damping_coefficient},
        body=_body_info(h, width), torque_limit_nm=torque_limit, efficiency=eff,
        design=design, warnings=notes, _solution=sol, _one_way=ow, _hydro=h, _wave=wave,
        **efields)


def _message(sol, p, pendulum, electrical=None) -> str:
    if electrical is not None and p > 0 >= electrical:
        return (f"no electrical power: through this take-off every motion found costs more "
                f"than it harvests (best electrical power {electrical:.3g} W, mechanical "
                f"{p:.3g} W); raise the efficiency or lower the damping")
    if p > 0:
        return str(getattr(sol, "message", "") or sol.status)
    return (f"the pendulum cannot rotate with positive power in this wave (best P = {p:.3g} W): "
            f"its damping c = {pendulum.damping_coefficient:g} N m s/rad takes more than the "
            "wave gives; lower the damping or raise the wave height")


# --- the command ------------------------------------------------------------------------------
def buoy(*, wave_height=None, wave_period=None, hs=None, tp=None, spectrum="jonswap",
         gamma_peak=3.3, repeat_period=None, seed=None, cutoff=3.0, record=None, taper=0.1,
         mass=BUOY["mass"], length=BUOY["length"], inertia=BUOY["inertia"],
         damping_coefficient=BUOY["damping_coefficient"], body="cylinder", radius=None,
         draft=None, mesh=None, hydro=None, winding=1, harmonics=None, torque_limit=None,
         efficiency=None, optimize_design=None, mass_bounds=None, length_bounds=None,
         inertia_bounds=None, damping_coefficient_bounds=None, controller="optimum",
         horizon=1.0, update_interval=0.125):
    """The coupled optimum of a pendulum inside a floating buoy (command ``buoy``).

    Parameters
    ----------
    wave_height, wave_period : float
        A regular wave: height ``H`` (m, crest to trough) and period (s); ``wave_period``
        as ``"FROM:TO:N"`` gives power against period (:class:`BuoySweepResult`). Default
        the embedded design's wave (``parapend.defaults.BUOY``).
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
    winding : turns of the pendulum per wave (per record for an irregular sea).
    harmonics : N of the motion (default chosen from the problem and checked).
    torque_limit : N m.
    efficiency : float, pair or str
        Of the power take-off: a number in (0, 1] (both ways), a pair ``(eta_g, eta_m)``
        or the text ``"ETA_G,ETA_M"``: the motion maximizes the electrical power
        (docs/buoy.md), within ``torque_limit`` if given.
    optimize_design : comma list of pendulum parameters to choose (``"length,inertia"``)
        for the largest coupled power, each within ``<name>_bounds`` ``"LO:HI"``.

    controller, horizon, update_interval : ``"optimum"`` (the non-causal coupled optimum),
        or a causal receding-horizon controller run on the coupled time-domain plant in an
        irregular sea (:mod:`parapend.buoy.control`): ``"mpc"`` (planned on the coupled model) or
        ``"one-way-mpc"`` (planned on the free buoy's heave); horizon and update interval in
        peak periods.

    Returns
    -------
    result : BuoyResult, BuoySweepResult or BuoyMPCResult
        One design; a period sweep; a receding-horizon run (``controller``, the result of
        :func:`parapend.buoy.control.buoy_mpc`).
    """
    from .coupled import Wave

    if controller not in ("optimum", "mpc", "one-way-mpc"):
        raise ParameterError(f"controller: expected optimum, mpc or one-way-mpc, got "
                             f"{controller!r:.40}")
    periods = parse_periods(wave_period)
    if controller != "optimum" and (periods is not None or not any(
            v is not None for v in (hs, tp, repeat_period, seed))):
        raise ParameterError("controller: mpc runs in an irregular sea state: give --hs and "
                             "--tp (and --repeat-period, --seed)")
    irregular = any(v is not None for v in (hs, tp, record, repeat_period, seed))
    if irregular:
        bad = [n for n, v in (("wave-height", wave_height), ("wave-period", wave_period))
               if v is not None]
        if bad:
            raise ParameterError(f"{bad[0]}: a regular wave or an irregular sea (--hs, --tp, "
                                 "--record), not both")
    pend = _pendulum(mass, length, inertia, damping_coefficient)
    if winding is not None:
        winding = check_int("winding", winding, 1, 64)
    if harmonics is not None:
        harmonics = check_int("harmonics", harmonics, 2, 4096)
    if torque_limit is not None:
        torque_limit = check_positive("torque-limit", torque_limit)
    if efficiency is not None:
        from .pto import efficiency_pair

        efficiency = efficiency_pair(efficiency)
        if efficiency == (1.0, 1.0):
            efficiency = None  # lossless: the ideal problem
    variables, bounds = _design_request(optimize_design, pend, mass_bounds=mass_bounds,
                                        length_bounds=length_bounds,
                                        inertia_bounds=inertia_bounds,
                                        damping_coefficient_bounds=damping_coefficient_bounds)
    height = check_range("wave-height", BUOY["wave_height"] if wave_height is None
                         else wave_height, 1e-4, 30.0, why="regular wave height, m")
    if periods is not None and variables:
        raise ParameterError("optimize-design: one wave period at a time (drop FROM:TO:N)")
    nb = BUOY["bem_harmonics"]
    if irregular:
        from ..units import Units

        wave, info = _irregular_wave(hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff,
                                     record, taper, Units(pend.length, pend.mass, 9.81,
                                                          pend.inertia))
        amps = np.abs(np.asarray(wave.amplitudes))
        sig = np.nonzero(amps >= 1e-3 * amps.max())[0]  # the components that matter
        top = np.nonzero(amps)[0][-1]
        h, width = _hydro(body, radius, draft, mesh, hydro,
                          wave.omega * np.array([sig[0] + 1.0, top + 1.0]), 2)
        h.check_covers(wave.omega * (sig[0] + 1), wave.omega * (sig[-1] + 1),
                       name="tp" if record is None else "record")
    else:
        if periods is None:
            period = _period(BUOY["wave_period"] if wave_period is None else wave_period)
            periods_all = np.array([period])
        else:
            periods_all = np.array([_period(p) for p in periods])
        h, width = _hydro(body, radius, draft, mesh, hydro, 2 * math.pi / periods_all, nb)
        w = 2 * math.pi / periods_all
        h.check_covers(float(np.min(w)), float(np.max(w)), name="wave-period")
        if periods is not None:
            _check_floats(h, pend)
            from .design import period_sweep

            return period_sweep(h, width, pend, height, periods_all, winding=winding,
                                harmonics=harmonics, torque_limit=torque_limit,
                                efficiency=efficiency)
        wave = Wave.regular(height, float(periods_all[0]))
        info = {"kind": "regular", "height_m": height, "period_s": float(periods_all[0]),
                "omega_rad_per_s": 2 * math.pi / float(periods_all[0])}
    _check_floats(h, pend)
    if controller != "optimum":
        from .control import mpc_command

        return mpc_command(h, pend, wave, info, controller=controller, horizon=horizon,
                           update_interval=update_interval, winding=winding,
                           harmonics=harmonics, torque_limit=torque_limit,
                           efficiency=efficiency, irregular=irregular,
                           design=bool(variables))
    opts = {"winding": winding, "harmonics": harmonics, "torque_limit": torque_limit,
            "efficiency": efficiency}
    design = None
    if variables:
        from .design import optimize_design as _outer

        found = _outer(lambda p: _solve(h, p, wave, one_way=False, **opts)[0], pend,
                       variables, bounds, check=lambda p: _check_floats(h, p))
        pend, design = found.pendulum, found.to_dict()
    sol, ow, notes = _solve(h, pend, wave, **opts)
    return _result(h, width, pend, wave, info, sol, ow, torque_limit=torque_limit,
                   efficiency=efficiency, winding=winding, design=design, notes=notes)


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
