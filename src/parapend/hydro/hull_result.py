"""The answer for a pendulum in a surging, heaving, pitching hull (``parapend buoy --dofs
surge,heave,pitch``): rotation, swinging and rest side by side, the best one's motion, the
hull's, the torque and the bearing load, with the checks (energy balance, radiation bound,
one-way answer, refinement, linear theory's validity).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from ..results import Result
from .hull import HullProblem
from .hull_optimum import BOUND_RCOND, HullPTO, hull_search, make_case, radiation_bound
from .optimum import TORQUE_SLACK
from .waves import energy_flux

__all__ = ["HullResult", "HullSweepResult", "MotionAt", "hull_answer"]

#: pitch beyond which linear hull theory is stretched (deg)
PITCH_VALIDITY_DEG = 15.0
#: points per period on which the extremes are first located (then refined by Brent)
PEAK_POINTS = 2048


class MotionAt:
    """The motion of one solution at any time (s), from its coefficients: ``phi`` and the
    hull exactly (trigonometric sums), the torque and the bearing load from (P)."""

    def __init__(self, problem: HullProblem, x, y):
        cs = problem.case
        self.case, self.x = cs, np.asarray(x, dtype=float)
        self.xi = problem.harmonics_of(y)

    def __call__(self, t) -> dict:
        cs, x, w = self.case, self.x, self.case.omega
        t = np.atleast_1d(np.asarray(t, dtype=float))
        s = w * t
        n = cs.harmonics
        k = np.arange(1, n + 1)
        sn, cn = np.sin(np.outer(s, k)), np.cos(np.outer(s, k))
        a, b = x[1:n + 1], x[n + 1:]
        phi = cs.winding * s + x[0] + sn @ a + cn @ b
        phi1 = w * (cs.winding + (cn * k) @ a - (sn * k) @ b)
        phi2 = -w**2 * ((sn * k**2) @ a + (cn * k**2) @ b)
        kh = np.arange(1, cs.hull_harmonics + 1)
        e = np.exp(1j * np.outer(s, kh))
        xi = (self.xi[0].real + (e @ self.xi[1:]).real).T
        xi1 = (e @ (1j * w * kh[:, None] * self.xi[1:])).real.T
        xi2 = (e @ (-(w * kh[:, None]) ** 2 * self.xi[1:])).real.T
        g = cs.G
        p2 = g @ xi2
        ml = cs.m * cs.l
        sp, cp = np.sin(phi), np.cos(phi)
        v = phi1 - xi1[2]
        tau = cs.I * phi2 + cs.c * v - ml * ((cs.g + p2[1]) * sp - p2[0] * cp)
        # the bearing's load: the pendulum's mass times its centre's acceleration, plus its
        # weight (the force the pivot applies to the pendulum)
        fx = cs.m * p2[0] + ml * (cp * phi2 - sp * phi1**2)
        fz = cs.m * p2[1] - ml * (sp * phi2 + cp * phi1**2) + cs.m * cs.g
        return {"t": t, "phi": phi, "phi_dot": phi1, "xi": xi, "xi_dot": xi1, "tau": tau,
                "relative_speed": v, "power": -tau * v, "pivot_force": np.hypot(fx, fz)}


def peak(fun, period: float, points: int = PEAK_POINTS) -> float:
    """The largest value of the periodic ``fun(t)`` (vectorized): located on ``points``
    samples, then refined between the neighbours of the largest by Brent's method."""
    t = period * np.arange(points) / points
    v = fun(t)
    i = int(np.argmax(v))
    h = period / points
    r = minimize_scalar(lambda s: -float(fun(np.array([s]))[0]),
                        bounds=(t[i] - h, t[i] + h), method="bounded",
                        options={"xatol": 1e-12 * period})
    return max(float(v[i]), -float(r.fun))


@dataclass(frozen=True, eq=False, repr=False)
class HullResult(Result):
    """The optimum of a pendulum in a hull that surges, heaves and pitches (SI; field names
    are the JSON keys of ``parapend buoy --dofs surge,heave,pitch``).

    Attributes
    ----------
    power_w : the best mode's mean power: the mechanical ``P = -<tau (phi' - beta')>``
        with an ideal power take-off; with ``efficiency`` (``[eta_g, eta_m]``) the
        electrical ``<e(p)>`` (``eta_g p`` generating, ``p / eta_m`` motoring, ``p`` the
        instantaneous mechanical power), less ``copper_loss_w_per_nm2`` times ``<tau^2>``.
    mechanical_power_w : the mechanical power ``P`` of that motion (= power_w ideal).
    torque_limit_nm : ``|tau|`` held below it on the solve grid (its peak between the grid
        points checked, ``TORQUE_SLACK``).
    mode : ``"rotation"``, ``"swinging"`` or ``"rest"`` (the pendulum held: 0 W) - the
        best; ``winding`` its turns per wave (0: swinging).
    modes : each mode's answer side by side (power, one-way power, mean angle, peak torque,
        status, the search's evidence).
    one_way_power_w : the best mode's optimum with the hull moving as if the pendulum were
        not there; one_way_ratio : ``one_way_power_w / power_w``.
    energy_balance_residual
        The relative residual of the energy balance ``P + c <(phi' - beta')^2> =
        sum_k Re((F a)_k^H U_k) / 2 - U_k^H B_k U_k / 2`` (below 1e-9 when the solve is
        right).
    radiation_bound_w : ``sum_k (F a)_k^H B_k^+ (F a)_k / 8``, singular values of ``B_k``
        below ``bound_rcond`` of the largest cut (``bound_cut`` of them); bound_fraction.
    surge_amplitude_m, heave_amplitude_m, pitch_amplitude_deg : half the peak-to-peak hull
        motion; surge_phase_deg, heave_phase_deg, pitch_phase_deg: the phase of its first
        harmonic against the wave's elevation at O (regular waves); mean_heel_deg : the mean
        pitch (the mean generator torque heels the hull).
    mean_angle_deg : the pendulum's mean absolute angle from the upward vertical (180:
        hanging); swing_amplitude_deg : half its peak-to-peak swing (swinging only).
    peak_torque_nm, peak_pivot_force_n : largest ``|tau|`` and bearing load over the motion
        (located on the motion itself, between samples).
    harmonics, hull_harmonics : of the answer; refinement_change_w : the power's change
        from the answer with half as many (the stated discretization error).
    """

    power_w: float
    mechanical_power_w: float
    efficiency: list | None
    copper_loss_w_per_nm2: float
    torque_limit_nm: float | None
    mode: str
    winding: int
    modes: list
    one_way_power_w: float | None
    one_way_ratio: float | None
    energy_balance_residual: float | None
    radiation_bound_w: float
    bound_fraction: float | None
    bound_rcond: float
    bound_cut: int
    capture_width_m: float | None
    energy_flux_w_per_m: float
    surge_amplitude_m: float
    heave_amplitude_m: float
    pitch_amplitude_deg: float
    surge_phase_deg: float | None
    heave_phase_deg: float | None
    pitch_phase_deg: float | None
    mean_heel_deg: float
    mean_angle_deg: float | None
    swing_amplitude_deg: float | None
    peak_torque_nm: float
    peak_pivot_force_n: float
    harmonics: int
    hull_harmonics: int
    refinement_change_w: float | None
    success: bool
    status: str
    dofs: list
    wave: dict
    pendulum: dict
    body: dict
    pivot: dict
    warnings: list
    validity_warnings: list
    _motion: object = field(default=None, repr=False)

    command = "buoy"
    headline = ("power_w", "mode", "one_way_power_w", "radiation_bound_w", "status")

    @property
    def motion(self):
        """The best mode's motion at any time: a callable ``t -> dict`` (s; None at
        rest)."""
        return self._motion

    def samples(self, points: int = 801) -> dict:
        """One period of the best mode's motion (the hull at rest when the mode is rest)."""
        period = 2 * math.pi / float(self.wave["omega_rad_per_s"])
        t = period * np.arange(points) / (points - 1)
        if self._motion is None:
            z = np.zeros_like(t)
            return {"t": t, "phi": z + math.pi, "phi_dot": z, "xi": np.zeros((3, t.size)),
                    "tau": z, "power": z, "pivot_force": z, "relative_speed": z}
        return self._motion(t)

    def _series(self):
        import xarray as xr

        s = self.samples()
        cols = {"phi": s["phi"], "theta": s["phi"] - s["xi"][2], "torque_nm": s["tau"],
                "instantaneous_power_w": s["power"], "surge_m": s["xi"][0],
                "heave_m": s["xi"][1], "pitch_deg": np.degrees(s["xi"][2]),
                "pivot_force_n": s["pivot_force"]}
        return xr.Dataset({k: ("time_s", np.asarray(v, float)) for k, v in cols.items()},
                          coords={"time_s": s["t"]})

    def to_dict(self) -> dict:
        return super().to_dict()

    def _figure(self):
        from .figures import plot_hull

        return plot_hull(self)


def _deg(v) -> float:
    return float(np.degrees(v))


def _mode(sol) -> dict:
    pr = HullProblem(sol.case)
    y = pr.solve_hull(sol.x)
    mot = MotionAt(pr, sol.x, y)
    period = 2 * math.pi / sol.case.omega
    pk = peak(lambda t: np.abs(mot(t)["tau"]), period)
    status, ok = sol.status, sol.success
    limit = sol.pto.torque_limit
    if limit is not None and math.isfinite(sol.power) and pk > limit * (1 + 1e-12):
        # the limit is imposed on the solve grid: checked between its points
        over = pk / limit - 1
        ok = ok and over <= TORQUE_SLACK
        status += (f"; between the grid points the peak torque is {pk:.6g} N m "
                   f"({over:.1e} above the limit)")
    s = mot(period * np.arange(PEAK_POINTS) / PEAK_POINTS)
    k = sol.case.winding
    swing = None if k else 0.5 * _deg(np.max(s["phi"]) - np.min(s["phi"]))
    mean = _deg(math.remainder(float(np.mean(s["phi"])) - math.pi, 2 * math.pi) + math.pi)
    return {"mode": "swinging" if k == 0 else "rotation", "winding": k,
            "power_w": sol.power, "mechanical_power_w": (
                sol.power if sol.mechanical_power is None else sol.mechanical_power),
            "one_way_power_w": sol.one_way_power,
            "energy_balance_residual": sol.energy_balance_residual,
            "refinement_change_w": sol.refinement_change, "harmonics": sol.case.harmonics,
            "mean_angle_deg": mean if k == 0 else None, "swing_amplitude_deg": swing,
            "peak_torque_nm": pk, "distinct_maxima": sol.distinct_maxima,
            "found_by": sol.found_by, "starts": sol.runs, "success": ok,
            "status": status, "_solution": sol, "_motion": mot}


def _solve_mode(hull, pendulum, wave, k, harmonics, pivot, pitch_inertia, pto) -> dict:
    def make(scale):
        base = make_case(hull, pendulum, wave, winding=k, harmonics=harmonics, pivot=pivot,
                         pitch_inertia=pitch_inertia)
        if scale == 1:
            return base
        return make_case(hull, pendulum, wave, winding=k, harmonics=scale * base.harmonics,
                         hull_harmonics=scale * base.hull_harmonics, pivot=pivot,
                         pitch_inertia=pitch_inertia)
    return _mode(hull_search(make, pto=pto))


def hull_answer(hull, pendulum, wave, *, pivot, windings=(1, 0), pitch_inertia=None,
                harmonics=None, wave_info=None, geometry=None, notes=(),
                pto: HullPTO | None = None) -> HullResult:
    """Solve each winding of ``windings`` (0: swinging), put them beside rest, and build
    the result from the best; ``pto`` the power take-off (None: ideal)."""
    pto = pto or HullPTO()
    from threadpoolctl import threadpool_limits

    modes = []
    # small dense matrices (a few hundred): BLAS threads cost more than they save
    with threadpool_limits(1, user_api="blas"):
        for k in windings:
            modes.append(_solve_mode(hull, pendulum, wave, k, harmonics, pivot,
                                     pitch_inertia, pto))
    ok_modes = [m for m in modes if m["success"]]
    best = max(ok_modes or modes, key=lambda m: m["power_w"])
    rest = {"mode": "rest", "winding": None, "power_w": 0.0, "mechanical_power_w": 0.0,
            "success": True, "status": "the pendulum held (no power)"}
    public = [{k: v for k, v in m.items() if not k.startswith("_")} for m in modes] + [rest]
    sol = best["_solution"]
    cs = sol.case
    at_rest = best["power_w"] <= 0 and len(windings) > 1
    mot = None if at_rest else best["_motion"]
    period = 2 * math.pi / wave.omega
    s = (mot or best["_motion"])(period * np.arange(PEAK_POINTS) / PEAK_POINTS)
    xi1 = best["_motion"].xi[1] if not at_rest else np.zeros(3)
    amps = np.asarray(wave.amplitudes)
    regular = amps.size == 1
    def ph(z):
        return (_deg(np.angle(z / amps[0])) if regular and abs(z) > 0 else None)
    def half(v):
        return (0.0 if at_rest else 0.5 * float(np.max(v) - np.min(v)))
    bound, cut = radiation_bound(cs)
    flux = energy_flux(wave.omega, amps, hull.rho, hull.g, hull.water_depth)
    p = 0.0 if at_rest else float(best["power_w"])
    pitch_amp = _deg(half(s["xi"][2]))
    validity = []
    peak_pitch = 0.0 if at_rest else _deg(np.max(np.abs(s["xi"][2])))
    if peak_pitch > PITCH_VALIDITY_DEG:
        validity.append(f"linear theory: the pitch reaches {peak_pitch:.3g} degrees, beyond "
                        f"about {PITCH_VALIDITY_DEG:g}; the answer is outside its validity")
    if geometry is not None and not at_rest:
        d = geometry.get("draft_m")
        half_len = geometry.get("half_length_m", 0.0)
        ends = np.abs(s["xi"][1]) + half_len * np.abs(np.sin(s["xi"][2]))
        if d is not None and float(np.max(ends)) > d:
            validity.append(f"linear theory: the hull's heave and pitch move its ends by up "
                            f"to {float(np.max(ends)):.3g} m, more than its draft {d:.3g} m")
    warnings = list(getattr(hull, "notes", ())) + list(notes) + [
        f"{m['mode']}: {m['status']}" for m in modes if not m["success"]]
    if cut:
        warnings.append(f"radiation bound: {cut} singular value(s) of B below "
                        f"{BOUND_RCOND:g} of the largest cut in its pseudo-inverse")
    owp = None if at_rest else best["one_way_power_w"]
    return HullResult(
        power_w=p, mechanical_power_w=0.0 if at_rest else float(best["mechanical_power_w"]),
        efficiency=list(pto.efficiency) if pto.efficiency is not None else None,
        copper_loss_w_per_nm2=pto.copper_loss, torque_limit_nm=pto.torque_limit,
        mode="rest" if at_rest else best["mode"],
        winding=None if at_rest else best["winding"], modes=public,
        one_way_power_w=owp, one_way_ratio=(owp / p if owp is not None and p > 0 else None),
        energy_balance_residual=None if at_rest else best["energy_balance_residual"],
        radiation_bound_w=bound, bound_fraction=(p / bound if bound > 0 else None),
        bound_rcond=BOUND_RCOND, bound_cut=cut,
        capture_width_m=(p / flux if flux > 0 else None), energy_flux_w_per_m=flux,
        surge_amplitude_m=half(s["xi"][0]), heave_amplitude_m=half(s["xi"][1]),
        pitch_amplitude_deg=pitch_amp, surge_phase_deg=ph(xi1[0]),
        heave_phase_deg=ph(xi1[1]), pitch_phase_deg=ph(xi1[2]),
        mean_heel_deg=0.0 if at_rest else _deg(best["_motion"].xi[0, 2].real),
        mean_angle_deg=None if at_rest else best["mean_angle_deg"],
        swing_amplitude_deg=None if at_rest else best["swing_amplitude_deg"],
        peak_torque_nm=0.0 if at_rest else best["peak_torque_nm"],
        peak_pivot_force_n=peak(lambda t: (mot or best["_motion"])(t)["pivot_force"],
                                period) if not at_rest else pendulum.mass * hull.g,
        harmonics=cs.harmonics, hull_harmonics=cs.hull_harmonics,
        refinement_change_w=None if at_rest else best["refinement_change_w"],
        success=all(m["success"] for m in modes),
        status="; ".join(f"{m['mode']}: {m['status']}" for m in modes),
        dofs=["surge", "heave", "pitch"], wave=dict(wave_info or {},
                                                    omega_rad_per_s=wave.omega),
        pendulum={"mass_kg": pendulum.mass, "length_m": pendulum.length,
                  "inertia_kg_m2": pendulum.inertia,
                  "damping_coefficient": pendulum.damping_coefficient},
        body=dict(geometry or {}, description=getattr(hull, "description", "")),
        pivot={"pivot_offset_m": cs.pivot[0], "pivot_height_m": cs.pivot[1]},
        warnings=warnings, validity_warnings=validity, _motion=mot)


@dataclass(frozen=True, eq=False, repr=False)
class HullSweepResult(Result):
    """Rotation against swinging over wave periods (regular waves of one height): arrays
    over ``period_s``; ``mode`` the best per period; each :class:`HullResult` in
    ``results``."""

    period_s: np.ndarray
    power_w: np.ndarray
    mechanical_power_w: np.ndarray
    rotation_power_w: np.ndarray
    swinging_power_w: np.ndarray
    one_way_power_w: np.ndarray
    radiation_bound_w: np.ndarray
    heave_amplitude_m: np.ndarray
    pitch_amplitude_deg: np.ndarray
    energy_balance_residual: np.ndarray
    mode: list
    status: list
    success: bool
    wave_height_m: float
    pendulum: dict
    body: dict
    pivot: dict
    warnings: list
    _results: tuple = field(default=(), repr=False)

    command = "buoy"
    headline = ("period_s", "power_w", "success")

    @property
    def results(self) -> tuple:
        """Each period's :class:`HullResult`."""
        return self._results

    @classmethod
    def from_results(cls, periods, results, height) -> HullSweepResult:
        def arr(name):
            return np.array([np.nan if getattr(r, name) is None else getattr(r, name)
                             for r in results], dtype=float)

        def mode_power(r, mode):
            return next((m["power_w"] for m in r.modes if m["mode"] == mode), np.nan)

        warn = [f"T = {t:g} s: {w}" for t, r in zip(periods, results)
                for w in list(r.warnings) + list(r.validity_warnings)]
        return cls(period_s=np.asarray(periods, dtype=float), power_w=arr("power_w"),
                   mechanical_power_w=arr("mechanical_power_w"),
                   rotation_power_w=np.array([mode_power(r, "rotation") for r in results]),
                   swinging_power_w=np.array([mode_power(r, "swinging") for r in results]),
                   one_way_power_w=arr("one_way_power_w"),
                   radiation_bound_w=arr("radiation_bound_w"),
                   heave_amplitude_m=arr("heave_amplitude_m"),
                   pitch_amplitude_deg=arr("pitch_amplitude_deg"),
                   energy_balance_residual=arr("energy_balance_residual"),
                   mode=[r.mode for r in results], status=[r.status for r in results],
                   success=all(r.success for r in results), wave_height_m=float(height),
                   pendulum=results[0].pendulum, body=results[0].body,
                   pivot=results[0].pivot, warnings=warn, _results=tuple(results))

    def _series(self):
        import xarray as xr

        names = ("power_w", "mechanical_power_w", "rotation_power_w", "swinging_power_w",
                 "one_way_power_w", "radiation_bound_w", "heave_amplitude_m", "pitch_amplitude_deg",
                 "energy_balance_residual")
        ds = xr.Dataset({k: ("period_s", np.asarray(getattr(self, k), dtype=float))
                         for k in names}, coords={"period_s": self.period_s})
        ds["mode"] = ("period_s", np.asarray(self.mode, dtype=str))
        return ds

    def _figure(self):
        from .figures import plot_hull_sweep

        return plot_hull_sweep(self)

    def __repr__(self) -> str:
        p = np.asarray(self.period_s, dtype=float)
        return (f"HullSweepResult(period_s: {p.size} periods from {p[0]:.6g} to {p[-1]:.6g}, "
                f"largest power_w={np.nanmax(self.power_w):.6g}, success={self.success!r})")
