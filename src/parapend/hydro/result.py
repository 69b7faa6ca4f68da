"""The floating body's results and one wave's answer, for every degree-of-freedom set:
:class:`BuoyResult` (one wave, or one periodic record) and :class:`BuoySweepResult` (power
against wave period), one type each whatever the body's DOFs; :func:`optimum`, the one
function of the coupled optimum, which dispatches on the coefficients' DOFs to the heaving
buoy's kernel (:func:`_solve`: the coupled optimum and the one-way one; :func:`_result`:
what a designer reads) or to the hull's (:func:`hull_answer`: rotation, swinging and rest
side by side). :mod:`.api` (the command), :mod:`.design` (sweeps, the design search) and
:mod:`.control` (receding-horizon control) all build their answers from here.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from ..results import _Result
from ..seas import BREAKING_STEEPNESS, STEEP_WARNING, sea_steepness_warning  # noqa: F401
from . import _hull_krylov  # also registers the hull's matrix-free solver
from .hull import (
    BOUND_RCOND,
    HullProblem,
    HullPTO,
    bound_error,
    hold_limit,
    hull_search,
    ideal_problem,
    make_case,
    radiation_bound,
)
from .optimum import TORQUE_SLACK
from .waves import energy_flux

__all__ = ["BuoyResult", "BuoySweepResult", "MotionAt", "error_estimate", "free_heave",
           "best_label", "hull_answer", "mode_label", "optimum"]


#: the JSON keys of a heave-only answer (a buoy), in their order
HEAVE_KEYS = ("power_w", "heave_amplitude_m", "peak_torque_nm", "radiation_bound_w",
              "bound_fraction", "limit_w", "capture_width_m", "capture_width_ratio",
              "energy_flux_w_per_m", "one_way_power_w", "one_way_ratio", "free_heave_amplitude_m",
              "energy_balance_residual", "harmonics", "winding", "success", "status", "message",
              "wave", "pendulum", "body", "torque_limit_nm", "efficiency", "design", "warnings",
              "electrical_power_w", "mechanical_power_w", "pto_loss_w", "generated_power_w",
              "motoring_power_w", "ideal_power_w", "one_way_electrical_power_w", "mesh_error_w",
              "mesh_error_relative", "grid_error_w", "validity_warnings")
#: a hull's sea state over seeded realizations (``realizations``; None otherwise):
#: ``parapend.hydro.realizations``
REALIZATION_KEYS = ("realizations", "realizations_solved", "realization_seeds",
                    "realization_powers_w", "realization_reasons",
                    "realization_peak_torques_nm", "realization_peak_pivot_forces_n",
                    "mean_power_w", "power_std_w", "power_ci_w", "power_ci_half_width_w",
                    "power_ci_method")
#: the JSON keys of an answer in surge, heave and pitch (a hull), in their order
HULL_KEYS = ("power_w", "headline_reason", "mechanical_power_w", "efficiency",
             "copper_loss_w_per_nm2", "torque_limit_nm", "mode", "winding", "modes", "maxima",
             "maxima_powers_w", "one_way_power_w", "one_way_ratio",
             "energy_balance_residual", "radiation_bound_w", "bound_fraction", "bound_rcond",
             "bound_cut", "bound_error_w", "capture_width_limit_w", "capture_width_m",
             "energy_flux_w_per_m",
             "surge_amplitude_m",
             "heave_amplitude_m", "pitch_amplitude_deg", "surge_phase_deg", "heave_phase_deg",
             "pitch_phase_deg", "mean_heel_deg", "mean_angle_deg", "swing_amplitude_deg",
             "peak_torque_nm", "peak_pivot_force_n", "harmonics", "hull_harmonics",
             "refinement_change_w", "discretization_error_estimate_w", "refinement_history",
             "success", "status", "dofs", "wave", "pendulum", "body", "pivot", "warnings",
             "validity_warnings", *REALIZATION_KEYS)
#: the same of a period sweep
HEAVE_SWEEP_KEYS = ("period_s", "power_w", "one_way_power_w", "radiation_bound_w", "limit_w",
                    "bound_fraction", "capture_width_m", "heave_amplitude_m",
                    "free_heave_amplitude_m", "energy_balance_residual", "status", "success",
                    "wave_height_m", "pendulum", "body", "warnings", "electrical_power_w",
                    "mechanical_power_w", "mesh_error_w", "validity_warnings", "grid_error_w")
HULL_SWEEP_KEYS = ("period_s", "power_w", "headline_reason", "mechanical_power_w",
                   "rotation_power_w", "rotation_winding", "swinging_power_w",
                   "one_way_power_w", "radiation_bound_w",
                   "heave_amplitude_m", "pitch_amplitude_deg", "energy_balance_residual", "mode",
                   "status", "success", "wave_height_m", "pendulum", "body", "pivot", "warnings")


#: the fields' types (the others: ``float | None``), of one answer and of a sweep
_TYPES = {**dict.fromkeys(("harmonics", "winding", "bound_cut", "hull_harmonics", "maxima",
                           "realizations", "realizations_solved"), "int | None"),
          **dict.fromkeys(("status", "message", "mode", "headline_reason", "power_ci_method"),
                          "str | None"),
          **dict.fromkeys(("realization_seeds", "realization_powers_w", "realization_reasons",
                           "realization_peak_torques_nm", "realization_peak_pivot_forces_n",
                           "power_ci_w", "refinement_history"), "list | None"),
          **dict.fromkeys(("wave", "pendulum", "body", "design", "pivot"), "dict | None"),
          **dict.fromkeys(("efficiency", "modes", "maxima_powers_w"), "list | None"),
          "success": "bool | None"}
_SWEEP_TYPES = {**dict.fromkeys(("status", "mode", "rotation_winding"), "list | None"),
                **dict.fromkeys(("pendulum", "body", "pivot"), "dict | None"),
                "success": "bool | None", "wave_height_m": "float | None"}


def _union_fields(*key_sets, types, default="float | None"):
    """Class decorator (before :func:`dataclasses.dataclass`): the public fields of a result
    of several DOF sets are the union of their JSON keys, in order, each None by default
    (``warnings``, ``validity_warnings``: an empty list; ``dofs``: ``["heave"]``), typed by
    ``types``, else ``default`` (a sweep's: ``np.ndarray | None``); the class's own
    annotated fields (its private ones) follow."""

    def add(cls):
        names = list(dict.fromkeys(k for keys in key_sets for k in keys))
        public = {}
        for name in names:
            if name in ("warnings", "validity_warnings", "dofs"):
                public[name] = "list"
                setattr(cls, name, field(default_factory=(
                    (lambda: ["heave"]) if name == "dofs" else list)))
            else:
                public[name] = types.get(name, default)
                setattr(cls, name, None)
        cls.__annotations__ = {**public, **cls.__dict__.get("__annotations__", {})}
        return cls
    return add


def _heave_only(dofs) -> bool:
    return tuple(dofs) == ("heave",)


@dataclass(frozen=True, eq=False, repr=False)
@_union_fields(HEAVE_KEYS, HULL_KEYS, types=_TYPES)
class BuoyResult(_Result):
    """The coupled optimum of a pendulum in a floating body, for its degrees of freedom
    ``dofs`` (``["heave"]``: the heaving buoy; ``["surge", "heave", "pitch"]``: a hull), in
    one wave or one periodic record (field names = JSON keys of ``parapend buoy``; SI units,
    named in each field). The JSON holds the fields of its DOF set (``HEAVE_KEYS``,
    ``HULL_KEYS``); the others are None.

    Attributes
    ----------
    dofs : the body's degrees of freedom (in the JSON of a hull).

    Heave alone (the buoy):

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

    Surge, heave and pitch (a hull):

    power_w : the best mode's mean power: the mechanical ``P = -<tau (phi' - beta')>``
        with an ideal power take-off; with ``efficiency`` (``[eta_g, eta_m]``) the
        electrical ``<e(p)>`` (``eta_g p`` generating, ``p / eta_m`` motoring, ``p`` the
        instantaneous mechanical power), less ``copper_loss_w_per_nm2`` times ``<tau^2>``.
        An answer only when resolved and plausible: the best mode's search converged, the
        power at most the radiation bound, at least rest's 0 W (rest is the answer when no
        motion beats it); otherwise None, with the reason in ``headline_reason`` (the
        command exits with status 3).
    headline_reason : why ``power_w`` is None (None when it is the answer).
    maxima, maxima_powers_w : the count and the powers (W) of the distinct local maxima the
        search found, over the modes (each mode's also in ``modes``).
    capture_width_limit_w : ``sum_k J_k 3 lambda_k / (2 pi)``: a body moving in surge, heave
        and pitch absorbs at most the power of a crest that wide (heave ``lambda / (2 pi)``,
        surge and pitch together ``lambda / pi``); beside the radiation bound, which uses the
        body's own coefficients.
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
    radiation_bound_w : ``sum_k (F a)_k^H B_k^+ (F a)_k / 8`` of these coefficients (a
        mesh's or a dataset's: it moves with the mesh, and a warning says when it exceeds
        the capture-width limit, which does not), singular values of ``B_k``
        below ``bound_rcond`` of the largest cut (``bound_cut`` of them): ``bound_rcond`` is
        the data's noise (``HullHydro.damping_noise``: B's asymmetry or its negative part
        set to 0, relative to its largest entry), at least 1e-8; bound_fraction.
    bound_error_w : the bound's error from that noise, to first order (each kept term's
        ``noise sigma_max / sigma_i`` of itself, at most all of it): the data's stated
        error, not the mesh's (a BEM's asymmetry underestimates that; docs/hull.md).
    surge_amplitude_m, heave_amplitude_m, pitch_amplitude_deg : half the peak-to-peak hull
        motion; surge_phase_deg, heave_phase_deg, pitch_phase_deg: the phase of its first
        harmonic against the wave's elevation at O (regular waves); mean_heel_deg : the mean
        pitch (the mean generator torque heels the hull).
    mean_angle_deg : the pendulum's mean absolute angle from the upward vertical (180:
        hanging); swing_amplitude_deg : half its peak-to-peak swing (swinging only).
    peak_torque_nm, peak_pivot_force_n : largest ``|tau|`` and bearing load over the motion
        (located on the motion itself, between samples).
    harmonics, hull_harmonics : of the answer; refinement_change_w : the power's change
        from the answer with half as many (the last doubling's change); refinement_history:
        ``[harmonics, power_w]`` of each stage of the doubling, coarsest first.
    discretization_error_estimate_w : the stated discretization error
        (``error_estimate``): an estimate from the doublings (the last change, or its
        geometric tail where the changes shrink slowly), not a proven bound; None where the
        changes do not shrink. It covers the discretization of the maximum found, not
        another maximum a search at other harmonics may find.
    realizations : a sea state over ``R`` seeded records (``buoy(realizations=R)``,
        ``parapend.hydro.realizations``; None: one record): ``realization_seeds``,
        ``realization_powers_w`` (NaN/null: no resolved answer, ``realization_reasons``
        says why), ``realization_peak_torques_nm``, ``realization_peak_pivot_forces_n``;
        ``mean_power_w`` over the ``realizations_solved`` resolved ones, ``power_std_w``
        (ddof 1), ``power_ci_w`` its 95 % interval ``[low, high]`` and
        ``power_ci_half_width_w`` (``power_ci_method``: Student's t with ``R - 1``
        degrees of freedom); the other fields are the first record's (seed ``seed``).
    """

    _solution: object = field(default=None, repr=False)
    _one_way: object = field(default=None, repr=False)
    _hydro: object = field(default=None, repr=False)
    _wave: object = field(default=None, repr=False)
    _motion: object = field(default=None, repr=False)

    command = "buoy"

    @property
    def headline(self) -> tuple:
        """The fields the repr shows."""
        if _heave_only(self.dofs):
            return ("power_w", "electrical_power_w", "one_way_power_w", "radiation_bound_w",
                    "heave_amplitude_m", "status")
        if self.realizations is not None:
            return ("mean_power_w", "power_ci_w", "realizations", "power_w", "status")
        return ("power_w", "mode", "one_way_power_w", "radiation_bound_w", "status")

    def to_dict(self) -> dict:
        d = super().to_dict()
        return {k: d[k] for k in (HEAVE_KEYS if _heave_only(self.dofs) else HULL_KEYS)}

    def to_dataset(self):
        """The result's Dataset; over several realizations also each one's power, peak
        torque and bearing load over ``realization`` (its ``seed`` a coordinate)."""
        ds = super().to_dataset()
        if self.realizations is None:
            return ds
        n = len(self.realization_seeds)
        ds = ds.assign_coords(realization=("realization", list(range(n)),
                                           {"long_name": "realization"}),
                              seed=("realization", list(self.realization_seeds),
                                    {"long_name": "seed of the record's phases"}))
        for name, long in (("realization_powers_w", "the record's optimum power (NaN: no "
                                                    "resolved answer)"),
                           ("realization_peak_torques_nm", "the record's peak torque"),
                           ("realization_peak_pivot_forces_n", "the record's peak bearing "
                                                               "load")):
            ds.attrs.pop(name, None)
            unit = {"w": "W", "nm": "N m", "n": "N"}[name.rsplit("_", 1)[1]]
            ds[name] = ("realization", [math.nan if v is None else float(v)
                                        for v in getattr(self, name)],
                        {"units": unit, "long_name": long})
        if self.power_ci_w is not None:
            ds.attrs.pop("power_ci_w", None)
            ds["power_ci_low_w"] = ((), self.power_ci_w[0], {
                "units": "W", "long_name": "lower end of the mean power's 95 % t-interval"})
            ds["power_ci_high_w"] = ((), self.power_ci_w[1], {
                "units": "W", "long_name": "upper end of the mean power's 95 % t-interval"})
        return ds

    def _csv_text(self) -> str:
        """``save("x.csv")``: over several realizations the records' table (seed, power,
        peaks); else the motion over one period."""
        if self.realizations is None:
            return super()._csv_text()
        from ..results import dataset_csv

        ds = self.to_dataset()
        return dataset_csv(ds[[n for n in ("realization_powers_w",
                                           "realization_peak_torques_nm",
                                           "realization_peak_pivot_forces_n")]]
                           .reset_coords().set_coords([]))

    @property
    def solution(self):
        """The coupled optimum (heave alone: :class:`parapend.hydro.optimum.CoupledSolution`;
        a hull: None, its modes' in ``modes``)."""
        return self._solution

    @property
    def hydrodynamics(self):
        """The body's hydrodynamic coefficients the optimum was solved with
        (:class:`parapend.hydro.bem.Hydro`, or a hull's
        :class:`~parapend.hydro.bem.HullHydro`)."""
        return self._hydro

    @property
    def incident_wave(self):
        """The incident wave (regular or a periodic record) the optimum was solved for."""
        return self._wave

    @property
    def motion(self):
        """A hull's best mode's motion at any time: a callable ``t -> dict`` (s; None at
        rest, and for the heaving buoy, whose motion is :meth:`samples`)."""
        return self._motion

    def samples(self, points: int | None = None) -> dict:
        """One period on a uniform grid. Heave alone (400 points): ``t`` (s), ``theta``
        (rad), ``theta_dot`` (rad/s), ``z`` (m), ``z_dot`` (m/s), ``tau`` (N m), ``power``
        (``-tau theta'``, W) of the coupled optimum, and ``z_free`` (m), the free buoy's
        heave. A hull (801 points): its best mode's motion (the hull at rest when the mode
        is rest)."""
        if _heave_only(self.dofs):
            return self._heave_samples(400 if points is None else points)
        return self._hull_samples(801 if points is None else points)

    def _heave_samples(self, points: int) -> dict:
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

    def _hull_samples(self, points: int) -> dict:
        """One period of the best mode's motion (the hull at rest when the mode is rest)."""
        period = 2 * math.pi / float(self.wave["omega_rad_per_s"])
        t = period * np.arange(points) / (points - 1)
        if self._motion is None:
            z = np.zeros_like(t)
            return {"t": t, "phi": z + math.pi, "phi_dot": z, "xi": np.zeros((3, t.size)),
                    "tau": z, "power": z, "pivot_force": z, "relative_speed": z}
        return self._motion(t)

    def _series(self):
        """The motion over one period (SI): what ``--save`` writes beside the scalars."""
        return self._heave_series() if _heave_only(self.dofs) else self._hull_series()

    def _heave_series(self):
        """The motion over one period (SI): what ``--save`` writes beside the scalars."""
        import xarray as xr

        s = self.samples()
        names = {"theta": "theta", "theta_dot": "theta_dot_rad_per_s", "z": "heave_m",
                 "z_dot": "heave_speed_m_per_s", "tau": "torque_nm",
                 "power": "instantaneous_power_w", "z_free": "free_heave_m"}
        return xr.Dataset({names[k]: ("time_s", s[k]) for k in names},
                          coords={"time_s": s["t"]})

    def _hull_series(self):
        import xarray as xr

        s = self.samples()
        cols = {"phi": s["phi"], "theta": s["phi"] - s["xi"][2], "torque_nm": s["tau"],
                "instantaneous_power_w": s["power"], "surge_m": s["xi"][0],
                "heave_m": s["xi"][1], "pitch_deg": np.degrees(s["xi"][2]),
                "pivot_force_n": s["pivot_force"]}
        return xr.Dataset({k: ("time_s", np.asarray(v, float)) for k, v in cols.items()},
                          coords={"time_s": s["t"]})

    def _figure(self):
        from .figures import plot_hull, plot_motion

        return plot_motion(self) if _heave_only(self.dofs) else plot_hull(self)


@dataclass(frozen=True, eq=False, repr=False)
@_union_fields(HEAVE_SWEEP_KEYS, HULL_SWEEP_KEYS, ("dofs",), types=_SWEEP_TYPES,
               default="np.ndarray | None")
class BuoySweepResult(_Result):
    """Power of one design against wave period (``wave_period="FROM:TO:N"`` or a list),
    regular waves of one height, for the body's degrees of freedom ``dofs``: arrays over
    ``period_s``, each field named with its unit; the JSON holds the fields of its DOF set
    (``HEAVE_SWEEP_KEYS``, ``HULL_SWEEP_KEYS``). Every period is solved on the same
    mesh and frequencies as alone (:class:`BuoyResult`: the same numbers).

    A hull's ``headline_reason`` is each period's (None where its power is the answer):
    a period without a resolved answer makes the command exit with status 3, as alone.
    Heave alone: ``electrical_power_w`` with an efficiency, else None; ``mesh_error_w``,
    ``grid_error_w`` and ``validity_warnings`` are those of each period (the warnings
    prefixed with the period). A hull: rotation against swinging, ``mode`` the best per
    period; each period's :class:`BuoyResult` in :attr:`results`."""

    _results: tuple = field(default=(), repr=False)

    command = "buoy"
    headline = ("period_s", "power_w", "success")

    def to_dict(self) -> dict:
        d = super().to_dict()
        keys = HEAVE_SWEEP_KEYS if _heave_only(self.dofs) else HULL_SWEEP_KEYS
        return {k: d[k] for k in keys}

    @property
    def results(self) -> tuple:
        """Each period's :class:`BuoyResult` (a hull's sweep)."""
        return self._results

    @classmethod
    def from_results(cls, periods, results, height) -> BuoySweepResult:
        """A hull's sweep from each period's result; periods past ``results`` (a time limit
        stopped the sweep) NaN with the status ``"time_limit"``, and no success."""
        from ..deadline import TIME_LIMIT

        left = len(periods) - len(results)

        def arr(name):
            return np.array([np.nan if getattr(r, name) is None else getattr(r, name)
                             for r in results] + [np.nan] * left, dtype=float)

        def best_of(r, mode):
            # the better of the mode's answers (a hull's rotation: either sense): (power,
            # winding), (NaN, None) where none has a power
            ms = [m for m in r.modes if m["mode"] == mode and m["power_w"] is not None
                  and math.isfinite(m["power_w"])]
            if not ms:
                return np.nan, None
            m = max(ms, key=lambda m: m["power_w"])
            return m["power_w"], m["winding"]

        rot = [best_of(r, "rotation") for r in results]

        warn = [f"T = {t:g} s: {w}" for t, r in zip(periods, results)
                for w in list(r.warnings) + list(r.validity_warnings)]
        if left:
            warn.append(f"time limit reached: {len(results)} of {len(periods)} periods "
                        f"solved, the other {left} left out (NaN, status {TIME_LIMIT}); a "
                        "partial sweep")
        return cls(period_s=np.asarray(periods, dtype=float), power_w=arr("power_w"),
                   mechanical_power_w=arr("mechanical_power_w"),
                   rotation_power_w=np.array([p for p, _ in rot] + [np.nan] * left,
                                             dtype=float),
                   rotation_winding=[k for _, k in rot] + [None] * left,
                   swinging_power_w=np.array([best_of(r, "swinging")[0] for r in results]
                                             + [np.nan] * left, dtype=float),
                   one_way_power_w=arr("one_way_power_w"),
                   radiation_bound_w=arr("radiation_bound_w"),
                   heave_amplitude_m=arr("heave_amplitude_m"),
                   pitch_amplitude_deg=arr("pitch_amplitude_deg"),
                   energy_balance_residual=arr("energy_balance_residual"),
                   mode=[r.mode for r in results] + [None] * left,
                   status=[r.status for r in results] + [TIME_LIMIT] * left,
                   headline_reason=[r.headline_reason for r in results] + [None] * left,
                   success=not left and all(r.success for r in results),
                   wave_height_m=float(height),
                   pendulum=results[0].pendulum, body=results[0].body,
                   pivot=results[0].pivot, warnings=warn, _results=tuple(results),
                   dofs=list(results[0].dofs))

    def _series(self):
        """The sweep over ``period_s`` (what ``--save`` writes)."""
        return self._heave_series() if _heave_only(self.dofs) else self._hull_series()

    def _heave_series(self):
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

    def _hull_series(self):
        import xarray as xr

        names = ("power_w", "mechanical_power_w", "rotation_power_w", "swinging_power_w",
                 "one_way_power_w", "radiation_bound_w", "heave_amplitude_m", "pitch_amplitude_deg",
                 "energy_balance_residual")
        ds = xr.Dataset({k: ("period_s", np.asarray(getattr(self, k), dtype=float))
                         for k in names}, coords={"period_s": self.period_s})
        ds["mode"] = ("period_s", np.asarray(self.mode, dtype=str))
        # which way the better rotation turns: its winding (turns a wave; negative against
        # a positive pitch), 0 where none has a power
        ds["rotation_winding"] = ("period_s", np.asarray(
            [0 if k is None else int(k) for k in self.rotation_winding], dtype=np.int16), {
                "long_name": "winding of the better rotation (turns per wave; negative: "
                             "against a positive pitch; 0: no rotation solved)"})
        for name in ("status", "headline_reason"):  # each period's ("" where None)
            if getattr(self, name) is not None:
                ds[name] = ("period_s", np.asarray(["" if v is None else str(v)
                                                    for v in getattr(self, name)], dtype=str))
        return ds

    def _figure(self):
        from .figures import plot_hull_sweep, plot_sweep

        return plot_sweep(self) if _heave_only(self.dofs) else plot_hull_sweep(self)

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


def optimum(h, pendulum, wave, *, wave_info=None, winding=None, harmonics=None, pto=None,
            pivot=(0.0, 0.0), pitch_inertia=None, geometry=None, width=None, coarse=None,
            design=None, winding_search=False, winding_climb: int = 0) -> BuoyResult:
    """The coupled optimum of a pendulum in a floating body, for any of its degree-of-freedom
    sets: one wave or one periodic record, one :class:`BuoyResult`.

    Parameters
    ----------
    h : :class:`~parapend.hydro.bem.Hydro` or :class:`~parapend.hydro.bem.HullHydro`
        The body's coefficients; their ``dofs`` choose the kernel: heave alone, the heaving
        buoy's specialised kernel (:mod:`.coupled`, :func:`.optimum.coupled_optimum`: the
        heave is linear in ``cos(theta)``); surge, heave and pitch, the hull's
        (:mod:`.hull`). The hull's kernel with surge and pitch locked out gives the heave
        kernel's answer (to 3e-10, tests/test_hull_kernel.py).
    pendulum : :class:`~parapend.hydro.coupled.Pendulum`; wave : :class:`~.coupled.Wave`.
    wave_info : dict, the wave's description for the result.
    winding : turns of the pendulum per wave (per record); None: 1 in heave alone, a hull's
        rotation both ways (1, -1) and swinging (0) side by side; a tuple: those windings
        (a hull).
    harmonics : N of the motion (None: chosen from the problem).
    pto : :class:`~parapend.hydro.hull.HullPTO` (torque limit, N m; efficiency; copper loss,
        W per (N m)^2; heave alone has no copper loss) or None (ideal).
    pivot, pitch_inertia : a hull's pivot ``(offset, height)`` from O (m) and its pitch
        inertia about O without the pendulum (kg m^2; None: the data's, else a homogeneous
        hull's).
    geometry, width, coarse, design : the body's dimensions (validity checks), width (m,
        capture-width ratio), the body on the error estimate's coarser mesh (heave alone),
        and the design search's record, for the result.
    winding_search : a hull: also the windings between swinging and the largest of
        ``winding`` (:func:`hull_answer`'s ``search``).
    winding_climb : a hull: also the rotation's other turns, up to this many a record
        (:func:`hull_answer`'s ``climb``; 0: none).
    """
    from .hull import HullPTO

    pto = pto or HullPTO()
    if tuple(h.dofs) != ("heave",):
        windings = ((1, -1, 0) if winding is None else (winding,) if np.ndim(winding) == 0
                    else tuple(winding))
        return hull_answer(h, pendulum, wave, pivot=pivot, windings=windings,
                           pitch_inertia=pitch_inertia, harmonics=harmonics,
                           wave_info=wave_info, geometry=geometry, pto=pto,
                           search=winding_search, climb=winding_climb)
    if pto.copper_loss:
        from ..errors import ParameterError

        raise ParameterError("copper-loss: the heaving buoy's optimum has no copper loss yet; "
                             "needs --dofs surge,heave,pitch")
    eff = pto.efficiency
    eff = None if eff is None or tuple(eff) == (1.0, 1.0) else eff
    winding = 1 if winding is None else winding
    opts = {"winding": winding, "harmonics": harmonics, "torque_limit": pto.torque_limit,
            "efficiency": eff}
    sol, ow, notes = _solve(h, pendulum, wave, **opts)
    errors = _error_powers(h, coarse, pendulum, wave, **opts)
    return _result(h, width, pendulum, wave, wave_info, sol, ow, torque_limit=pto.torque_limit,
                   efficiency=eff, winding=winding, design=design, notes=notes,
                   error_powers=errors, geometry=geometry)


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
    out += _sea_validity(wave_info)
    return out


def _sea_validity(wave_info) -> list:
    """A sea state's steepness warning (``Hs / lambda_p`` past 1/20), as a list."""
    if wave_info.get("kind") != "irregular" or wave_info.get("hs") is None:
        return []
    text = sea_steepness_warning(float(wave_info["hs"]), float(wave_info["tp"]))
    return [text] if text else []


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


# -- a hull in surge, heave and pitch: one wave's answer
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
        return self._loads(t, phi, phi1, phi2, xi, xi1, xi2)

    def on_grid(self, points: int) -> dict:
        """``__call__`` at ``t_j = j T / points`` (``T`` the period), the trigonometric
        sums by inverse FFTs on a grid of a multiple of ``points`` that resolves every
        harmonic (the same values to rounding, in ``O(N log N)`` rather than
        ``O(points N)``: a long record's thousands of harmonics)."""
        cs, x, w = self.case, self.x, self.case.omega
        n, nh = cs.harmonics, cs.hull_harmonics
        r = max(1, -(-(2 * max(n, nh) + 2) // points))
        m = r * points

        def sums(c):  # Re sum_k c_k e^{iks} at s = 2 pi j / points (c: (..., K), k >= 1)
            full = np.zeros(c.shape[:-1] + (m // 2 + 1,), dtype=complex)
            full[..., 1:c.shape[-1] + 1] = c * (0.5 * m)
            return np.fft.irfft(full, m, axis=-1)[..., ::r]

        kn, kh = w * np.arange(1, n + 1), w * np.arange(1, nh + 1)
        cn = x[n + 1:] - 1j * x[1:n + 1]
        p0, p1, p2 = sums(np.stack((cn, 1j * kn * cn, -kn**2 * cn)))
        s = 2 * np.pi * np.arange(points) / points
        xk = self.xi[1:].T
        h0, h1, h2 = sums(np.stack((xk, 1j * kh * xk, -kh**2 * xk)))
        return self._loads(s / w, cs.winding * s + x[0] + p0, w * cs.winding + p1, p2,
                           (self.xi[0].real + h0.T).T, h1, h2)

    def _loads(self, t, phi, phi1, phi2, xi, xi1, xi2) -> dict:
        """The torque, the power and the bearing's load from the motion (P)."""
        cs = self.case
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


def peak(fun, period: float, points: int = PEAK_POINTS, grid=None) -> float:
    """The largest value of the periodic ``fun(t)`` (vectorized): located on ``points``
    samples (``grid(points)``'s values there, when given: the same samples by a faster
    route), then refined between the neighbours of the largest by Brent's method."""
    t = period * np.arange(points) / points
    v = fun(t) if grid is None else grid(points)
    i = int(np.argmax(v))
    h = period / points
    r = minimize_scalar(lambda s: -float(fun(np.array([s]))[0]),
                        bounds=(t[i] - h, t[i] + h), method="bounded",
                        options={"xatol": 1e-12 * period})
    return max(float(v[i]), -float(r.fun))


def error_estimate(history) -> float | None:
    r"""The discretization error stated beside a power refined by doubling the harmonics
    (W): from the stages' powers ``P_0, P_1, ..., P_k`` (``history``: ``(harmonics,
    power)``, each stage twice the harmonics of the one before) and their changes
    ``d_i = |P_i - P_{i-1}|``:

    - one doubling: ``d_1``;
    - more: with ``rho = d_k / d_{k-1}``, the geometric tail of the changes still to come,
      ``max(d_k, d_k rho / (1 - rho))`` (Richardson's estimate of a sequence converging
      geometrically; ``d_k`` where it converges faster than halving), None where
      ``rho >= 1`` (the changes do not shrink: no estimate).

    An estimate, not a bound: tests/test_hull_statistics.py checks, on a few cases, that it
    exceeds the change on one more doubling. None without a doubling."""
    p = [float(v) for _, v in history]
    d = [abs(b - a) for a, b in zip(p, p[1:])]
    if not d:
        return None
    if len(d) == 1 or d[-2] == 0.0:
        return d[-1]
    rho = d[-1] / d[-2]
    if not rho < 1.0:
        return None
    return max(d[-1], d[-1] * rho / (1.0 - rho))


def _deg(v) -> float:
    return float(np.degrees(v))


#: the answer's hull motion (and the torque and bearing load, which read the pivot's
#: acceleration) is reported from the hull solved once more at this many times the solve's
#: hull harmonics, at the answer's phi: the pendulum's reaction has content up to about twice
#: phi's harmonics near a sharp flip, above the solve's cut ``n + max(1, K)``; the power moves
#: by rounding (5.5e-8 on a 100-wave record), the hull's motion by up to 3 % there
REPORT_HULL_FACTOR = 2


def _reported(case, x, resolve=None):
    """The reported motion (:class:`MotionAt`) of the answer ``x`` on ``case`` (its hull
    solved again on ``resolve(case)``: None, the solve's own cut) and its peak torque (N m):
    located on ``PEAK_POINTS`` samples, refined by Brent's method."""
    pr = ideal_problem(case if resolve is None else resolve(case))
    mot = MotionAt(pr, x, pr.solve_hull(x))
    return mot, peak(lambda t: np.abs(mot(t)["tau"]), 2 * math.pi / case.omega,
                     grid=lambda m: np.abs(mot.on_grid(m)["tau"]))


def _mode(sol, resolve=None, checks: bool = True) -> dict:
    """One mode's entry; ``resolve(case)``: the same case with ``REPORT_HULL_FACTOR`` times
    the hull harmonics, for the reported motion (None: the solve's own cut); ``checks``:
    the optimality check (False: left out, its entries None)."""
    mot, pk = _reported(sol.case, sol.x, resolve if math.isfinite(sol.power) else None)
    status, ok = sol.status, sol.success
    limit = sol.pto.torque_limit
    if limit is not None and math.isfinite(sol.power) and pk > limit * (1 + 1e-12):
        # the limit is imposed on the solve grid: checked between its points
        over = pk / limit - 1
        ok = ok and over <= TORQUE_SLACK
        status += (f"; between the grid points the peak torque is {pk:.6g} N m "
                   f"({over:.1e} above the limit)")
    s = mot.on_grid(PEAK_POINTS)
    k = sol.case.winding
    checked = _optimality(sol) if checks else _UNCHECKED
    swing = None if k else 0.5 * _deg(np.max(s["phi"]) - np.min(s["phi"]))
    mean = _deg(math.remainder(float(np.mean(s["phi"])) - math.pi, 2 * math.pi) + math.pi)
    return {"mode": "swinging" if k == 0 else "rotation", "winding": k,
            "power_w": sol.power, "mechanical_power_w": (
                sol.power if sol.mechanical_power is None else sol.mechanical_power),
            "one_way_power_w": sol.one_way_power,
            "energy_balance_residual": sol.energy_balance_residual,
            "refinement_change_w": sol.refinement_change, "harmonics": sol.case.harmonics,
            "discretization_error_estimate_w": error_estimate(sol.refinement_history),
            "refinement_history": [[int(n), float(v)] for n, v in sol.refinement_history],
            "mean_angle_deg": mean if k == 0 else None, "swing_amplitude_deg": swing,
            "peak_torque_nm": pk, "distinct_maxima": sol.distinct_maxima,
            "maxima_powers_w": [float(v) for v in sol.maxima_powers],
            "found_by": sol.found_by, "starts": sol.runs, "success": ok,
            **checked, "status": status, "_solution": sol, "_motion": mot}


_UNCHECKED = {"gradient_max_w_per_rad": None, "hessian_largest_eigenvalue_w_per_rad2": None,
              "hessian_scaled_largest_eigenvalue": None, "optimality_smoothing_width_w": None}


def _optimality(sol) -> dict:
    """First- and second-order optimality of the answer ``sol`` (a mode entry's keys; None
    where not checked): of the ideal power, or of the take-off's objective that the
    answer's climb maximized (:func:`_pto_objective`)."""
    out = dict(_UNCHECKED)
    if not math.isfinite(sol.power):
        return out
    obj = _pto_objective(sol) if sol.pto.active else ideal_problem(sol.case)
    if obj is not None:
        grad, top, scaled = _hull_krylov.optimality(obj, sol.x)
        out.update({"gradient_max_w_per_rad": grad,
                    "hessian_largest_eigenvalue_w_per_rad2": top,
                    "hessian_scaled_largest_eigenvalue": scaled,
                    "optimality_smoothing_width_w": obj.width if sol.pto.smoothed else None})
    return out


def _pto_objective(sol):
    """The take-off's objective that ``sol``'s answer maximizes, for its optimality checks
    (None where the solver did not say): the smoothed electrical power at the smoothing
    width of the climb that gave the answer (an efficiency's kink is not differentiable
    at ``s = 0``: the checks are the last climb's, at that width), under a torque limit the
    augmented Lagrangian at the penalty and multipliers of that climb (its gradient the
    Lagrangian's at the multipliers' update from them)."""
    if sol.pto_state is None:
        return None
    pr = sol.pto.problem(sol.case)
    pr.set_climbed(sol.pto_state)
    return pr


#: a power above the radiation bound by more than this (relative: the discretization's)
#: is not an answer
BOUND_SLACK = 1e-3


def capture_width_limit(omega, amplitudes, rho, g, depth) -> float:
    """``sum_k J_k 3 lambda_k / (2 pi)`` (W): the most a body in surge, heave and pitch
    absorbs from the wave ``sum_k a_k exp(i k omega t)`` (heave: a crest of
    ``lambda / (2 pi)``; surge and pitch, one antisymmetric pattern: ``lambda / pi``;
    ``J_k`` each harmonic's energy flux, :func:`~parapend.hydro.waves.energy_flux`)."""
    from .waves import wavenumber

    total = 0.0
    for k, a in enumerate(np.asarray(amplitudes), start=1):
        if a != 0:
            w = k * omega
            lam = 2 * math.pi / wavenumber(w, depth, g)
            total += energy_flux(w, [a], rho, g, depth) * 3 * lam / (2 * math.pi)
    return float(total)


def _ends(hull, geometry) -> tuple:
    """The hull's draft and half-length (m) for the validity check, and how they were had:
    the geometry's, or (a dataset) the wall-sided box's of the same hydrostatics: draft
    ``M g / C_33``, half-length ``sqrt(3 C_55 / C_33)`` (a box's waterplane, ``C_55 ~ rho g
    A_wp L^2 / 12``)."""
    if geometry is not None:
        return geometry.get("draft_m"), geometry.get("half_length_m", 0.0), ""
    c = np.asarray(getattr(hull, "hydrostatic_stiffness", np.zeros((3, 3))), float)
    if not (c.shape == (3, 3) and c[1, 1] > 0 and c[2, 2] > 0):
        return None, 0.0, ""
    d = float(hull.mass) * float(hull.g) / float(c[1, 1])
    return (d, math.sqrt(3 * float(c[2, 2]) / float(c[1, 1])),
            " (the dataset's hydrostatics as a wall-sided box: an estimate)")


def headline_reason(modes, best, power, bound, at_rest, limit=None) -> str | None:
    """Why the best mode's ``power`` (W) is not the answer, or None when it is: rest (0 W)
    answers when a mode converged and none beats it; a search that did not converge, or a
    power above the radiation ``bound`` or the capture-width ``limit`` (W; None: not
    checked), beyond ``BOUND_SLACK``, is no answer."""
    if at_rest:
        if any(m["success"] for m in modes):
            return None
        return ("no mode's search converged (" + "; ".join(
            f"{m['mode']}: {m['status']}" for m in modes) + "); rest's 0 W is only a "
            "lower bound")
    if not best["success"]:
        return f"the best mode ({best['mode']}) did not converge: {best['status']}"
    if not power <= bound * (1 + BOUND_SLACK):
        return (f"the {best['mode']}'s {power:.4g} W is {power / bound:.4g} times the "
                f"radiation bound {bound:.4g} W: impossible (the inputs, the data or the "
                "solve are wrong)")
    if limit is not None and not power <= limit * (1 + BOUND_SLACK):
        return (f"the {best['mode']}'s {power:.4g} W is {power / limit:.4g} times the "
                f"capture-width limit {limit:.4g} W, which no body moving in surge, heave "
                "and pitch beats: impossible (the data's B or F, or the solve, are wrong)")
    return None


def bound_note(bound, error, limit) -> str | None:
    """The warning of a radiation ``bound`` (W) above the capture-width ``limit`` (W) by
    more than its ``error`` (W): the bound is of these coefficients, a mesh's or a
    dataset's, and B's near-null directions inflate it; the limit does not depend on them."""
    if not bound > (limit + error) * (1 + BOUND_SLACK):
        return None
    return (f"radiation bound: {bound:.4g} W is {bound / limit:.3g} times the capture-width "
            f"limit {limit:.4g} W: it is of this mesh's (or dataset's) B and F, whose "
            "near-null directions inflate it, and moves with the mesh; the capture-width "
            "limit bounds the power")


def _solve_mode(hull, pendulum, wave, k, harmonics, pivot, pitch_inertia, pto,
                screen=None, checks: bool = True) -> dict:
    """One winding's mode entry (:func:`_mode`). ``screen`` (a :class:`_Screen`; an ideal
    take-off's): the answer before its refinement is first compared with the best mode's, and
    one below it by more than the margin is entered unrefined and unchecked (``_screened``);
    ``checks`` False: the entry leaves its optimality check out (``_unchecked``), for
    :func:`hull_answer` to check the best mode alone once all are solved."""
    def make(scale):
        base = make_case(hull, pendulum, wave, winding=k, harmonics=harmonics, pivot=pivot,
                         pitch_inertia=pitch_inertia)
        if scale == 1:
            return base
        return make_case(hull, pendulum, wave, winding=k, harmonics=scale * base.harmonics,
                         hull_harmonics=scale * base.hull_harmonics, pivot=pivot,
                         pitch_inertia=pitch_inertia)
    def resolve(cs):
        return make_case(hull, pendulum, wave, winding=k, harmonics=cs.harmonics,
                         hull_harmonics=REPORT_HULL_FACTOR * cs.hull_harmonics, pivot=pivot,
                         pitch_inertia=pitch_inertia)
    def peak_torque(cs, x):
        return _reported(cs, x, resolve)[1]
    if screen is None or pto.active:
        sol = hold_limit(hull_search(make, pto=pto), peak_torque)
    else:
        sol = hull_search(make, pto=pto, screen=lambda s: screen.unrefined(s) is None)
    if sol.screened:
        ref = screen.levels[sol.case.harmonics]
        m = _mode(sol, resolve, checks=False)
        m.update(status=f"{sol.status} at {sol.case.harmonics} harmonics, {sol.power:.6g} W: "
                 f"below the best mode's {ref:.6g} W there by more than "
                 f"{screen.margin(ref):.2g} of it; not refined", _screened=True)
        return m
    m = _mode(sol, resolve, checks=checks)
    if not checks:
        m["_unchecked"] = True
    return m


#: the winding search (:func:`hull_answer`'s ``search``) stops after this many windings in
#: a row that do not beat the best so far
SEARCH_MISSES = 2
#: a record of this many waves or more (``waves_in``) has its windings searched by default
#: (:func:`parapend.hydro.api.solve_record`): over a long record the pendulum that swings
#: through the upright gains by going over the top a few times net (measured: +2.4 % at one
#: net turn on a 234-wave record); a shorter record has its rotation's turns climbed
#: instead (``_climb_windings``: a turn is a fifth of a 4-peak-period record's)
WINDING_SEARCH_WAVES = 20


#: a searched winding (and on a long record the rotation, solved after the swinging)
#: whose answer on one level of the continuation or on the record's own harmonics is below
#: the best mode's on the same harmonics by more than this share of it (or four times the
#: best's own change from there to its refined answer, if more) is a miss: not climbed
#: further, not refined, not checked. The refinements of the windings' answers moved them
#: by 7e-5 to 6.6e-3 of the power on the measured 234-wave records (3 net turns at Hs 1 m,
#: Te 7 s: 456.75 to 459.79 W); the windings' powers differ by 1e-3 to 3e-2. The levels
#: move far more (the 200-wave barge record's swinging: 63, 1000, 1580, 1634 W at 175,
#: 351, 702, 1404 harmonics, so a margin of 2.5, 0.13 and 0.01 there; the rotation's
#: 529, 1017, 1309, 1377 W, screened at 702). A refinement and an optimality check are
#: about half a searched winding's cost; a refined winding below the best is not checked.
SCREEN_MARGIN = 1e-2


class _Screen:
    """The screen of :func:`_solve_mode` against the mode ``best`` (an entry of
    :func:`_mode`): :meth:`unrefined` on each level and before the refinement."""

    def __init__(self, best: dict):
        self.best = best
        hist = best.get("refinement_history") or ()
        levels = best["_solution"].level_history if "_solution" in best else ()
        # the best's power on each level of its continuation and each stage of its
        # refinement
        self.levels = {int(n): float(p) for n, p in (*levels, *hist)}
        self.last = float(hist[-1][1]) if hist else None  # the best's refined power

    def unrefined(self, sol):
        """``best``'s power at ``sol``'s harmonics where ``sol`` (an unrefined answer) is
        below it by more than :meth:`margin` (a miss), else None (refine it)."""
        ref = self.levels.get(sol.case.harmonics)
        if ref is None or not math.isfinite(sol.power):
            return None
        return ref if sol.power < ref - self.margin(ref) * abs(ref) else None

    def margin(self, ref: float) -> float:
        """A share of ``best``'s power ``ref`` on some harmonics: :data:`SCREEN_MARGIN`, or
        four times ``best``'s change from there to its refined answer."""
        moved = abs(self.last - ref) / abs(ref) if self.last is not None and ref else 0.0
        return max(SCREEN_MARGIN, 4 * moved)


def through_upright(mean_angle_deg, swing_amplitude_deg) -> bool:
    """Whether a swing of ``mean_angle_deg +- swing_amplitude_deg`` (the absolute angle from
    the upward vertical) passes the upright: a multiple of 360 degrees within it."""
    lo = mean_angle_deg - swing_amplitude_deg
    return math.floor((mean_angle_deg + swing_amplitude_deg) / 360.0) * 360.0 >= lo


def _power_of(m) -> float:
    p = m["power_w"]
    return p if p is not None and math.isfinite(p) else -math.inf


def _search_windings(modes, solve, top: int) -> None:
    """The windings between swinging and rotation (``top`` net turns either way) on a long
    record, appended to ``modes``: where the swinging optimum is the better mode and passes
    the upright, the pendulum may go over the top a few times more one way than the other;
    1, 2, 3, ... net turns in the sense of a positive pitch, then -1, -2, -3, ... against it,
    are solved (``solve(k, screen)``: a winding below the best so far before its
    refinement, by :data:`SCREEN_MARGIN`, is left there unrefined), each sense until
    :data:`SEARCH_MISSES` in a row do not beat the best so far.
    Their answers swing (``mode`` "swinging", ``winding`` k). The powers over the windings
    are not monotone (measured on a 234-wave record: 0, 1, 2, 3, 4 net turns 453.8, 464.7,
    458.7, 459.8, 456.5 W), so this is a search, not a bracket: its answer is the best of
    the windings tried."""
    swing = next((m for m in modes if m["winding"] == 0 and m["success"]), None)
    if swing is None or swing["mean_angle_deg"] is None or not through_upright(
            swing["mean_angle_deg"], swing["swing_amplitude_deg"]):
        return
    lead = max((m for m in modes if m["success"] and not m.get("_screened")),
               key=_power_of)  # the best so far
    if _power_of(swing) < _power_of(lead):  # rotation wins: net turns are nearer the swing
        return
    for sense in (1, -1):
        misses, k = 0, 1
        while misses < SEARCH_MISSES and k < top:
            m = dict(solve(sense * k, _Screen(lead)), mode="swinging", searched=True)
            modes.append(m)
            if m["success"] and not m.get("_screened") and _power_of(m) > _power_of(lead):
                misses, lead = 0, m
            else:
                misses += 1
            k += 1


def _climb_windings(modes, solve, top: int) -> None:
    """The rotation's turns over a short record, appended to ``modes``: from the better
    sense's rotation (one turn per wave, the record's mean harmonic ``K``), ``K - 1``,
    ``K - 2``, ... turns (down to one) and then ``K + 1``, ``K + 2``, ... (up to ``top``)
    in the same sense, each way until :data:`SEARCH_MISSES` in a row do not beat the best
    rotation so far. A record's mean harmonic is above its peak's (the spectrum's tail):
    on the default sea's 4-peak-period records (``K`` = 5) 4 turns won on 6 of seeds 0 to
    9, 3 and 2 on one each, by up to 3.5 %; the powers over the turns are not monotone
    (seed 0: 2, 3, 4, 5 turns 1000.8, 956.9, 989.8, 988.1 W), so this is a search, not a
    bracket. The answers are rotations (``mode`` "rotation", ``winding`` the turns, signed,
    ``searched``)."""
    rot = [m for m in modes if m["mode"] == "rotation" and m["success"]
           and not m.get("_screened") and _power_of(m) > -math.inf]
    if not rot:
        return
    start = max(rot, key=_power_of)
    sense = 1 if start["winding"] > 0 else -1
    tried = {m["winding"] for m in modes}
    lead = start
    for step in (-1, 1):
        misses, k = 0, abs(start["winding"]) + step
        while misses < SEARCH_MISSES and 1 <= k <= top:
            won = False
            if sense * k not in tried:
                # screened against the best rotation so far, checked only if the best
                m = dict(solve(sense * k, _Screen(lead), checks=False), searched=True)
                modes.append(m)
                tried.add(sense * k)
                won = (m["success"] and not m.get("_screened")
                       and _power_of(m) > _power_of(lead))
                lead = m if won else lead
            misses = 0 if won else misses + 1
            k += step


def _check_best(modes, best) -> None:
    """The optimality check left out of the ``modes`` solved unchecked (``_unchecked``, a
    searched record's: the check of a 12192-harmonic answer is some 250 Hessian products,
    13 s of CPU), done on ``best`` alone; the others' statuses say they are not checked."""
    for m in modes:
        if m.pop("_unchecked", False):
            if m is best:
                m.update(_optimality(m["_solution"]))
            else:
                m["status"] += "; below the best: its optimality not checked"


def mode_label(m) -> str:
    """A mode's name in a status: ``rotation`` (in the sense of a positive pitch),
    ``rotation, reversed`` (against it), a searched rotation's ``rotation, k turns`` (and
    ``, reversed``), ``swinging, k net turns``."""
    k = m["winding"]
    if m["mode"] == "swinging" and k:
        return f"swinging, {k} net turn{'s' if abs(k) > 1 else ''}"
    if m["mode"] == "rotation" and m.get("searched"):
        return (f"rotation, {abs(k)} turn{'s' if abs(k) > 1 else ''}"
                + (", reversed" if k < 0 else ""))
    if m["mode"] == "rotation" and k is not None and k < 0:
        return "rotation, reversed"
    return m["mode"]


def best_label(r) -> str:
    """The name of a hull answer ``r``'s best mode (:func:`mode_label` of its entry in
    ``r.modes``: a searched rotation's turns with it)."""
    m = next((m for m in r.modes or () if m["mode"] == r.mode
              and m["winding"] == r.winding), {"mode": r.mode, "winding": r.winding})
    return mode_label(m)


def hull_answer(hull, pendulum, wave, *, pivot, windings=(1, -1, 0), pitch_inertia=None,
                harmonics=None, wave_info=None, geometry=None, notes=(),
                pto: HullPTO | None = None, search: bool = False,
                climb: int = 0) -> BuoyResult:
    """Solve each winding of ``windings`` (0: swinging; a negative one turns against the
    sense of a positive pitch: a hull that surges and pitches is not the same problem both
    ways), put them beside rest, and build the result from the best; ``pto`` the power
    take-off (None: ideal); ``search``: where swinging (winding 0) is the better mode and
    passes the upright, also 1, 2, 3, ... net turns either way below the largest of
    ``windings``, each sense until ``SEARCH_MISSES`` in a row do not beat the best (a
    search: the powers over the windings are not monotone); with ``search`` the
    swinging is solved first and the other windings are screened against it
    (``SCREEN_MARGIN``); ``climb`` (a short record's): also the rotation's other turns, up
    to ``climb`` a record, in the better sense (``_climb_windings``)."""
    pto = pto or HullPTO()
    from threadpoolctl import threadpool_limits

    searched = search and 0 in windings

    def solve(k, screen=None, checks=None):
        # a searched record's modes (and a climb's) are checked once all are solved, the
        # best alone
        return _solve_mode(hull, pendulum, wave, k, harmonics, pivot, pitch_inertia, pto,
                           screen, checks=not searched if checks is None else checks)
    # small dense matrices (a few hundred): BLAS threads cost more than they save
    with threadpool_limits(1, user_api="blas"):
        if searched:
            # a long record's swinging first: the other windings are screened against it
            # (on the long records measured swinging wins; the rotation screened there
            # skips its finer levels, its refinement and its optimality check)
            swing = solve(0)
            screen = _Screen(swing) if swing["success"] else None
            modes = [swing if k == 0 else solve(k, screen) for k in windings]
            _search_windings(modes, solve, max(abs(k) for k in windings))
        else:
            modes = [solve(k) for k in windings]
        if climb:
            _climb_windings(modes, solve, climb)
        ok_modes = [m for m in modes if m["success"] and not m.get("_screened")
                    and _power_of(m) > -math.inf]
        best = max(ok_modes or modes, key=_power_of)
        _check_best(modes, best)
    rest = {"mode": "rest", "winding": None, "power_w": 0.0, "mechanical_power_w": 0.0,
            "success": True, "status": "the pendulum held (no power)"}
    public = [{k: v for k, v in m.items() if not k.startswith("_")} for m in modes] + [rest]
    sol = best["_solution"]
    cs = sol.case
    # rest (0 W: no torque, or the pendulum held) is the answer when no motion beats it,
    # whatever the windings asked for
    at_rest = not _power_of(best) > 0
    mot = None if at_rest else best["_motion"]
    period = 2 * math.pi / wave.omega
    s = (mot or best["_motion"]).on_grid(PEAK_POINTS)
    xi1 = best["_motion"].xi[1] if not at_rest else np.zeros(3)
    amps = np.asarray(wave.amplitudes)
    regular = amps.size == 1
    def ph(z):
        return (_deg(np.angle(z / amps[0])) if regular and abs(z) > 0 else None)
    def half(v):
        return (0.0 if at_rest else 0.5 * float(np.max(v) - np.min(v)))
    rcond = max(BOUND_RCOND, float(getattr(hull, "damping_noise", 0.0)))
    bound, cut = radiation_bound(cs, rcond)
    bound_err = bound_error(cs, float(getattr(hull, "damping_noise", 0.0)))
    flux = energy_flux(wave.omega, amps, hull.rho, hull.g, hull.water_depth)
    cw_limit = capture_width_limit(wave.omega, amps, hull.rho, hull.g, hull.water_depth)
    p = 0.0 if at_rest else float(best["power_w"])
    pitch_amp = _deg(half(s["xi"][2]))
    validity = []
    peak_pitch = 0.0 if at_rest else _deg(np.max(np.abs(s["xi"][2])))
    if peak_pitch > PITCH_VALIDITY_DEG:
        validity.append(f"linear theory: the pitch reaches {peak_pitch:.3g} degrees, beyond "
                        f"about {PITCH_VALIDITY_DEG:g}; the answer is outside its validity")
    w_info = wave_info or {}
    if w_info.get("kind") == "regular":
        from .waves import wavenumber

        lam = 2 * math.pi / wavenumber(wave.omega, hull.water_depth, hull.g)
        steep = float(w_info["height_m"]) / lam
        if steep > STEEP_WARNING:
            validity.append(f"linear theory: the wave's steepness H / lambda = {steep:.3g} "
                            f"exceeds {STEEP_WARNING:.3g} (1/20; breaking at 1/7): a steep "
                            "wave's nonlinearity is left out")
    validity += _sea_validity(w_info)
    d, half_len, est = _ends(hull, geometry)
    if d is not None and not at_rest:
        ends = np.abs(s["xi"][1]) + half_len * np.abs(np.sin(s["xi"][2]))
        if float(np.max(ends)) > d:
            validity.append(f"linear theory: the hull's heave and pitch move its ends by up "
                            f"to {float(np.max(ends)):.3g} m, more than its draft {d:.3g} m"
                            + est)
    warnings = list(getattr(hull, "notes", ())) + list(notes) + [
        f"{mode_label(m)}: {m['status']}" for m in modes if not m["success"]]
    if cut:
        warnings.append(f"radiation bound: {cut} singular value(s) of B below "
                        f"{rcond:.3g} of the largest (the data's noise) cut in its "
                        "pseudo-inverse")
    maxima = sorted((v for m in modes for v in m.get("maxima_powers_w") or ()), reverse=True)
    note = bound_note(bound, bound_err, cw_limit)
    if note:
        warnings.append(note)
    reason = headline_reason(modes, best, p, bound, at_rest, limit=cw_limit)
    if reason:
        warnings.append(f"no resolved answer: {reason}")
    owp = None if at_rest else best["one_way_power_w"]
    return BuoyResult(
        power_w=None if reason else p, headline_reason=reason,
        maxima=len(maxima), maxima_powers_w=maxima,
        mechanical_power_w=(None if reason else 0.0 if at_rest
                            else float(best["mechanical_power_w"])),
        efficiency=list(pto.efficiency) if pto.efficiency is not None else None,
        copper_loss_w_per_nm2=pto.copper_loss, torque_limit_nm=pto.torque_limit,
        mode="rest" if at_rest else best["mode"],
        winding=None if at_rest else best["winding"], modes=public,
        one_way_power_w=owp, one_way_ratio=(owp / p if owp is not None and p > 0 else None),
        energy_balance_residual=None if at_rest else best["energy_balance_residual"],
        radiation_bound_w=bound,
        bound_fraction=(p / bound if bound > 0 and not reason else None),
        bound_rcond=rcond, bound_cut=cut, bound_error_w=bound_err,
        capture_width_limit_w=cw_limit,
        capture_width_m=(p / flux if flux > 0 and not reason else None),
        energy_flux_w_per_m=flux,
        surge_amplitude_m=half(s["xi"][0]), heave_amplitude_m=half(s["xi"][1]),
        pitch_amplitude_deg=pitch_amp, surge_phase_deg=ph(xi1[0]),
        heave_phase_deg=ph(xi1[1]), pitch_phase_deg=ph(xi1[2]),
        mean_heel_deg=0.0 if at_rest else _deg(best["_motion"].xi[0, 2].real),
        mean_angle_deg=None if at_rest else best["mean_angle_deg"],
        swing_amplitude_deg=None if at_rest else best["swing_amplitude_deg"],
        peak_torque_nm=0.0 if at_rest else best["peak_torque_nm"],
        peak_pivot_force_n=peak(lambda t: (mot or best["_motion"])(t)["pivot_force"],
                                period, grid=lambda m: (mot or best["_motion"]).on_grid(m)[
                                    "pivot_force"]) if not at_rest else pendulum.mass * hull.g,
        harmonics=cs.harmonics, hull_harmonics=cs.hull_harmonics,
        refinement_change_w=None if at_rest else best["refinement_change_w"],
        discretization_error_estimate_w=(None if at_rest
                                         else best["discretization_error_estimate_w"]),
        refinement_history=None if at_rest else best["refinement_history"],
        # a searched winding that did not converge is reported, not the answer's failure
        success=all(m["success"] for m in modes if not m.get("searched")) and not reason,
        status="; ".join(f"{mode_label(m)}: {m['status']}" for m in modes),
        dofs=["surge", "heave", "pitch"], wave=dict(wave_info or {},
                                                    omega_rad_per_s=wave.omega),
        pendulum={"mass_kg": pendulum.mass, "length_m": pendulum.length,
                  "inertia_kg_m2": pendulum.inertia,
                  "damping_coefficient": pendulum.damping_coefficient},
        body=dict(geometry or {}, description=getattr(hull, "description", "")),
        pivot={"pivot_offset_m": cs.pivot[0], "pivot_height_m": cs.pivot[1]},
        warnings=warnings, validity_warnings=validity, _motion=mot, _hydro=hull, _wave=wave)


