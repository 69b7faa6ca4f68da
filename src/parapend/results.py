"""Frozen result objects; their field names are the JSON keys of the command line."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

__all__ = ["CONVENTION", "OptimizeResult", "Record", "ThresholdResult", "to_jsonable"]

CONVENTION = ("theta from the upright; non-dimensional time (unit sqrt(l/g)); power positive "
              "when harvested, P = -<T theta'> (paper Eqs. 14-16; the paper's tables list -P "
              "of its Eq. 8)")


def to_jsonable(value):
    """Convert numpy scalars/arrays and nested containers to plain JSON types (NaN -> None)."""
    if isinstance(value, dict):
        return {k: to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return [to_jsonable(v) for v in value.tolist()]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    return value


class _Result:
    """Mixin: ``to_dict`` over the public dataclass fields (private ``_`` fields skipped)."""

    def to_dict(self) -> dict:
        return {f.name: to_jsonable(getattr(self, f.name)) for f in fields(self)
                if not f.name.startswith("_")}


@dataclass(frozen=True, eq=False)
class OptimizeResult(_Result):
    """Optimal period-1 rotation for one excitation and damping.

    Attributes
    ----------
    power : float
        Mean extracted power of the optimum (Eq. 15; positive = harvested).
    uniform_power : float
        Best uniform rotation (Eq. 17, phase optimized), same damping.
    limit_power : float
        gamma -> 0 supremum ``omega*TV(q)/(2 pi)`` (Eqs. 19/24/32 generalized).
    gain_over_uniform : float or None
        ``power/uniform_power - 1``; None when the uniform rotation extracts nothing.
    harmonics, gamma, omega : the problem (gamma: viscous damping, the CLI flag --gamma).
    success, status, message, iterations : convergence. ``success`` means the solver
        converged; status "converged", "no_power" (converged, but the optimum is P <= 0:
        gamma at or above gamma*, or a constant q; ``success`` is True), "stalled",
        "max_iterations", "nonfinite" (Fourier) or the BVP's statuses; iterations of the
        winning Newton run.
    coefficients : dict
        ``{"a0": float, "a": [N], "b": [N]}`` of Eq. 10.
    peak_torque : float
        ``max |T(t)|`` over the period (Eq. 14).
    method : str
        "fourier" (Eq. 10, N harmonics) or "bvp" (Euler-Lagrange BVP, Eqs. 13/22/27); for
        "bvp", ``coefficients`` is the N-harmonic Fourier projection of the BVP motion, and
        ``mesh_nodes``, ``max_residual``, ``residual_floor`` (> 0 where elements passed at
        the residual's rounding floor, not at tol: boundary layers at gamma below about
        1e-15), ``continuation_steps`` describe the solve.
    search, candidate_patterns, patterns_tried, polished, abandoned : the evidence of the
        global search (docs/global.md): ``search`` is "exhaustive" (every half-turn
        direction pattern of the limit motion, ``candidate_patterns`` of them, was a seed;
        ``C(2m, m - 1)`` for ``extrema_per_period = 2m``, a float past 2^53, inf past 1e308),
        "dynamic-programme" (too many to list: seeds from the (t, theta) dynamic programme),
        or "bvp-starts"; runs carried to convergence and runs abandoned as unable to win.
    second_power, second_distance : float or None
        The best other distinct local maximum among the runs polished to convergence, and
        the RMS distance of its motion from the optimum's over one period (rad; distinct:
        above 1e-6). Runs abandoned as unable to win are never polished, so a better other
        maximum may exist: ``second_power`` is a lower bound of the second-best maximum.
        None: every polished run reached the optimum. (BVP: the best other start's power,
        distinct by more than 1e-9 relative; no distance.)
    upper_bound, bound_gap : ``limit_power - gamma omega^2`` (no rotation does better, as
        ``<theta'^2> >= omega^2``) and its distance to ``power``.
    torque_limit, efficiency_generating, efficiency_motoring : float or None
        The power take-off (:func:`parapend.pto.optimize_pto`): ``|T| <= torque_limit``
        (m g l), electrical power ``eta_g p`` generating, ``p / eta_m`` motoring; None when
        not set. ``power`` stays the mechanical ``P = -<T theta'>`` of the PTO optimum.
    electrical_power : float or None
        Mean electrical power of the motion, unsmoothed efficiency model.
    unconstrained_power : float or None
        The ideal (lossless, unlimited) optimum the PTO solve started from.
    peak_power, motoring_energy, harvested_energy : float or None
        ``max p`` of ``p = -T theta'``, and ``int max(-p, 0) dt``, ``int max(p, 0) dt`` over
        one forcing period (m g l): the energy the machine puts back into, and takes from,
        the pendulum each cycle.
    max_violation : float or None
        ``max(peak_torque / torque_limit - 1, 0)`` on the dense evaluation.
    intervals, refinement_change : int or None, float or None
        The torque-limited optimum is solved in the time domain (``method`` "hermite",
        :mod:`parapend.optimal.hermite`) on ``intervals`` cubic Hermite intervals, the
        efficiency and copper-loss optima (``method`` "collocation",
        :mod:`parapend.optimal.collocation`) on ``intervals`` Hermite-Simpson intervals; both
        checked by one doubling: ``refinement_change`` is the change of the (electrical)
        power between the last two.
    peak_torque_converged : bool or None
        Whether ``peak_torque`` moved by less than 1 % between the last two meshes of a
        time-domain PTO solve. The Fourier optimum at gamma = 0: False (its peak grows like
        N^2 towards the limit's instant flips: 164, 587, 2215 at N = 12, 24, 48); at
        gamma > 0 and for the BVP: None (not checked).
        False where the optimal torque is impulsive (its peak grows with the mesh, as the
        efficiency optimum at gamma = 0: 16, 32, 65, 129 on 128 to 1024 intervals) or
        singular (many torques give the same power): ``peak_torque``, ``peak_torque_nm``
        and ``peak_power`` are then properties of the mesh, not of the motion.
    peak_torque_coarse : float or None
        The peak torque on half the intervals (the last refinement).
    torque_impulse, torque_impulse_change : float or None
        Collocation: ``int |T| dt`` over the arc around the peak where ``T`` keeps its sign
        (the braking impulse, m g l times the time unit), and its change from half the
        intervals; it converges where the peak does not.
    units, power_w, uniform_power_w, limit_power_w, peak_torque_nm, electrical_power_w,
    energy_per_cycle_j, motoring_energy_j : physical values (W, N m, J) when a pendulum's
        length and mass were given (:mod:`parapend.units`); None otherwise.
    uniform_pto_feasible, uniform_pto_power, uniform_pto_electrical_power,
    uniform_pto_peak_torque, uniform_pto_phase : the best uniform rotation through the same
        power take-off (:func:`parapend.pto.uniform_under_pto`): its phase maximizes the
        electrical power among the phases whose peak torque meets the limit; all None
        (``uniform_pto_feasible`` False) when no phase does, None without a take-off.
    gain_over_uniform_pto : float or None
        Like for like: ``electrical_power / uniform_pto_electrical_power - 1`` (the
        mechanical powers when there is no efficiency or copper loss).
    uniform_pto_power_w, uniform_pto_electrical_power_w : float or None
        The same in watts, with physical units.
    winding : int
        K, turns per forcing period, ``theta(t + 2 pi/omega) = theta(t) + 2 pi K`` (1: the
        paper's period-1 rotation); ``uniform_power`` is then the uniform rotation with K
        turns and ``upper_bound`` is ``limit - gamma K^2 omega^2``.
    """

    power: float
    uniform_power: float
    limit_power: float
    gain_over_uniform: float | None
    harmonics: int
    gamma: float
    omega: float
    success: bool
    status: str
    message: str
    iterations: int
    coefficients: dict
    peak_torque: float
    method: str = "fourier"
    found_by: str = ""
    local_maxima: list = field(default_factory=list)
    gradient_norm: float = float("nan")
    strict_maximum: bool = False
    quadrature_points: int = 0
    mean_square_speed: float = float("nan")
    search: str = ""
    candidate_patterns: int | float = 1
    extrema_per_period: int = 2
    patterns_tried: int = 0
    polished: int = 0
    abandoned: int = 0
    second_power: float | None = None
    second_distance: float | None = None
    upper_bound: float = float("nan")
    bound_gap: float = float("nan")
    mesh_nodes: int | None = None
    max_residual: float | None = None
    residual_floor: float | None = None
    continuation_steps: int | None = None
    excitation: dict = field(default_factory=dict)
    torque_limit: float | None = None
    efficiency_generating: float | None = None
    efficiency_motoring: float | None = None
    electrical_power: float | None = None
    unconstrained_power: float | None = None
    peak_power: float | None = None
    motoring_energy: float | None = None
    harvested_energy: float | None = None
    max_violation: float | None = None
    intervals: int | None = None
    refinement_change: float | None = None
    peak_torque_converged: bool | None = None
    peak_torque_coarse: float | None = None
    torque_impulse: float | None = None
    torque_impulse_change: float | None = None
    units: dict | None = None
    power_w: float | None = None
    uniform_power_w: float | None = None
    limit_power_w: float | None = None
    peak_torque_nm: float | None = None
    electrical_power_w: float | None = None
    energy_per_cycle_j: float | None = None
    motoring_energy_j: float | None = None
    uniform_pto_feasible: bool | None = None
    uniform_pto_power: float | None = None
    uniform_pto_electrical_power: float | None = None
    uniform_pto_peak_torque: float | None = None
    uniform_pto_phase: float | None = None
    gain_over_uniform_pto: float | None = None
    uniform_pto_power_w: float | None = None
    uniform_pto_electrical_power_w: float | None = None
    winding: int = 1
    convention: str = CONVENTION
    _motion: object = field(default=None, repr=False)
    _excitation: object = field(default=None, repr=False)

    @property
    def motion(self):
        """The optimal motion: a :class:`~parapend.trajectory.FourierMotion`, or a
        :class:`~parapend.optimal.hermite.HermiteMotion` for ``method`` "hermite", a
        :class:`~parapend.optimal.collocation.CollocationMotion` for "collocation"."""
        return self._motion


@dataclass(frozen=True, eq=False)
class ThresholdResult(_Result):
    """Damping ``gamma*`` beyond which no period-1 rotation extracts power.

    ``power_at_threshold`` is the optimal power at ``damping_threshold`` (zero to the
    solver's tolerance); ``uniform_threshold`` is ``|Q1|/(2 omega)``, where the best uniform
    rotation stops extracting. ``harmonics`` is the final N; ``refinement_change`` is
    ``|gamma*(N) - gamma*(N/2)|``, the check by one refinement (NaN when N was given).
    With a pendulum's length and mass (:mod:`parapend.units`), ``units`` describes them and
    ``damping_threshold_coefficient`` and ``uniform_threshold_coefficient`` are the two
    thresholds as viscous damping coefficients ``c = gamma I / t0`` in N m s/rad.
    """

    damping_threshold: float
    uniform_threshold: float
    power_at_threshold: float
    harmonics: int
    omega: float
    success: bool
    status: str
    message: str
    iterations: int
    mean_square_speed: float = float("nan")
    refinement_change: float = float("nan")
    excitation: dict = field(default_factory=dict)
    units: dict | None = None
    damping_threshold_coefficient: float | None = None
    uniform_threshold_coefficient: float | None = None
    convention: str = CONVENTION


class Record(_Result):
    """A frozen result whose fields are the keys of a command's JSON object (for the
    commands whose result is not one of the dataclasses above: ``figure``, ``reproduce``,
    ``sweep``, ``map``, ``optimize --method all``). Fields read as attributes or with
    ``record["key"]``; ``to_dict`` gives the JSON object. Objects that are not JSON (a
    figure, a Dataset) ride along as private attributes (``_figure``, ``_dataset``;
    :meth:`to_dataset` returns the Dataset); the
    attributes of ``_source`` (the object the record describes, e.g. a simulated motion)
    read through.
    """

    __slots__ = ("_kind", "_data", "_private")

    def __init__(self, kind: str, data: dict, **private):
        object.__setattr__(self, "_kind", kind)
        object.__setattr__(self, "_data", dict(data))
        object.__setattr__(self, "_private", private)

    def __getattr__(self, name):
        data = object.__getattribute__(self, "_data")
        if name in data:
            return data[name]
        private = object.__getattribute__(self, "_private")
        if name.startswith("_") and name[1:] in private:
            return private[name[1:]]
        if "source" in private and not name.startswith("_"):
            return getattr(private["source"], name)
        raise AttributeError(f"{object.__getattribute__(self, '_kind')} result has no field "
                             f"{name!r}")

    def __getitem__(self, key):
        return self._data[key]

    def __setattr__(self, name, value):
        raise AttributeError(f"{self._kind} result is frozen")

    def __dir__(self):
        return sorted(self._data)

    def __repr__(self) -> str:
        keys = ", ".join(self._data)
        return f"{self._kind.capitalize()}Result({keys})"

    def fields(self) -> tuple:
        """The field names, which are the JSON keys."""
        return tuple(self._data)

    def to_dataset(self):
        """The full ``xarray.Dataset`` behind the record (``basins``, ``rotations``,
        ``sweep``, ``map``, ``power-matrix``: what ``--save`` writes).

        Raises
        ------
        AttributeError
            For a command whose result carries no Dataset.
        """
        private = object.__getattribute__(self, "_private")
        if private.get("dataset") is None:
            raise AttributeError(f"{self._kind} result has no Dataset")
        return private["dataset"]

    def to_dict(self) -> dict:
        return to_jsonable(self._data)
