"""The buoy's results and one wave's answer: :class:`BuoyResult` (one wave, or one periodic
record), :class:`BuoySweepResult` (power against wave period), and how a result is made from
the body's coefficients, the pendulum and the wave (:func:`_solve`: the coupled optimum and
the one-way one; :func:`_result`: what a designer reads). :mod:`.api` (the command),
:mod:`.design` (sweeps, the design search) and :mod:`.control` (receding-horizon control)
all build their answers from here.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..results import _Result
from .waves import energy_flux

__all__ = ["BuoyResult", "BuoySweepResult", "free_heave"]


@dataclass(frozen=True, eq=False, repr=False)
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
        (:func:`~parapend.hydro.waves.energy_flux`); capture_width_ratio : over the body's
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
        maximizes the electrical power, ``power_w`` is that electrical power (the headline:
        what the design delivers) and ``mechanical_power_w`` the same motion's mechanical
        power ``-<tau theta'>`` (what the bound fraction, the capture width and the energy
        balance are of).
    mechanical_power_w : see ``efficiency`` (None without one).
    electrical_power_w : ``<e(p)>``, ``e = eta_g p`` generating, ``p / eta_m`` motoring
        (equal to ``power_w`` with an efficiency).
    pto_loss_w : ``mechanical_power_w - electrical_power_w``, the take-off's losses.
    generated_power_w, motoring_power_w : ``<max(p, 0)>`` and ``<max(-p, 0)>``.
    ideal_power_w : the ideal (lossless) coupled optimum
        ``electrical_power_w <= eta_g ideal_power_w``.
    one_way_electrical_power_w : the one-way answer's electrical optimum.
    mesh_error_w : the estimate of the discretization error of ``power_w``: ``|P - P_c|``,
        ``P_c`` the same optimum on the same body meshed with panels ``COARSE = 1.5`` times
        larger, on the same frequencies (:func:`parapend.hydro.bem.body_frequencies`; None
        for a mesh file or a dataset, which have one mesh); mesh_error_relative : over
        ``power_w``.
    grid_error_w : the same for the frequency grid: ``|P - P_h|``, ``P_h`` the optimum on
        every other frequency of the grid (the last kept). Linear interpolation converges
        like the spacing squared, so the answer's own interpolation error is about a third
        of it.
    validity_warnings : where the answer lies outside linear theory's assumptions: the
        heave amplitude above the draft or the freeboard, the body's bottom out of the water
        or its top under it (the motion relative to the wave), a regular wave steeper than
        the breaking limit ``H / lambda = 1/7`` (docs/buoy.md).
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
    mechanical_power_w: float | None = None
    pto_loss_w: float | None = None
    generated_power_w: float | None = None
    motoring_power_w: float | None = None
    ideal_power_w: float | None = None
    one_way_electrical_power_w: float | None = None
    mesh_error_w: float | None = None
    mesh_error_relative: float | None = None
    grid_error_w: float | None = None
    validity_warnings: list = field(default_factory=list)
    _solution: object = field(default=None, repr=False)
    _one_way: object = field(default=None, repr=False)
    _hydro: object = field(default=None, repr=False)
    _wave: object = field(default=None, repr=False)

    @property
    def solution(self):
        """The coupled optimum (:class:`parapend.hydro.optimum.CoupledSolution`)."""
        return self._solution

    @property
    def hydrodynamics(self):
        """The body's hydrodynamic coefficients the optimum was solved with
        (:class:`parapend.hydro.bem.Hydro`)."""
        return self._hydro

    @property
    def incident_wave(self):
        """The incident wave (regular or a periodic record) the optimum was solved for."""
        return self._wave

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

    command = "buoy"
    headline = ("power_w", "electrical_power_w", "one_way_power_w", "radiation_bound_w",
                "heave_amplitude_m", "status")

    def _series(self):
        """The motion over one period (SI): what ``--save`` writes beside the scalars."""
        import xarray as xr

        s = self.samples()
        names = {"theta": "theta", "theta_dot": "theta_dot_rad_per_s", "z": "heave_m",
                 "z_dot": "heave_speed_m_per_s", "tau": "torque_nm",
                 "power": "instantaneous_power_w", "z_free": "free_heave_m"}
        return xr.Dataset({names[k]: ("time_s", s[k]) for k in names},
                          coords={"time_s": s["t"]})

    def _figure(self):
        from .figures import plot_motion

        return plot_motion(self)


@dataclass(frozen=True, eq=False, repr=False)
class BuoySweepResult(_Result):
    """Power of one design against wave period (``wave_period="FROM:TO:N"``), regular waves
    of one height: arrays over ``period_s``, each field named with its unit
    (``electrical_power_w`` with an efficiency, else None). Every period is solved on the
    same mesh and frequencies as alone (:class:`BuoyResult`: the same numbers);
    ``mesh_error_w``, ``grid_error_w`` and ``validity_warnings`` are those of each period
    (the warnings prefixed with the period)."""

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
    mechanical_power_w: np.ndarray | None = None
    mesh_error_w: np.ndarray | None = None
    validity_warnings: list = field(default_factory=list)
    grid_error_w: np.ndarray | None = None

    command = "buoy"
    headline = ("period_s", "power_w", "success")

    def _series(self):
        """The sweep over ``period_s`` (what ``--save`` writes)."""
        import xarray as xr

        names = ("power_w", "one_way_power_w", "radiation_bound_w", "limit_w",
                 "bound_fraction", "capture_width_m", "heave_amplitude_m",
                 "free_heave_amplitude_m", "energy_balance_residual")
        ds = xr.Dataset({k: ("period_s", np.asarray(getattr(self, k), dtype=float))
                         for k in names}, coords={"period_s": self.period_s})
        ds["status"] = ("period_s", np.asarray(self.status, dtype=str))
        for name in ("electrical_power_w", "mechanical_power_w"):
            if getattr(self, name) is not None:
                ds[name] = ("period_s", np.asarray(getattr(self, name), dtype=float))
        if self.mesh_error_w is not None:
            ds["mesh_error_w"] = ("period_s", np.asarray(self.mesh_error_w, dtype=float))
        if self.grid_error_w is not None:
            ds["grid_error_w"] = ("period_s", np.asarray(self.grid_error_w, dtype=float))
        return ds

    def to_dict(self) -> dict:
        return super().to_dict()

    def _figure(self):
        from .figures import plot_sweep

        return plot_sweep(self)

    def __repr__(self) -> str:
        p = np.asarray(self.period_s, dtype=float)
        w = np.asarray(self.power_w, dtype=float)
        return (f"BuoySweepResult(period_s: {p.size} periods from {p[0]:.6g} to {p[-1]:.6g}, "
                f"largest power_w={np.nanmax(w):.6g}, success={self.success!r})")


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


def free_heave(hydro, wave, t) -> np.ndarray:
    """The free buoy's heave (m) at times ``t`` (s): ``Re sum_k F a_k / D exp(i k w t)``."""
    k = np.arange(1, len(wave.amplitudes) + 1)
    zk = hydro.free_response(k * wave.omega) * np.asarray(wave.amplitudes)
    ph = np.multiply.outer(np.asarray(t, dtype=float) * wave.omega, k)
    return (np.exp(1j * ph) @ zk).real


def _half_range(x) -> float:
    x = np.asarray(x, dtype=float)
    return 0.5 * float(np.max(x) - np.min(x))



def _body_info(h, width, geometry=None) -> dict:
    out = {"description": getattr(h, "description", ""), "mass_kg": float(h.mass),
           "hydrostatic_stiffness_n_per_m": float(h.hydrostatic_stiffness),
           "rho_kg_per_m3": float(h.rho), "water_depth_m": float(h.water_depth),
           "frequencies": int(np.size(h.omega)),
           "omega_range_rad_per_s": [float(np.min(h.omega)), float(np.max(h.omega))]}
    if width is not None:
        out["width_m"] = width
    if geometry is not None:
        out.update(geometry)
    return out



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


def _power_on(hydro, pendulum, wave, *, winding, harmonics, torque_limit, efficiency):
    """``power_w`` of the same problem on other coefficients ``hydro`` (its warnings
    dropped: they are the answer's own)."""
    import warnings

    from .optimum import coupled_optimum

    kw = {"winding": winding, "harmonics": harmonics}
    if torque_limit is not None:
        kw["torque_limit"] = torque_limit
    if efficiency is not None:
        kw["efficiency"] = efficiency
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = coupled_optimum(hydro, pendulum, wave, **kw)
    return float(sol.power)


def _half_grid(h):
    """The same coefficients on every other frequency of ``h``'s grid (the last kept); None
    below 3 frequencies."""
    n = np.size(h.omega)
    if n < 3:
        return None
    i = np.arange(0, n, 2)
    if i[-1] != n - 1:
        i = np.append(i, n - 1)
    return dataclasses.replace(h, omega=np.asarray(h.omega)[i],
                               added_mass=np.asarray(h.added_mass)[i],
                               radiation_damping=np.asarray(h.radiation_damping)[i],
                               excitation=np.asarray(h.excitation)[i])


def _error_powers(h, coarse, pendulum, wave, **opts):
    """``(P_c, P_half)``: the same optimum on the coarse mesh ``coarse`` (None: none) and on
    every other frequency of ``h`` (the error estimates' second answers)."""
    pc = None if coarse is None else _power_on(coarse, pendulum, wave, **opts)
    half = _half_grid(h)
    return pc, None if half is None else _power_on(half, pendulum, wave, **opts)


#: A regular wave steeper than this breaks (Michell's limit, H / lambda ~ 0.142).
BREAKING_STEEPNESS = 1 / 7


def _validity(z, eta, wave, wave_info, h, geometry) -> list:
    """Where the motion ``z`` (m, one period's samples) in the wave ``eta`` (m, the same
    times) leaves linear theory's assumptions (:class:`BuoyResult`'s ``validity_warnings``)."""
    out = []
    heave = _half_range(z)
    rel = np.asarray(z) - np.asarray(eta)
    if geometry is not None:
        d, f = geometry["draft_m"], geometry["freeboard_m"]
        for name, size in (("draft", d), ("freeboard", f)):
            if heave > size:
                out.append(f"linear theory: the heave amplitude {heave:.3g} m exceeds the "
                           f"body's {name} {size:.3g} m; the answer is outside its validity")
        if float(np.max(rel)) > d:
            out.append(f"linear theory: the body's bottom leaves the water (the heave "
                       f"relative to the wave reaches {float(np.max(rel)):.3g} m, the draft "
                       f"is {d:.3g} m)")
        if -float(np.min(rel)) > f:
            out.append(f"linear theory: the body's top goes under water (the wave rises "
                       f"{-float(np.min(rel)):.3g} m above the body's still waterline, the "
                       f"freeboard is {f:.3g} m)")
    if wave_info.get("kind") == "regular":
        from .waves import wavenumber

        k = wavenumber(wave.omega, h.water_depth, h.g)
        height = 2 * float(np.max(np.abs(np.asarray(wave.amplitudes))))
        steep = height * k / (2 * math.pi)
        if steep > BREAKING_STEEPNESS:
            out.append(f"linear theory: the wave's steepness H / lambda = {steep:.3g} exceeds "
                       f"the breaking limit 1/7 (wavelength {2 * math.pi / k:.3g} m)")
    return out


def _result(h, width, pendulum, wave, wave_info, sol, ow, *, torque_limit, efficiency,
            winding, design=None, notes=(), error_powers=(None, None),
            geometry=None) -> BuoyResult:
    period = 2 * math.pi / wave.omega
    t = period * np.arange(801) / 800
    s = sol.sample(t)
    amps = np.asarray(wave.amplitudes)
    flux = energy_flux(wave.omega, amps, h.rho, h.g, h.water_depth)
    p = float(sol.power)
    bound = float(sol.radiation_bound)
    cw = p / flux if flux > 0 else math.nan
    notes = list(getattr(h, "notes", ())) + list(notes)
    n = int(sol.harmonics)
    above = np.asarray(h.above_range(wave.omega * np.arange(1, n + 1)))
    if above.any():
        k = int(np.argmax(above)) + 1
        notes.append(f"harmonics {k} to {n} of the motion ({k * wave.omega:.4g} rad/s and "
                     f"above) lie above the dataset's highest frequency "
                     f"{float(np.max(h.omega)):.4g} rad/s: there A is held and B = F = 0")
    owp = None if ow is None else float(ow.power)
    coarse_power, half_power = error_powers
    err = None if coarse_power is None else abs(p - float(coarse_power))
    gerr = None if half_power is None else abs(p - float(half_power))
    eta = (np.exp(1j * np.multiply.outer(t * wave.omega, np.arange(1, amps.size + 1)))
           @ amps).real
    validity = _validity(s["z"], eta, wave, wave_info, h, geometry)
    ep = sol.electrical_power
    harvest = p if ep is None else float(ep)  # what the design delivers
    # a heaving body absorbs at most the radiation bound: a power above it (beyond the
    # discretization's 0.1 %) is an impossible number, never a success
    impossible = harvest > 0 and not p <= bound * (1 + 1e-3)
    if impossible:
        notes.append(f"the power {p:.6g} W exceeds the radiation bound {bound:.6g} W: the "
                     "hydrodynamic data or the solve are wrong; not a success")
    eff = None if sol.efficiency is None else [float(v) for v in sol.efficiency]
    efields = {} if ep is None else {
        "electrical_power_w": float(ep), "mechanical_power_w": p, "pto_loss_w": p - float(ep),
        "generated_power_w": float(sol.generated_power),
        "motoring_power_w": float(sol.motoring_power),
        "ideal_power_w": float(sol.ideal_power),
        "one_way_electrical_power_w": None if ow is None or ow.electrical_power is None
        else float(ow.electrical_power)}
    return BuoyResult(
        power_w=harvest, heave_amplitude_m=_half_range(s["z"]),
        peak_torque_nm=float(sol.peak_torque()),
        radiation_bound_w=bound, bound_fraction=p / bound if bound > 0 else None,
        limit_w=float(sol.limit), capture_width_m=cw,
        capture_width_ratio=cw / width if width else None, energy_flux_w_per_m=flux,
        one_way_power_w=owp, one_way_ratio=owp / p if owp is not None and p > 0 else None,
        free_heave_amplitude_m=_half_range(free_heave(h, wave, t)),
        energy_balance_residual=float(sol.energy_balance_residual), harmonics=n,
        winding=int(winding), success=bool(sol.success) and harvest > 0 and not impossible,
        status=("above_bound" if impossible else str(sol.status)) if harvest > 0
        else "no_power",
        message=_message(sol, p, pendulum, ep, bound=bound, torque_limit=torque_limit),
        wave=wave_info,
        pendulum={"mass_kg": pendulum.mass, "length_m": pendulum.length,
                  "inertia_kg_m2": pendulum.inertia,
                  "damping_coefficient_nm_s_per_rad": pendulum.damping_coefficient},
        body=_body_info(h, width, geometry), torque_limit_nm=torque_limit, efficiency=eff,
        design=design, warnings=notes, mesh_error_w=err,
        mesh_error_relative=err / p if err is not None and p > 0 else None,
        grid_error_w=gerr,
        validity_warnings=validity, _solution=sol, _one_way=ow, _hydro=h, _wave=wave,
        **efields)


def _message(sol, p, pendulum, electrical=None, *, bound=None, torque_limit=None) -> str:
    """The solve's message; where no power is harvested, its cause, beginning with the
    option to change (the CLI names it): no force on the body, a torque limit too low to
    turn the pendulum over, losses, or the pendulum's damping."""
    if not p > 0 and bound is not None and not bound > 0:
        return ("wave: the wave gives the body nothing to absorb (radiation bound 0 W: no "
                "excitation force or no radiation damping at its frequencies); check the "
                "hydrodynamic data and the wave period")
    mgl = pendulum.mass * 9.81 * pendulum.length
    if not p > 0 and torque_limit is not None and torque_limit < mgl:
        return (f"torque-limit: the pendulum cannot rotate with positive power within a torque "
                f"limit of {torque_limit:.3g} N m (best P = {p:.3g} W; m g l = {mgl:.3g} N m "
                "holds it against gravity); raise the limit")
    if electrical is not None and p > 0 >= electrical:
        return (f"no electrical power: through this take-off every motion found costs more "
                f"than it harvests (best electrical power {electrical:.3g} W, mechanical "
                f"{p:.3g} W); raise the efficiency or lower the damping")
    if p > 0:
        return str(getattr(sol, "message", "") or sol.status)
    return (f"the pendulum cannot rotate with positive power in this wave (best P = {p:.3g} W): "
            f"its damping c = {pendulum.damping_coefficient:g} N m s/rad takes more than the "
            "wave gives; lower the damping or raise the wave height")


