r"""Design maps: resumable parameter sweeps over omega, delta, gamma, T_max and efficiency.

One sweep computes, at every point of a grid, what :func:`parapend.optimize` computes (the
optimum of the truncated Fourier problem, Eqs. 10-11, by the global search of
docs/global.md), the best uniform rotation (Eq. 17) and the gamma -> 0 limit (Eqs. 19, 24,
32), and on request the damping threshold gamma* (Eq. 15, Fig. 6). With a torque limit or an
efficiency (fixed or swept) each point is :func:`parapend.pto.optimize_pto` instead.

The grid
    Axes in the order ``omega, delta, gamma, torque_limit, efficiency``; an axis with two or
    more values is a dimension, one with one value a scalar coordinate. The last dimension
    is the fastest: the grid is cut into *blocks* of whole runs along it (one chunk of the
    store each), and inside a run every point starts a continuation from its neighbour's
    optimum (the warm start, below). Each run starts afresh, so a block's values do not
    depend on which process computes it or in which order: a resumed sweep recomputes a
    block exactly as an uninterrupted one did.

The warm start and the global search
    A point's ``power`` is the global search started cold, exactly as in
    :func:`parapend.optimize`; so it equals optimize's power (bit for bit on one machine).
    The neighbour's optimum is then continued to this point (one Newton run, abandoned as
    soon as its quadratic model cannot beat the global search); when it converges to a
    higher maximum (by more than 1e-9), the excess is ``branch_gap`` and the continuation
    goes on along that branch. So the warm start cannot change ``power``; it checks the
    global search along every run of the map (0 everywhere on the maps measured so far).

The searches of a block together
    The global searches of a block's points run in lockstep (:mod:`.optimal.batch`): the
    array work of each Newton iteration is done for up to 128 points at once, with the same
    arithmetic per point as ``search_fourier``, so ``power`` is still optimize's bit for bit.

The store (Zarr 3)
    Made whole (every array, its chunks, coordinates and attributes) before the first
    block, behind a root ``zarr.json`` that says "being created" (written first: a
    directory is only ever emptied when parapend recognises it as its own), then written
    block by block: the variables of a block, then its ``done`` mask. Zarr skips chunks
    that equal the fill value, so the data alone cannot say what finished; the mask can, and
    a block is only counted when its mask is written. Running the same sweep on the same
    store resumes it: the blocks whose mask is set are verified (every chunk present and
    decodable, a status at every point) and not recomputed unless damaged, and the store
    ends byte for byte as an uninterrupted run's. The store is locked (``flock`` on its
    directory) while a sweep writes it: a second sweep on it is refused with one line; the
    lock dies with its process (``kill -9`` included).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import math
import os
import shutil
import tempfile
import threading
import time
import warnings
from pathlib import Path

import numpy as np

from . import limits
from .errors import OutputError, ParameterError, SolverError, check_int, check_range
from .fileio import TEMP_PREFIX

__all__ = ["AXES", "STATUSES", "VARIABLES", "SweepRun", "SweepSpec", "compute_block",
           "open_sweep", "parse_axis", "plot_map", "sweep", "sweep_spec"]

log = logging.getLogger(__name__)

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
            "unresolved", "error", "other")
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
    "branch_gap": ("power of the branch continued from the neighbouring point above the "
                   "global search's (0: the global search found the best)", _POWER_UNITS),
    "status": ("solver status of the optimum", None),
    "damping_threshold": ("damping threshold gamma* beyond which no power can be extracted "
                          "(Fig. 6; ideal power take-off)", "sqrt(g/l)"),
    "threshold_status": ("solver status of the damping threshold", None),
}
_BRANCH_TOL = 1e-9
#: a continuation whose first Newton step lands this close to the global search's maximum
#: (max-norm of the coefficients, relative to max(1, |x|)) is on that maximum's branch
_SAME_BRANCH = 1e-4
#: points per block (one chunk, one task): about half a second of work at N = 24; smaller
#: blocks cost the writing process more than the computing ones (measured on the benchmark's
#: map: 3.7 s of its CPU with 128-point blocks, 1.0 s with 512)
_BLOCK_POINTS = 512
#: global searches run together at most this many at a time: 64 to 128 points cost 0.74 to
#: 0.77 ms each, 512 points 0.91 ms (the Hessians of a batch leave the cache)
_BATCH_POINTS = 128
#: and at most this many Hessian entries per batch (4 MiB of doubles; N = 24 allows 218)
_BATCH_ENTRIES = 1 << 19
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
        from .excitation import _check_amplitude

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
    def variables(self) -> tuple[str, ...]:
        out = ["power", "uniform_power", "limit_power"]
        out += ["electrical_power"] if self.pto else ["branch_gap"]
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
        """The sweep's identity (stored in the attributes; a resume must match it)."""
        return json.dumps({"axes": {a: list(self.values[a]) for a in AXES},
                           "excitation": self.excitation, "square_alpha": self.square_alpha,
                           "fourier": self.fourier, "harmonics": self.harmonics,
                           "threshold": self.threshold, "chunks": list(self.chunks)},
                          sort_keys=True)

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
    from .api import build_excitation, infer_excitation

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


# -- one block -----------------------------------------------------------------------------

def _continue(exc, n: int, gamma: float, found, problem, warm, first=None):
    """What optimize computes (power, status) from the point's global search ``found``, plus
    the continuation check from the neighbour's optimum ``warm``; see the module docstring.
    ``problem``: the search's N-harmonic problem (reused when ``best`` is on its grid);
    ``first``: ``problem.evaluate`` at the padded ``warm`` when computed already (with the
    other points of the block). Returns (power, status, branch_gap, x for the next point)."""
    from .optimal.fourier import FourierProblem, _ascent_step, _pad, newton_maximize

    best = found.best
    status = "no_power" if best.status == "converged" and best.power <= 0 else best.status
    gap, x = 0.0, best.x
    if warm is not None and math.isfinite(best.power):
        if problem is None or problem.points != best.points:
            problem, first = FourierProblem(exc, n, gamma, best.points), None
        x0 = _pad(warm, n)
        # one Newton step decides most points: when it lands on the global search's maximum
        # (within 1e-4 of the coefficients, from the concave region), the continuation
        # converges there (Newton converges quadratically near a strict maximum: the next
        # step would be within ~1e-8) and there is no other branch; a step of 1/47 of the
        # delta range of the benchmark's map lands within 5e-5 (median 5e-6)
        p, g, h = first if first is not None else problem.evaluate(x0)
        d, is_newton = _ascent_step(g, h)
        near = float(np.max(np.abs(x0 + d - best.x))) <= _SAME_BRANCH * max(
            1.0, float(np.max(np.abs(best.x))))
        if not (is_newton and math.isfinite(p) and near):
            r = newton_maximize(problem, x0, "warm", abandon_below=best.power)
            if r.status == "converged" and r.power > best.power + _BRANCH_TOL * max(
                    1.0, abs(best.power)):
                gap, x = r.power - best.power, r.x
    return best.power, status, gap, x


def _searches(spec: SweepSpec, ideal: list) -> list:
    """The global search of every ideal point of a block, ``(found, problem)`` each, or the
    exception it raised: all together (:func:`.optimal.batch.search_fourier_batch`, the
    same numbers as ``search_fourier`` point by point); if that raises, point by point, so
    that only the failing points are errors."""
    from .optimal import batch
    from .optimal.fourier import search_fourier

    if not ideal:
        return []
    try:
        out = []
        # at most _BATCH_POINTS points, fewer at large N: the Hessians of a batch take
        # points * (2N + 1)^2 doubles (twice that in the primary runs, limit and uniform)
        step = max(1, min(_BATCH_POINTS, _BATCH_ENTRIES // (2 * spec.harmonics + 1) ** 2))
        for i in range(0, len(ideal), step):
            part = ideal[i:i + step]
            out += batch.search_fourier_batch([(e, g) for e, g, _ in part], spec.harmonics,
                                              limits=[lim for _, _, lim in part])
        return out
    except Exception:  # noqa: BLE001 - recomputed point by point below
        out = []
        for exc, gamma, _ in ideal:
            try:
                out.append((search_fourier(exc, spec.harmonics, gamma), None))
            except Exception as err:  # noqa: BLE001 - recorded as status "error"
                out.append(err)
        return out


def _first_steps(spec: SweepSpec, runs: list, found: list) -> dict:
    """``problem.evaluate`` at the padded optimum of the previous point, for every ideal
    point whose neighbour is ideal too: the first step of the continuation, all together.
    Keyed by the point's index in ``found``; a point whose neighbour's continuation ends on
    another branch (``branch_gap``) is evaluated again, alone, by :func:`_continue`."""
    from .optimal.batch import ProblemBatch
    from .optimal.fourier import _pad

    pairs = []  # (k of the point, k of its neighbour)
    for kinds in runs:
        for prev, kind in zip(kinds, kinds[1:]):
            if isinstance(prev, tuple) and isinstance(kind, tuple):
                a, b = found[prev[1]], found[kind[1]]
                if (not isinstance(a, Exception) and not isinstance(b, Exception)
                        and b[1] is not None and b[1].points == b[0].best.points
                        and math.isfinite(b[0].best.power)):
                    pairs.append((kind[1], prev[1]))
    out: dict = {}
    groups: dict = {}
    for k, j in pairs:
        groups.setdefault(found[k][1].points, []).append((k, j))
    for grp in groups.values():
        try:
            p, g, h = ProblemBatch([found[k][1] for k, _ in grp]).evaluate(
                list(range(len(grp))),
                np.array([_pad(found[j][0].best.x, spec.harmonics) for _, j in grp]))
        except Exception:  # noqa: BLE001 - evaluated point by point in _continue
            continue
        for i, (k, _) in enumerate(grp):
            out[k] = (p[i], g[i].copy(), h[i])
    return out


def _point_input(spec: SweepSpec, p: dict):
    """The parts of a point that need no global search: (values, kind) with kind "pto",
    "constant", "error" or ``(excitation, gamma, limit)`` for an ideal point."""
    from .api import build_excitation
    from .optimal.limit import limit
    from .power import uniform_power

    kw = spec.excitation_args(p["omega"], p.get("delta"))
    out: dict = {}
    try:
        exc = build_excitation(**kw)
        gamma = p["gamma"]
        lim = limit(exc)
        out["uniform_power"] = uniform_power(exc, gamma)[0]
        out["limit_power"] = lim.power
        if spec.pto:
            from .pto import optimize_pto

            r = optimize_pto(torque_limit=p.get("torque_limit"), efficiency=p.get("efficiency"),
                             gamma=gamma, harmonics=spec.harmonics, **kw)
            out.update(power=r.power, electrical_power=r.electrical_power, status=r.status)
            return out, "pto"
        if lim.power <= 0:  # constant q: as optimize, the uniform rotation's loss
            out.update(power=-gamma * exc.omega**2, status="no_power", branch_gap=0.0)
            return out, "constant"
        return out, (exc, gamma, lim)
    except Exception as err:  # recorded as status "error", never dropped
        log.warning("sweep point %s failed: %s: %s", p, type(err).__name__, err)
        return {"status": "error"}, "error"


def _threshold(spec: SweepSpec, p: dict, thresholds: dict):
    """gamma* at the point's (omega, delta), once per block for each."""
    from .api import threshold

    key = (p["omega"], p.get("delta"))
    if key not in thresholds:
        try:
            t = threshold(**spec.excitation_args(p["omega"], p.get("delta")))
            thresholds[key] = (t.damping_threshold, t.status)
        except Exception as err:
            log.warning("sweep threshold at %s failed: %s: %s", p, type(err).__name__, err)
            thresholds[key] = (math.nan, "error")
    return thresholds[key]


def _finite(x) -> bool:
    try:
        return math.isfinite(x)
    except TypeError:
        return False


def compute_block(spec: SweepSpec, block: int) -> dict:
    """The variables of one block, as arrays of the block's shape.

    The global searches of all the block's ideal points run together
    (:mod:`.optimal.batch`); then each run along the fastest dimension continues from point
    to point (each run starts afresh)."""
    sl = spec.block_slices(block)
    shape = tuple(s.stop - s.start for s in sl)
    out = {v: (np.full(shape, NOT_COMPUTED, dtype=np.int8) if v.endswith("status")
               else np.full(shape, np.nan)) for v in spec.variables}
    fixed = {a: (spec.values[a][0] if len(spec.values[a]) == 1 else None) for a in AXES
             if len(spec.values[a]) <= 1}
    runs, ideal = [], []  # runs: [(index, point, values, kind)]; ideal: search inputs
    for lead in np.ndindex(*shape[:-1]):
        run = []
        for j in range(shape[-1]):
            idx = (*lead, j)
            p = dict(fixed)
            for d, s, i in zip(spec.dims, sl, idx):
                p[d] = spec.values[d][s.start + i]
            vals, kind = _point_input(spec, p)
            if isinstance(kind, tuple):  # ("ideal", k into ideal, excitation, gamma)
                ideal.append(kind)
                kind = ("ideal", len(ideal) - 1, kind[0], kind[1])
            run.append((idx, p, vals, kind))
        runs.append(run)
    found = _searches(spec, ideal)
    first = _first_steps(spec, [[kind for *_, kind in run] for run in runs], found)
    thresholds: dict = {}
    for run in runs:
        warm, prev = None, None
        for idx, p, vals, kind in run:
            if kind in ("error", "constant"):
                warm = None
            elif kind != "pto":
                _, k, exc, gamma = kind
                try:
                    if isinstance(found[k], Exception):
                        raise found[k]
                    # the first step was evaluated from the neighbour's global optimum: valid
                    # when the warm start is that optimum (no branch above it)
                    pre = first.get(k) if prev is not None and warm is prev else None
                    pw, st, gap, warm = _continue(exc, spec.harmonics, gamma, *found[k], warm,
                                                  pre)
                    prev = found[k][0].best.x
                    vals.update(power=pw, status=st, branch_gap=gap)
                except Exception as err:  # recorded as status "error", never dropped
                    log.warning("sweep point %s failed: %s: %s", p, type(err).__name__, err)
                    vals.clear()
                    vals["status"] = "error"
                    warm = None
            if spec.threshold:
                vals["damping_threshold"], vals["threshold_status"] = _threshold(
                    spec, p, thresholds)
            # a success always has a finite number (what _verify relies on to tell a
            # legitimate NaN from a lost chunk)
            for st, num in (("status", "power"), ("threshold_status", "damping_threshold")):
                if vals.get(st) in _SUCCESS and not _finite(vals.get(num)):
                    vals[st] = "nonfinite"
            for k, v in vals.items():
                if k.endswith("status"):
                    out[k][idx] = _CODE.get(v, _CODE["other"])
                elif v is not None:
                    out[k][idx] = v
    return out


# -- the store -----------------------------------------------------------------------------

def _attrs(spec: SweepSpec, command: str | None) -> dict:
    from . import __version__

    a = {"title": "parapend design map", "parapend_version": __version__,
         "command": command or "parapend.sweep()", "sweep": spec.to_json(),
         "excitation": spec.excitation, "harmonics": spec.harmonics,
         "conventions": "theta'' + gamma theta' - (1 + q(t)) sin(theta) = T(t), theta from "
                        "the upright; P = -<T theta'> > 0 is harvested (docs/design.md)"}
    if spec.excitation == "square":
        a["square_alpha"] = "default" if spec.square_alpha is None else spec.square_alpha
    if spec.excitation == "fourier":
        a["fourier"] = str(spec.fourier)
    return a


def _var_attrs(name: str) -> dict:
    long, units = VARIABLES[name]
    a = {"long_name": long}
    if units:
        a["units"] = units
    if name.endswith("status"):
        a.update(flag_values=list(range(len(STATUSES))), flag_meanings=" ".join(STATUSES),
                 comment="-1: not computed; success: converged or no_power")
    return a


def _template(spec: SweepSpec, command: str | None):
    """The whole store as a lazy Dataset (dask arrays of fill values) and its encoding."""
    import dask.array as da
    import xarray as xr
    from zarr.codecs import ZstdCodec

    dims, shape, chunks = spec.dims, spec.shape, spec.chunks
    data, enc = {}, {}
    for v in (*spec.variables, "done"):
        if v == "done":
            arr = da.zeros(shape, dtype=bool, chunks=chunks)
            fill = False
            attrs = {"long_name": "block finished (written after the block's data)"}
        elif v.endswith("status"):
            arr = da.full(shape, NOT_COMPUTED, dtype=np.int8, chunks=chunks)
            fill, attrs = NOT_COMPUTED, _var_attrs(v)
        else:
            arr = da.full(shape, np.nan, dtype=float, chunks=chunks)
            fill, attrs = np.nan, _var_attrs(v)
        data[v] = (dims, arr, attrs)
        # zstd with its checksum: a chunk altered on disk fails to decode (found by _verify)
        enc[v] = {"chunks": chunks, "fill_value": fill,
                  "compressors": (ZstdCodec(level=0, checksum=True),)}
    coords = {}
    for a in AXES:
        vals = spec.values[a]
        long, units = _AXIS_ATTRS[a]
        if len(vals) >= 2:
            coords[a] = (a, np.array(vals), {"long_name": long, "units": units})
        elif len(vals) == 1:
            coords[a] = ((), vals[0], {"long_name": long, "units": units})
    ds = xr.Dataset(data, coords=coords, attrs=_attrs(spec, command))
    return ds, enc


@contextlib.contextmanager
def _locked(path: Path):
    """An exclusive, non-blocking ``flock`` on the store's directory for the sweep's time."""
    import fcntl

    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ParameterError(f"store: {str(path)!r} is being written by another parapend "
                                 "sweep; wait for it to finish or choose another --store") \
                from None
        yield
    finally:
        os.close(fd)  # releases the lock


@contextlib.contextmanager
def _quiet_zarr():
    """Zarr warns about foreign files (a ``.partial`` left by a killed write): they are
    removed on resume, and a reader need not see the warning."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Object at .* is not recognized")
        yield


#: The title every sweep store carries in its root attributes.
_TITLE = "parapend design map"
#: ``parapend_store`` of the root ``zarr.json`` a sweep writes first into a store it creates
#: (see :func:`_prepare`): the directory is parapend's, and its creation has not finished.
_CREATING = "creating"
#: A temporary directory that an earlier version's store creation left beside the store
#: (``kill -9``) is removed once it is this old (seconds): a creation takes well under one.
_STALE_SECONDS = 600


def _own_names() -> set:
    """The names a sweep writes at the top of its store (its temporaries aside)."""
    return {*VARIABLES, "done", *AXES, "zarr.json"}


def _short(err: BaseException) -> str:
    return " ".join(str(err).split())[:160] or type(err).__name__


def _root_attrs(path: Path) -> dict | None:
    """The attributes of the Zarr 3 group whose ``zarr.json`` is in ``path``, or None."""
    try:
        meta = json.loads((path / "zarr.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(meta, dict) or meta.get("node_type") != "group":
        return None
    attrs = meta.get("attributes")
    return attrs if isinstance(attrs, dict) else None


def _identify(path: Path) -> tuple[str, str | None]:
    """What the directory ``path`` holds, by what parapend itself writes there: ``("store",
    identity)`` for a sweep store (root attributes with the title and the sweep's identity),
    ``("creating", None)`` for a creation that did not finish (the root ``zarr.json`` that
    :func:`_prepare` writes first), ``("empty", None)`` when it holds nothing but parapend's
    temporaries, else ``("foreign", None)``."""
    attrs = _root_attrs(path)
    if attrs is not None and attrs.get("parapend_store") == _CREATING:
        return "creating", None
    if attrs is not None and attrs.get("title") == _TITLE and isinstance(attrs.get("sweep"),
                                                                         str):
        return "store", attrs["sweep"]
    if all(e.name.startswith(TEMP_PREFIX) for e in path.iterdir()):
        return "empty", None
    return "foreign", None


def _store_spec(path: Path) -> str | None:
    """The sweep identity recorded in a store's root metadata, or None."""
    try:
        return _identify(path)[1]
    except OSError:
        return None


def _write_marker(path: Path) -> None:
    """Make the root ``zarr.json`` of ``path`` say "a parapend store being created", atomically
    (a temporary beside it, then a rename): from then on the directory is recognised as
    parapend's, whatever interrupts the creation."""
    meta = {"zarr_format": 3, "node_type": "group",
            "attributes": {"title": _TITLE, "parapend_store": _CREATING}}
    fd, tmp = tempfile.mkstemp(prefix=TEMP_PREFIX, dir=path)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(json.dumps(meta))
        os.replace(tmp, path / "zarr.json")
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _create(path: Path, spec: SweepSpec, command: str | None) -> None:
    """Write the whole layout into a temporary directory inside the store (so that a
    ``kill -9`` leaves it where the next run on the store removes it), then move its entries
    in, the root ``zarr.json`` last: a store whose root attributes hold the sweep is
    complete."""
    ds, enc = _template(spec, command)
    tmp = Path(tempfile.mkdtemp(prefix=TEMP_PREFIX, dir=path))
    try:
        ds.to_zarr(tmp, mode="w-", compute=False, encoding=enc, consolidated=False,
                   zarr_format=3)
        names = sorted(e.name for e in tmp.iterdir() if e.name != "zarr.json")
        for name in names:
            os.replace(tmp / name, path / name)
        os.replace(tmp / "zarr.json", path / "zarr.json")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _remove(entry: Path) -> None:
    if entry.is_dir() and not entry.is_symlink():
        shutil.rmtree(entry)
    else:
        entry.unlink()


def _remove_stale_temps(parent: Path) -> None:
    """Remove the temporary directories that an earlier version's store creation, killed,
    left beside a store: named ``.tmp-parapend-*``, directories (parapend's other
    temporaries are files), holding nothing but a store's entries (and a root ``zarr.json``
    with a sweep store's title, if any) and untouched for ten minutes."""
    own, now = _own_names(), time.time()
    try:
        entries = [e for e in parent.iterdir() if e.name.startswith(TEMP_PREFIX)]
    except OSError:
        return
    for e in entries:
        try:
            if e.is_symlink() or not e.is_dir() or now - e.stat().st_mtime < _STALE_SECONDS:
                continue
            names = {c.name for c in e.iterdir()}
            if not names or not names <= own:
                continue
            if "zarr.json" in names and (_root_attrs(e) or {}).get("title") != _TITLE:
                continue
            shutil.rmtree(e)
        except OSError:
            continue


def _prepare(path: Path, spec: SweepSpec, command: str | None, overwrite: bool) -> None:
    """Under the lock: create the store, or check that it holds this sweep (resume).

    Only a directory that parapend recognises as its own (a sweep store, a creation cut short,
    or an empty directory) is ever emptied: anything else is refused, ``--overwrite`` or
    not, and so is a store that also holds files parapend did not write."""
    _remove_stale_temps(path.parent if str(path.parent) else Path("."))
    kind, recorded = _identify(path)
    if kind == "foreign":
        raise ParameterError(f"store: {str(path)!r} exists and is not a parapend sweep store "
                             "(parapend never deletes such a directory, --overwrite or not); "
                             "choose another --store")
    if kind == "store" and not overwrite:
        if recorded != spec.to_json():
            raise ParameterError(f"store: {str(path)!r} holds a different sweep (other axes, "
                                 "excitation, harmonics or threshold); choose another "
                                 "--store, or --overwrite to replace it")
        for p in path.rglob("*.partial"):  # a chunk write cut short by kill -9
            with contextlib.suppress(OSError):
                p.unlink()
        return
    # an empty directory, a creation cut short, or --overwrite of a sweep store: emptied,
    # after its root says "being created", and only of the names a sweep writes
    own = _own_names()
    entries = list(path.iterdir())
    extra = sorted(e.name for e in entries
                   if e.name not in own and not e.name.startswith(TEMP_PREFIX))
    if extra:
        raise ParameterError(f"store: {str(path)!r} also holds {extra[0]!r}, which parapend "
                             "did not write; move it away or choose another --store")
    _write_marker(path)
    for e in entries:
        if e.name != "zarr.json":
            with contextlib.suppress(FileNotFoundError):
                _remove(e)
    _create(path, spec, command)


def _check_store_path(store) -> Path:
    if store is None or not str(store).strip():
        raise ParameterError("store: expected a directory name, e.g. map.zarr")
    path = Path(store)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise ParameterError(f"store: directory {str(parent)!r} does not exist")
    if path.exists() and not path.is_dir():
        raise ParameterError(f"store: {str(path)!r} is a file, expected a Zarr store "
                             "(a directory)")
    return path


# -- verifying a store -----------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class _StoredSpec(SweepSpec):
    """A sweep read back from a store's identity: its chunks are the recorded ones."""

    stored_chunks: tuple = ()

    @property
    def chunks(self) -> tuple[int, ...]:
        return self.stored_chunks


def _spec_of(identity) -> SweepSpec | None:
    """The :class:`SweepSpec` (its layout) of a store's recorded identity, or None."""
    try:
        d = json.loads(identity)
        values = {a: tuple(float(v) for v in d["axes"][a]) for a in AXES}
        spec = _StoredSpec(values, str(d["excitation"]), d["square_alpha"], d["fourier"],
                           int(d["harmonics"]), bool(d["threshold"]), None,
                           tuple(int(c) for c in d["chunks"]))
        ok = (len(spec.chunks) == len(spec.dims) >= 1
              and all(1 <= c <= n for c, n in zip(spec.chunks, spec.shape)))
    except (TypeError, ValueError, KeyError, AttributeError):
        return None
    return spec if ok else None


def _damaged(path: Path, what: str) -> ParameterError:
    return ParameterError(f"store: {str(path)!r} is damaged ({what}); compute it again with "
                          "parapend sweep --overwrite, or choose another --store")


def _expected(name: str):
    """dtype and fill value of a store's array."""
    if name == "done":
        return np.dtype(bool), False
    if name.endswith("status"):
        return np.dtype(np.int8), NOT_COMPUTED
    return np.dtype(float), math.nan


def _array(group, path: Path, spec: SweepSpec, name: str):
    """The store's array ``name``, checked against the sweep's layout."""
    import zarr

    try:
        a = group[name]
    except KeyError:
        raise _damaged(path, f"array {name!r} is missing") from None
    except Exception as err:  # noqa: BLE001 - metadata that cannot be read
        raise _damaged(path, f"array {name!r} is unreadable: {_short(err)}") from None
    dtype, fill = _expected(name)
    if not isinstance(a, zarr.Array):
        raise _damaged(path, f"{name!r} is not an array")
    try:
        same_fill = (math.isnan(a.fill_value) if isinstance(fill, float)
                     else a.fill_value == fill)
    except TypeError:
        same_fill = False
    if (np.dtype(a.dtype) != dtype or tuple(a.shape) != spec.shape
            or tuple(a.chunks) != spec.chunks or not same_fill):
        raise _damaged(path, f"array {name!r} is {np.dtype(a.dtype)} {list(a.shape)} in "
                             f"chunks {list(a.chunks)}, fill {a.fill_value}; expected {dtype} "
                             f"{list(spec.shape)} in chunks {list(spec.chunks)}, fill {fill}")
    return a


def _check_coords(group, path: Path, spec: SweepSpec) -> None:
    for a in AXES:
        vals = spec.values[a]
        if not vals:
            continue
        try:
            got = np.asarray(group[a][...], dtype=float)
        except Exception as err:  # noqa: BLE001 - missing or unreadable
            raise _damaged(path, f"coordinate {a!r} is missing or unreadable: "
                                 f"{_short(err)}") from None
        want = np.array(vals) if len(vals) >= 2 else np.array(vals[0])
        if got.shape != want.shape or not np.array_equal(got, want):
            raise _damaged(path, f"coordinate {a!r} differs from the sweep's values")


def _read(a, name: str, spec: SweepSpec, blocks) -> tuple[np.ndarray, set]:
    """All of array ``a`` and the blocks (of ``blocks``) whose chunk cannot be read: at
    once, or block by block when that fails (the others then hold the fill value)."""
    try:
        return np.asarray(a[...]), set()
    except Exception:  # noqa: BLE001 - a chunk that cannot be decoded: found below
        dtype, fill = _expected(name)
        out, bad = np.full(spec.shape, fill, dtype=dtype), set()
        for b in blocks:
            sl = spec.block_slices(b)
            try:
                out[sl] = a[sl]
            except Exception:  # noqa: BLE001 - recorded
                bad.add(b)
        return out, bad


def _chunk_files(path: Path, name: str) -> set:
    """The chunk keys present in array ``name``'s directory (``c/0/3``, ...)."""
    root = path / name
    out = set()
    for d, _, files in os.walk(root):
        rel = os.path.relpath(d, root)
        for f in files:
            if f != "zarr.json" and not f.endswith(".partial"):
                out.add(f if rel == "." else f"{rel}/{f}".replace(os.sep, "/"))
    return out


def _chunk_key(array, spec: SweepSpec, block: int) -> str:
    """The key (relative file name, ``c/0/3``) of a block's chunk in ``array``."""
    return array.metadata.encode_chunk_key(
        tuple(int(i) for i in np.unravel_index(block, spec.block_grid)))


def _verify(path: Path, spec: SweepSpec) -> tuple[np.ndarray, dict]:
    """Check a store against its sweep, cheaply: what a resume or a reader relies on.

    The arrays and coordinates must have the sweep's layout (else :class:`ParameterError`,
    one line). Then every block whose ``done`` mask is set must have every variable's chunk
    present (the data are written with ``write_empty_chunks``: a finished block has them
    all, NaN or not), decodable (zstd with a checksum), a status code at every point and a
    finite power where the status is a success. Returns ``done`` (per block: finished and
    sound) and ``damaged`` (block -> what is wrong), which includes blocks whose mask cannot
    be read.
    """
    import zarr

    nb = spec.blocks
    with _quiet_zarr():
        try:
            group = zarr.open_group(path, mode="r", zarr_format=3)
        except Exception as err:  # noqa: BLE001 - damaged root metadata
            raise _damaged(path, f"its root cannot be read: {_short(err)}") from None
        arrays = {v: _array(group, path, spec, v) for v in ("done", *spec.variables)}
        _check_coords(group, path, spec)
        mask, unreadable = _read(arrays["done"], "done", spec, range(nb))
        damaged = {b: "done: unreadable chunk" for b in unreadable}
        slices = [spec.block_slices(b) for b in range(nb)]
        done = np.array([b not in damaged and bool(mask[slices[b]].all()) for b in range(nb)],
                        dtype=bool)
        finished = np.flatnonzero(done).tolist()
        if not finished:
            return done, damaged
        keys = [_chunk_key(arrays["done"], spec, b) for b in range(nb)]
        values = {}
        for v in spec.variables:
            present = _chunk_files(path, v)
            for b in finished:
                if b not in damaged and keys[b] not in present:
                    damaged[b] = f"{v}: chunk missing"
            values[v], bad = _read(arrays[v], v, spec, [b for b in finished if b not in damaged])
            for b in sorted(bad):
                damaged.setdefault(b, f"{v}: chunk unreadable")
    success = [_CODE[s] for s in _SUCCESS]
    for b in finished:
        if b in damaged:
            continue
        sl = slices[b]
        for st_name, val_name in (("status", "power"),
                                  ("threshold_status", "damping_threshold")):
            if st_name not in values:
                continue
            st = values[st_name][sl]
            if not ((st >= 0) & (st < len(STATUSES))).all():
                damaged[b] = f"{st_name}: a point without a status"
            elif not np.isfinite(values[val_name][sl][np.isin(st, success)]).all():
                damaged[b] = f"{val_name}: NaN where the status is a success"
    for b in damaged:
        done[b] = False
    return done, damaged


def _damage_line(spec: SweepSpec, damaged: dict) -> str:
    points = sum(int(np.prod([s.stop - s.start for s in spec.block_slices(b)]))
                 for b in damaged)
    first = damaged[min(damaged)]
    return (f"{len(damaged)} of {spec.blocks} blocks ({points} points) marked finished have "
            f"missing or unreadable data ({first}{', ...' if len(damaged) > 1 else ''})")


def open_sweep(store, *, complete: bool = False):
    """Open a sweep store (Zarr directory, or a NetCDF export) as an ``xarray.Dataset``.

    A Zarr store is verified first (:func:`_verify`): a store whose creation did not finish,
    or one with missing or unreadable data in a finished block, is refused with one line
    (running the sweep again recomputes those blocks). ``complete=True`` also refuses a
    store whose ``done`` mask is not all set.
    """
    import xarray as xr

    path = Path(store)
    if not path.exists():
        raise ParameterError(f"store: {str(store)!r} does not exist")
    if path.is_dir():
        attrs = _root_attrs(path)
        if attrs is None or attrs.get("title") != _TITLE:
            raise ParameterError(f"store: {str(store)!r} is not a parapend sweep store (no "
                                 "readable zarr.json with a sweep's attributes)")
        if attrs.get("parapend_store") == _CREATING:
            raise ParameterError(f"store: {str(store)!r} was not created completely (the "
                                 "sweep was interrupted while creating it); run the sweep "
                                 "again")
        spec = _spec_of(attrs.get("sweep"))
        if spec is None:
            raise _damaged(path, "its sweep identity cannot be read")
        _, damaged = _verify(path, spec)
        if damaged:
            raise ParameterError(f"store: {str(store)!r} is damaged: "
                                 f"{_damage_line(spec, damaged)}; run the same sweep again "
                                 "(its 'command' attribute) to recompute them")
    try:
        if path.is_dir():
            with _quiet_zarr():
                ds = xr.open_zarr(path, consolidated=False, zarr_format=3).load()
        else:
            with xr.open_dataset(path) as f:
                ds = f.load()
    except Exception as err:  # noqa: BLE001 - any file that is not a readable sweep store
        raise ParameterError(f"store: cannot read {str(store)!r} as a sweep store: "
                             f"{_short(err)}") from None
    if "sweep" not in ds.attrs or "done" not in ds:
        raise ParameterError(f"store: {str(store)!r} is not a parapend sweep store")
    ds["done"] = ds["done"].astype(bool)
    if complete and not bool(ds["done"].all()):
        raise ParameterError(f"store: {str(store)!r} is not complete ({int(ds['done'].sum())} "
                             f"of {ds['done'].size} points); run the same sweep again to "
                             "finish it")
    return ds


# -- running -------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class SweepRun:
    """Outcome of :func:`sweep`: the map and what this run did.

    ``dataset`` has one variable per quantity (see :data:`VARIABLES`) over the swept
    dimensions, plus ``done``; ``computed_points`` were computed by this run,
    ``resumed_points`` found finished in the store; ``repaired_points`` (of the computed)
    were marked finished in the store but had missing or unreadable data.
    """

    dataset: object
    store: str | None
    points: int
    blocks: int
    computed_points: int
    resumed_points: int
    seconds: float
    executor: str
    repaired_points: int = 0


def _worker_init(parent: int) -> None:
    """A pool worker ignores Ctrl-C (the parent handles it) and exits when the parent is
    gone (``kill -9``: the pool's queues would keep it waiting for ever)."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch():
        while True:
            time.sleep(0.5)
            try:
                os.kill(parent, 0)
            except ProcessLookupError:
                os._exit(1)
            except OSError:
                pass

    threading.Thread(target=watch, daemon=True).start()


class _LocalPool:
    """The local worker processes (a ``forkserver`` pool), started in the background as soon
    as the sweep's parameters are checked: the server's imports and the workers' start (about
    a second) then overlap the preparation of the store instead of preceding the first block.
    """

    def __init__(self, workers: int, start: bool = True):
        self.workers = workers
        self.executor = None
        self._boot = None
        if start:
            self.start()

    def start(self):
        """Start the processes in the background (once)."""
        import concurrent.futures as cf
        import multiprocessing as mp
        import threading

        if self.executor is not None:
            return
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(["parapend.sweep", "parapend.api", "parapend.optimal.fourier",
                                    "parapend.optimal.batch"])
        self.executor = cf.ProcessPoolExecutor(max_workers=self.workers, mp_context=ctx,
                                               initializer=_worker_init,
                                               initargs=(os.getpid(),))
        self._boot = threading.Thread(target=self._submit_first, daemon=True)
        self._boot.start()

    def _submit_first(self):
        # the first submit starts every worker (in this thread, not the caller's)
        with contextlib.suppress(Exception):
            self.executor.submit(_ready)

    def shutdown(self):
        if self.executor is not None:
            self._boot.join()
            self.executor.shutdown(wait=True, cancel_futures=True)


def _ready() -> None:
    """A first task: it makes the pool start its processes."""


def _run_local(spec, todo, pool, done_cb):
    import concurrent.futures as cf

    if pool is None or len(todo) <= 1:
        for b in todo:
            done_cb(b, compute_block(spec, b))
        return "serial"
    pool.start()
    pool._boot.join()
    ex = pool.executor
    try:
        futs = {ex.submit(compute_block, spec, b): b for b in todo}
        for f in cf.as_completed(futs):
            try:
                vals = f.result()
            except cf.process.BrokenProcessPool:
                raise SolverError("a worker process died (killed, or out of memory); the "
                                  "finished blocks are in the store: run the same command "
                                  "again to resume") from None
            done_cb(futs[f], vals)
    except BaseException:
        # Ctrl-C or an error: the running blocks would not be written, so they are not
        # waited for (a block with a power take-off can take half a minute)
        _stop_workers(ex)
        raise
    finally:
        ex.shutdown(wait=True, cancel_futures=True)
    return f"{pool.workers} local processes"


def _stop_workers(ex) -> None:
    """End the worker processes of the executor ``ex`` now (SIGTERM)."""
    terminate = getattr(ex, "terminate_workers", None)  # Python 3.14
    if terminate is not None:
        with contextlib.suppress(Exception):
            terminate()
        return
    for proc in list((getattr(ex, "_processes", None) or {}).values()):
        with contextlib.suppress(Exception):
            proc.terminate()


def _connect(scheduler):
    """A distributed Client for ``scheduler`` (an address or a Client), and whether we own it:
    connected before the store is touched, so a wrong address leaves nothing behind."""
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("scheduler: needs the 'distributed' package (python -m pip "
                             "install distributed)") from None
    if hasattr(scheduler, "submit"):
        return scheduler, False
    address = str(scheduler).strip()
    try:
        from distributed.comm.addressing import parse_address, parse_host_port

        scheme, location = parse_address(address)
        if scheme in ("tcp", "tls"):
            parse_host_port(location)
    except (ValueError, TypeError) as err:
        raise ParameterError(f"scheduler: expected an address such as tcp://host:8786, got "
                             f"{address!r:.80} ({_short(err)})") from None
    # made in two steps so that a client whose start fails can be discarded here (left to
    # the garbage collector it would wait 20 s to close, then print a traceback), and in a
    # thread: distributed waits for ever on a server that accepts the connection but never
    # answers its handshake, and Ctrl-C must not wait for it either
    client = Client.__new__(Client)
    failed: list = []

    def start():
        try:
            client.__init__(address, timeout=f"{_CONNECT_SECONDS}s", set_as_default=False)
        except BaseException as err:  # noqa: BLE001 - handed to the caller's thread
            failed.append(err)

    thread = threading.Thread(target=start, name="parapend-connect", daemon=True)
    thread.start()
    try:
        thread.join(2 * _CONNECT_SECONDS)
    except BaseException:  # Ctrl-C
        _discard(client)
        raise
    if thread.is_alive():
        _discard(client)
        raise ParameterError(f"scheduler: cannot connect to {address!r:.80}: no answer within "
                             f"{2 * _CONNECT_SECONDS} s (is it a Dask scheduler?)")
    if failed:
        err = failed[0]
        _discard(client)
        why = (_short(err) if isinstance(err, (OSError, TimeoutError, ValueError))
               else "what answers there is not a Dask scheduler")
        raise ParameterError(f"scheduler: cannot connect to {address!r:.80}: {why}") \
            from None
    return client, True


#: seconds to connect to a Dask scheduler (twice that for its first answer)
_CONNECT_SECONDS = 10


def _discard(client) -> None:
    """Forget a Client that did not start or did not close: no 20 s close at collection."""
    with contextlib.suppress(Exception):
        client.status = "closed"
    with contextlib.suppress(Exception):
        client._loop_runner.stop()


def _close(client) -> None:
    """Close a Client we opened, within 2 s (a Ctrl-C must not wait for a slow scheduler)."""
    try:
        client.close(timeout=2)
    except Exception:  # noqa: BLE001 - a scheduler that does not answer: let it be
        _discard(client)


def _run_dask(spec, todo, client, done_cb):
    from distributed import as_completed

    futs = {client.submit(compute_block, spec, b, pure=False): b for b in todo}
    for f in as_completed(list(futs), loop=client.loop):
        try:
            vals = f.result()
        except (KeyboardInterrupt, ParameterError):
            raise
        except Exception as err:  # a lost worker, a worker without parapend, ...
            raise SolverError(f"a block failed on the Dask cluster ({type(err).__name__}: "
                              f"{' '.join(str(err).split())[:160]}); the finished blocks are "
                              "in the store: run the same command again to resume") from None
        done_cb(futs[f], vals)
        f.release()
    return f"Dask cluster at {client.scheduler.address}"


def sweep(store=None, *, omega=1.8, delta=None, gamma=0.0, torque_limit=None, efficiency=None,
          harmonics: int = 24, excitation=None, square_alpha=None, fourier=None,
          threshold: bool = False, workers: int | None = None, scheduler=None,
          overwrite: bool = False, command: str | None = None, progress=None,
          block_points: int | None = None) -> SweepRun:
    """A design map: the optimum (and more) at every point of a grid; see the module text.

    Parameters
    ----------
    store : path or None
        Zarr store (a directory, e.g. ``map.zarr``) written block by block and resumed when
        it already holds this sweep; None computes in memory.
    omega, delta, gamma, torque_limit, efficiency : number, sequence, or str
        One value, a sequence, ``"START:STOP:COUNT"`` or ``"A,B,C"`` (:func:`parse_axis`).
        ``torque_limit`` or ``efficiency`` makes each point :func:`parapend.pto.optimize_pto`.
    harmonics : int
        N of every solve (at most 128).
    excitation, square_alpha, fourier
        As :func:`parapend.optimize` (not "file").
    threshold : bool
        Also compute gamma* (:func:`parapend.threshold`) for every (omega, delta).
    workers : int or None
        Local processes (default: the number of CPUs, at most the number of blocks).
    scheduler : str or distributed.Client or None
        Address of a Dask distributed scheduler (``tcp://host:8786``), or a Client: the
        blocks run there, and are written here as they finish.
    overwrite : bool
        Replace a store that holds a different sweep. A directory that is not a parapend
        sweep store (or a store holding files a sweep does not write) is refused either
        way, never deleted.
    command : str or None
        The command line, recorded in the attributes (the first run's stays).
    progress : callable or None
        ``progress(done_points, total_points)`` after each block.
    block_points : int or None
        Points per block (one chunk, one task), about: default 512 (8 with a power
        take-off). Part of the sweep's identity, as it sets where continuation runs start.
    """
    spec = sweep_spec(omega=omega, delta=delta, gamma=gamma, torque_limit=torque_limit,
                      efficiency=efficiency, harmonics=harmonics, excitation=excitation,
                      square_alpha=square_alpha, fourier=fourier, threshold=threshold,
                      block_points=block_points)
    if workers is not None:
        workers = check_int("workers", workers, 1, 256)
    else:
        workers = max(1, min(os.cpu_count() or 1, spec.blocks))
    t0 = time.monotonic()
    client, own = _connect(scheduler) if scheduler is not None else (None, False)
    # the pool starts at once unless the store holds this sweep already (a resume, where
    # there may be nothing left to do): then only when blocks are left
    resume = (store is not None and not overwrite
              and _store_spec(_check_store_path(store)) == spec.to_json())
    pool = (_LocalPool(workers, start=not resume)
            if client is None and workers > 1 and spec.blocks > 1 else None)
    try:
        return _sweep(spec, store, pool, client, overwrite, command, progress, t0)
    finally:
        if pool is not None:
            pool.shutdown()
        if own:
            _close(client)


def _sweep(spec, store, pool, client, overwrite, command, progress, t0) -> SweepRun:
    total = spec.points
    sizes = [int(np.prod([s.stop - s.start for s in spec.block_slices(b)]))
             for b in range(spec.blocks)]
    if store is None:
        ds, _ = _template(spec, command)
        ds = ds.compute()
        arrays = {v: ds[v].values.copy() for v in (*spec.variables, "done")}
        counted = [0]

        def write(b, vals):
            sl = spec.block_slices(b)
            for k, v in vals.items():
                arrays[k][sl] = v
            arrays["done"][sl] = True
            counted[0] += sizes[b]
            if progress is not None:
                progress(counted[0], total)

        how = _execute(spec, list(range(spec.blocks)), pool, client, write)
        for k, v in arrays.items():
            ds[k] = (spec.dims, v, ds[k].attrs)
        return SweepRun(ds, None, total, spec.blocks, total, 0, time.monotonic() - t0, how)
    path = _check_store_path(store)
    path.mkdir(exist_ok=True)
    try:
        return _sweep_store(spec, path, pool, client, overwrite, command, progress, t0,
                            sizes)
    except OSError as exc:  # a full disk, a store made read-only, ...
        raise OutputError(f"cannot write {str(path)!r}: {_short_os(exc)}; the finished blocks "
                          "are in the store: run the same command again to resume") from None


def _short_os(exc: OSError) -> str:
    return " ".join(str(exc.strerror or exc).split())[:160]


def _sweep_store(spec, path, pool, client, overwrite, command, progress, t0, sizes):
    import zarr

    total = spec.points
    with _locked(path):
        _prepare(path, spec, command, overwrite)
        done, damaged = _verify(path, spec)
        with _quiet_zarr():
            group = zarr.open_group(path, mode="r+", zarr_format=3)
            # every chunk of a finished block is written, also one that equals the fill
            # value (all NaN): so a missing chunk is always damage (_verify)
            arrays = {k: group[k].with_config({"write_empty_chunks": True})
                      for k in spec.variables}
            mask = group["done"]
        if damaged:
            log.warning("store %s: %s; recomputed", path, _damage_line(spec, damaged))
            # not finished until recomputed: the mask's chunk goes first, then the data's
            # (a chunk that cannot be decoded is never read back to be updated)
            for b in sorted(damaged):
                for k in ("done", *spec.variables):
                    with contextlib.suppress(FileNotFoundError):
                        os.unlink(path / k / _chunk_key(mask, spec, b))
        todo = [b for b in range(spec.blocks) if not done[b]]
        repaired = sum(sizes[b] for b in damaged)
        resumed = total - sum(sizes[b] for b in todo)
        counted = [resumed]
        if progress is not None:
            progress(resumed, total)

        def write(b, vals):
            sl = spec.block_slices(b)
            for k in spec.variables:  # the data first, then the mask
                arrays[k][sl] = vals[k]
            mask[sl] = np.ones(vals["status"].shape, dtype=bool)
            counted[0] += sizes[b]
            if progress is not None:
                progress(counted[0], total)

        how = _execute(spec, todo, pool, client, write) if todo else "nothing to do"
    ds = open_sweep(path)
    return SweepRun(ds, str(path), total, spec.blocks, total - resumed, resumed,
                    time.monotonic() - t0, how, repaired)


def _execute(spec, todo, pool, client, write) -> str:
    if client is not None:
        return _run_dask(spec, todo, client, write)
    return _run_local(spec, todo, pool, write)


# -- heat maps -----------------------------------------------------------------------------

#: What ``parapend map`` can draw: a variable of the store, or ``gain`` (over uniform).
MAP_QUANTITIES = ("power", "gain", "damping_threshold", "uniform_power", "limit_power",
                  "electrical_power", "branch_gap")
_PAPER = {"omega": 1.8, "delta": -0.3, "gamma": 0.0}
_SHORT = {"power": "optimal power P", "gain": "gain over the best uniform rotation",
          "damping_threshold": "damping threshold gamma*",
          "uniform_power": "power of the best uniform rotation",
          "limit_power": "limit power (gamma -> 0)", "electrical_power": "electrical power",
          "branch_gap": "continued branch above the global search"}
_LABELS = {"omega": r"$\omega$", "delta": r"$\delta$", "gamma": r"$\gamma$",
           "torque_limit": r"$T_{max}$", "efficiency": r"$\eta$"}


def map_data(ds, quantity: str = "power", x: str | None = None, y: str | None = None,
             at: dict | None = None):
    """The 2-D slice a heat map shows: ``(values over (y, x), failed mask, title, label)``.

    ``gain`` is ``power / uniform_power - 1`` in percent. Points not computed are NaN;
    failed points (status other than converged and no_power) are NaN and flagged.
    Dimensions other than ``x`` and ``y`` are selected by ``at`` (nearest value; default
    their first value).
    """
    if quantity not in MAP_QUANTITIES:
        raise ParameterError(f"variable: expected one of {', '.join(MAP_QUANTITIES)}, got "
                             f"{quantity!r:.40}")
    need = "power" if quantity == "gain" else quantity
    if need not in ds:
        raise ParameterError(f"variable: {quantity!r} is not in this store (threshold maps "
                             "need a sweep with --threshold)")
    dims = [d for d in AXES if d in ds.dims]
    if len(dims) < 2:
        raise ParameterError(f"store: a heat map needs two swept axes, this store has "
                             f"{', '.join(dims) or 'none'}")
    x = x or dims[0]
    y = y or next(d for d in dims if d != x)
    for name, v in (("x", x), ("y", y)):
        if v not in dims:
            raise ParameterError(f"{name}: expected one of the store's axes "
                                 f"{', '.join(dims)}, got {v!r:.40}")
    if x == y:
        raise ParameterError("x, y: expected two different axes")
    at = dict(at or {})
    for k in at:
        if k not in dims or k in (x, y):
            raise ParameterError(f"at: {k!r:.40} is not another axis of the store "
                                 f"({', '.join(d for d in dims if d not in (x, y)) or 'none'})")
    sel = {d: ds[d].values[0] for d in dims if d not in (x, y)}
    sel.update(at)
    sub = ds.sel(sel, method="nearest") if sel else ds
    sub = sub.transpose(y, x)
    status = sub["status"]
    ok = sub["done"].values & np.isin(status.values, [_CODE[s] for s in _SUCCESS])
    failed = sub["done"].values & ~ok
    if quantity == "gain":  # as optimize's gain_over_uniform: none where uniform <= 0
        pu = sub["uniform_power"].values
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(pu > 0, 100.0 * (sub["power"].values / pu - 1.0), np.nan)
    else:
        z = np.array(sub[quantity].values, dtype=float)
    label = _SHORT[quantity]
    units = "%" if quantity == "gain" else VARIABLES[quantity][1]
    label = f"{label} ({units})" if units else label
    if quantity == "damping_threshold":
        ok = sub["done"].values & np.isin(sub["threshold_status"].values,
                                          [_CODE[s] for s in _SUCCESS])
        failed = sub["done"].values & ~ok
    z = np.where(ok, z, np.nan)
    fixed = {**{a: float(ds[a]) for a in AXES if a in ds.coords and ds[a].ndim == 0},
             **{k: float(sub[k]) for k in sel}}
    if quantity == "damping_threshold":  # gamma* depends on the excitation only
        fixed = {k: v for k, v in fixed.items() if k in ("omega", "delta")}
    title = ", ".join(f"{k} = {v:.4g}" for k, v in fixed.items())
    return z, failed, sub[x].values, sub[y].values, x, y, label, title


def plot_map(ds, quantity: str = "power", x=None, y=None, at=None, path=None):
    """Heat map of ``quantity`` over two axes, with labelled contour lines, the zero
    contour of the power (where it crosses gamma*) in black, failed points crossed, and the
    paper's case (omega = 1.8, delta = -0.3, gamma = 0) marked when inside the map."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from .fileio import save_figure
    from .style import figure_style

    z, failed, xs, ys, xn, yn, label, title = map_data(ds, quantity, x, y, at)
    with figure_style():
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
        cmap = plt.get_cmap("viridis").with_extremes(bad="0.85")
        finite = np.isfinite(z)
        lo, hi = (np.percentile(z[finite], [1, 99]) if finite.sum() >= 100 else
                  (np.nanmin(z), np.nanmax(z)) if finite.any() else (0.0, 1.0))
        # a few extreme points (the gain where the uniform rotation's power tends to 0)
        # would flatten the rest: the colours span the 1st to 99th percentile
        clipped = finite.any() and (np.nanmin(z) < lo or np.nanmax(z) > hi)
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(z), shading="nearest", cmap=cmap,
                             vmin=lo, vmax=hi)
        cb = fig.colorbar(mesh, ax=ax, extend="both" if clipped else "neither")
        cb.set_label(label)
        if min(z.shape) >= 3 and finite.sum() >= 9 and hi > lo:
            cs = ax.contour(xs, ys, np.ma.masked_invalid(z), levels=np.linspace(lo, hi, 9)[1:-1],
                            colors="white", linewidths=0.7)
            ax.clabel(cs, fontsize=7, fmt="%.3g")
            if quantity in ("power", "electrical_power") and np.nanmin(z) < 0 < np.nanmax(z):
                ax.contour(xs, ys, np.ma.masked_invalid(z), levels=[0.0], colors="black",
                           linewidths=1.2)
        if failed.any():
            yy, xx = np.nonzero(failed)
            ax.plot(xs[xx], ys[yy], "x", color="red", ms=4, label="failed (see status)")
        px, py = _PAPER.get(xn), _PAPER.get(yn)
        if (px is not None and py is not None and xs.min() <= px <= xs.max()
                and ys.min() <= py <= ys.max()):
            ax.plot([px], [py], marker="*", color="red", ms=12, mec="white", ls="none",
                    label=r"paper's case ($\omega$ = 1.8, $\delta$ = -0.3)")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best")
        for name, setter in ((xn, ax.set_xlabel), (yn, ax.set_ylabel)):
            unit = _AXIS_ATTRS[name][1]
            setter(_LABELS[name] + ("" if unit == "1" else f" ({unit})"))
        ax.grid(False)
        if title:
            ax.set_title(title)
        fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig
