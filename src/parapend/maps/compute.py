"""One block of a sweep: the global searches of its points together, then the continuation
along each run (:func:`compute_block`). Runs in the worker processes (local pool or Dask):
they import it as ``parapend.maps.compute``; it reads the spec and writes nothing.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .spec import _CODE, _SUCCESS, AXES, NOT_COMPUTED, SweepSpec

__all__ = ["compute_block"]

log = logging.getLogger(__name__)

_BRANCH_TOL = 1e-9
#: a continuation whose first Newton step lands this close to the global search's maximum
#: (max-norm of the coefficients, relative to max(1, |x|)) is on that maximum's branch
_SAME_BRANCH = 1e-4
#: global searches run together at most this many at a time: 64 to 128 points cost 0.74 to
#: 0.77 ms each, 512 points 0.91 ms (the Hessians of a batch leave the cache)
_BATCH_POINTS = 128
#: and at most this many Hessian entries per batch (4 MiB of doubles; N = 24 allows 218)
_BATCH_ENTRIES = 1 << 19


# -- one block -----------------------------------------------------------------------------

def _continue(exc, n: int, gamma: float, found, problem, warm, first=None):
    """What optimize computes (power, status) from the point's global search ``found``, plus
    the continuation check from the neighbour's optimum ``warm``; see the module docstring.
    ``problem``: the search's N-harmonic problem (reused when ``best`` is on its grid);
    ``first``: ``problem.evaluate`` at the padded ``warm`` when computed already (with the
    other points of the block). Returns (power, status, branch_gap, x for the next point)."""
    from ..optimal.fourier import FourierProblem, _ascent_step, _pad, newton_maximize

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
    from ..optimal import batch
    from ..optimal.fourier import search_fourier

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
    from ..optimal.batch import ProblemBatch
    from ..optimal.fourier import _pad

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
    from ..api import build_excitation
    from ..optimal.limit import limit
    from ..power import uniform_power

    kw = spec.excitation_args(p["omega"], p.get("delta"))
    out: dict = {}
    try:
        exc = build_excitation(**kw)
        gamma = p["gamma"]
        lim = limit(exc)
        out["uniform_power"] = uniform_power(exc, gamma)[0]
        out["limit_power"] = lim.power
        if spec.pto:
            from ..pto import optimize_pto

            r = optimize_pto(torque_limit=p.get("torque_limit"), efficiency=p.get("efficiency"),
                             gamma=gamma, harmonics=spec.harmonics, **kw)
            out.update(power=r.power, electrical_power=r.electrical_power, status=r.status)
            if spec.lossy:  # the headline is the electrical power, as optimize's
                out.update(power=r.electrical_power, mechanical_power=r.power)
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
    from ..api import threshold

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
    own = getattr(spec, "compute_block", None)  # another product on the engine
    if own is not None:
        return own(block)
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
