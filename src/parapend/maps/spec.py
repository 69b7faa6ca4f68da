"""The grid and the spec of a sweep: axes parsing, :class:`SweepSpec`, :func:`sweep_spec`,
and what a map holds (the variables, the status codes, the axes' attributes).

The first step of the one-way flow spec -> compute -> store -> run, and spec -> figures.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from .. import limits
from ..errors import ParameterError, check_int, check_range

__all__ = ["AXES", "NOT_COMPUTED", "STATUSES", "VARIABLES", "SweepSpec", "parse_axis",
           "sweep_spec"]

#: Sweepable parameters, in the order of the dimensions of a map.
AXES = ("omega", "delta", "gamma", "torque_limit", "efficiency")
_FLAGS = {"omega": "omega", "delta": "delta", "gamma": "gamma",
          "torque_limit": "torque-limit", "efficiency": "efficiency"}
_AXIS_ATTRS = {
    "omega": ("forcing frequency omega", "sqrt(g/l)"),
    "delta": ("excitation amplitude delta (base acceleration over g)", "1"),
    "gamma": ("viscous damping gamma", "sqrt(g/l)"),
    "torque_limit": ("torque limit T_max of the power take-off", "m g l"),
    "efficiency": ("efficiency of the power take-off (generating and motoring)", "1"),
}
_POWER_UNITS = "m g l sqrt(g/l)"

#: Status codes of the ``status`` variable (CF ``flag_values``/``flag_meanings``); -1 is the
#: fill value, "not computed". "error": the point raised (logged), "other": a status this
#: version does not know.
STATUSES = ("converged", "no_power", "stalled", "max_iterations", "nonfinite", "infeasible",
            "unresolved", "error", "other", "above_bound")
_CODE = {s: i for i, s in enumerate(STATUSES)}
NOT_COMPUTED = -1
_SUCCESS = ("converged", "no_power")

#: Variables of a map: name -> (long name, units); which are present depends on the sweep.
VARIABLES = {
    "power": ("optimal mean power extracted, P = -<T theta'> (positive = harvested)",
              _POWER_UNITS),
    "uniform_power": ("power of the best uniform rotation (Eq. 17)", _POWER_UNITS),
    "limit_power": ("gamma -> 0 limit of the power, omega TV(q) / 2 pi (Eqs. 19, 24, 32)",
                    _POWER_UNITS),
    "electrical_power": ("electrical power of the power take-off optimum", _POWER_UNITS),
    "mechanical_power": ("mechanical power P = -<T theta'> of the motion that maximizes the "
                         "electrical power (with an efficiency; power is the electrical)",
                         _POWER_UNITS),
    "branch_gap": ("power of the branch continued from the neighbouring point above the "
                   "global search's (0: the global search found the best)", _POWER_UNITS),
    "status": ("solver status of the optimum", None),
    "damping_threshold": ("damping threshold gamma* beyond which no power can be extracted "
                          "(Fig. 6; ideal power take-off)", "sqrt(g/l)"),
    "threshold_status": ("solver status of the damping threshold", None),
}
#: ``power`` of a map with an efficiency: the headline is the electrical power (as
#: ``optimize``), the same motion's mechanical power is ``mechanical_power``
ELECTRICAL_POWER = ("optimal mean electrical power through the power take-off (the motion "
                    "maximizes it; its mechanical power is mechanical_power)", _POWER_UNITS)
#: points per block (one chunk, one task): about half a second of work at N = 24; smaller
#: blocks cost the writing process more than the computing ones (measured on the benchmark's
#: map: 3.7 s of its CPU with 128-point blocks, 1.0 s with 512)
_BLOCK_POINTS = 512
_BLOCK_POINTS_PTO = 8


# -- the grid ------------------------------------------------------------------------------

def parse_axis(name: str, value) -> tuple[float, ...]:
    """Values of one axis: a number, a sequence of numbers, or text ``START:STOP:COUNT``
    (``COUNT`` values from START to STOP inclusive, like :func:`numpy.linspace`) or
    ``A,B,C``. Each value is checked against the parameter's admissible range."""
    flag = _FLAGS[name]
    if isinstance(value, str):
        text = value.strip()
        if text.count(":") == 2:
            a, b, c = text.split(":")
            try:
                start, stop = float(a), float(b)
            except ValueError:
                raise ParameterError(f"{flag}: expected START:STOP:COUNT with numbers, got "
                                     f"{value!r:.60}") from None
            try:
                count = int(c.strip())
            except ValueError:
                raise ParameterError(f"{flag}: expected an integer COUNT in START:STOP:COUNT, "
                                     f"got {value!r:.60}") from None
            count = check_int(flag, count, 1, limits.MAP_MAX_POINTS)
            for x in (start, stop):
                _check_value(name, x)
            vals = np.linspace(start, stop, count)
        elif ":" in text:
            raise ParameterError(f"{flag}: expected START:STOP:COUNT (three fields) or a "
                                 f"comma list, got {value!r:.60}")
        else:
            parts = [p for p in text.split(",")]
            if len(parts) > limits.MAP_MAX_POINTS or not all(p.strip() for p in parts):
                raise ParameterError(f"{flag}: expected numbers separated by commas, got "
                                     f"{value!r:.60}")
            try:
                vals = np.array([float(p) for p in parts])
            except ValueError:
                raise ParameterError(f"{flag}: expected numbers separated by commas, got "
                                     f"{value!r:.60}") from None
    else:
        vals = np.atleast_1d(np.asarray(value, dtype=object))
        if vals.ndim != 1 or vals.size == 0 or vals.size > limits.MAP_MAX_POINTS:
            raise ParameterError(f"{flag}: expected a number or a sequence of 1 to "
                                 f"{limits.MAP_MAX_POINTS} numbers")
    out = tuple(_check_value(name, v.item() if isinstance(v, np.generic) else v)
                for v in vals)
    if len(set(out)) != len(out):
        raise ParameterError(f"{flag}: expected distinct values, got a repeated one")
    return out


def _check_value(name: str, v) -> float:
    flag = _FLAGS[name]
    if name == "omega":
        return check_range(flag, v, *limits.OMEGA_RANGE,
                           why="units sqrt(g/l); see docs/limits-of-input.md")
    if name == "delta":  # the excitation's own rule: 0 or 1e-100 <= |delta| <= 1e3
        from ..excitation import _check_amplitude

        return _check_amplitude(flag, v)
    if name == "gamma":
        return check_range(flag, v, 0.0, limits.MAX_GAMMA)
    if name == "torque_limit":
        return check_range(flag, v, limits.MIN_TORQUE_LIMIT, limits.MAX_TORQUE_LIMIT,
                           why="units m g l")
    x = check_range(flag, v, 0.0, 1.0)
    if x <= 0:
        raise ParameterError(f"{flag}: expected a number in (0, 1], got {v!r}")
    return x


@dataclasses.dataclass(frozen=True)
class SweepSpec:
    """What a sweep computes: the axes, the excitation, N, and whether gamma* is wanted.

    ``values`` maps every name of :data:`AXES` to a tuple of floats (one value: a scalar
    coordinate; none: not used, e.g. no torque limit).
    """

    values: dict
    excitation: str = "harmonic"
    square_alpha: float | None = None
    fourier: str | None = None
    harmonics: int = 24
    threshold: bool = False
    block_points: int | None = None

    @property
    def dims(self) -> tuple[str, ...]:
        return tuple(a for a in AXES if len(self.values[a]) >= 2)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(self.values[a]) for a in self.dims)

    @property
    def points(self) -> int:
        return int(np.prod(self.shape))

    @property
    def pto(self) -> bool:
        return bool(self.values["torque_limit"] or self.values["efficiency"])

    @property
    def lossy(self) -> bool:
        """An efficiency is given: ``power`` is the electrical power, ``mechanical_power``
        the mechanical (the rule of ``optimize``)."""
        return bool(self.values["efficiency"])

    @property
    def variables(self) -> tuple[str, ...]:
        out = ["power", "uniform_power", "limit_power"]
        out += ["electrical_power"] if self.pto else ["branch_gap"]
        out += ["mechanical_power"] if self.lossy else []
        out += ["status"]
        if self.threshold:
            out += ["damping_threshold", "threshold_status"]
        return tuple(out)

    @property
    def chunks(self) -> tuple[int, ...]:
        """One block: runs along the fastest dimension, several of them side by side."""
        target = self.block_points or (_BLOCK_POINTS_PTO if self.pto else _BLOCK_POINTS)
        shape = self.shape
        c = [1] * len(shape)
        c[-1] = min(shape[-1], target)
        if len(shape) >= 2:
            c[-2] = min(shape[-2], max(1, target // c[-1]))
        return tuple(c)

    @property
    def block_grid(self) -> tuple[int, ...]:
        return tuple(-(-n // c) for n, c in zip(self.shape, self.chunks))

    @property
    def blocks(self) -> int:
        return int(np.prod(self.block_grid))

    def block_slices(self, block: int) -> tuple[slice, ...]:
        idx = np.unravel_index(block, self.block_grid)
        return tuple(slice(i * c, min((i + 1) * c, n))
                     for i, c, n in zip(idx, self.chunks, self.shape))

    def to_json(self) -> str:
        """The sweep's identity (stored in the attributes; a resume must match it). With an
        efficiency it says that ``power`` is the electrical power: a store an earlier version
        wrote (``power`` the mechanical one) is another sweep, never resumed into."""
        ident = {"axes": {a: list(self.values[a]) for a in AXES},
                 "excitation": self.excitation, "square_alpha": self.square_alpha,
                 "fourier": self.fourier, "harmonics": self.harmonics,
                 "threshold": self.threshold, "chunks": list(self.chunks)}
        if self.lossy:
            ident["power"] = "electrical"
        return json.dumps(ident, sort_keys=True)

    def attrs(self, name: str) -> tuple:
        """``(long name, units)`` of the variable ``name`` in this map."""
        return ELECTRICAL_POWER if name == "power" and self.lossy else VARIABLES[name]

    def excitation_args(self, omega: float, delta: float | None) -> dict:
        kw = {"excitation": self.excitation, "omega": omega}
        if self.excitation in ("harmonic", "two-harmonic", "square"):
            kw["delta"] = delta
        if self.excitation == "square":
            kw["square_alpha"] = self.square_alpha
        if self.excitation == "fourier":
            kw["fourier"] = self.fourier
        return kw


def sweep_spec(*, omega=1.8, delta=None, gamma=0.0, torque_limit=None, efficiency=None,
               harmonics: int = 24, excitation=None, square_alpha=None, fourier=None,
               threshold: bool = False, block_points: int | None = None) -> SweepSpec:
    """Check the parameters of a sweep (one line naming the offending one) and build its
    :class:`SweepSpec`; the bounds are in :mod:`parapend.limits` (``MAP_*``)."""
    from ..api import build_excitation, infer_excitation

    kind = infer_excitation(excitation, delta=delta, square_alpha=square_alpha,
                            fourier=fourier)
    if kind == "file":
        raise ParameterError("excitation: a sweep takes harmonic, two-harmonic, square or "
                             "fourier (a sampled file has no delta to vary)")
    uses_delta = kind in ("harmonic", "two-harmonic", "square")
    values = {"omega": parse_axis("omega", omega),
              "delta": parse_axis("delta", -0.3 if delta is None else delta) if uses_delta
              else (),
              "gamma": parse_axis("gamma", gamma),
              "torque_limit": () if torque_limit is None else parse_axis("torque_limit",
                                                                         torque_limit),
              "efficiency": () if efficiency is None else parse_axis("efficiency",
                                                                     efficiency)}
    pto = bool(values["torque_limit"] or values["efficiency"])
    n = check_int("harmonics", harmonics, 1,
                  limits.MAX_PTO_HARMONICS if pto else limits.MAP_MAX_HARMONICS)
    if block_points is not None:
        block_points = check_int("block-points", block_points, 1, 1 << 16)
    spec = SweepSpec(values, kind, square_alpha, fourier, n, bool(threshold), block_points)
    if not spec.dims:
        raise ParameterError("omega, delta, gamma, torque-limit, efficiency: expected at least "
                             "one axis with two or more values (e.g. --omega 1.2:2.4:128)")
    pts = spec.points
    cap = limits.MAP_MAX_PTO_POINTS if pto else limits.MAP_MAX_POINTS
    if pts > cap:
        raise ParameterError(f"{', '.join(_FLAGS[d] for d in spec.dims)}: expected at most "
                             f"{cap} points{' with a power take-off' if pto else ''}, got "
                             f"{' x '.join(map(str, spec.shape))} = {pts}")
    if pts * max(n, 24) ** 2 > limits.MAP_MAX_WORK:
        raise ParameterError(f"harmonics: expected points * max(harmonics, 24)^2 <= "
                             f"{limits.MAP_MAX_WORK}, got {pts} * {max(n, 24)}^2; lower "
                             "--harmonics or the number of points")
    # the excitation parameters that do not vary: checked once here (an unknown Fourier term
    # list, a square_alpha out of range), with the first values of the axes
    build_excitation(**spec.excitation_args(values["omega"][0],
                                            values["delta"][0] if uses_delta else None))
    return spec
