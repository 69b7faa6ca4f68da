"""Basins of attraction of paper Eq. 1 on a grid of initial conditions (paper Fig. 2 right).

Initial conditions ``(phi, phi')`` at ``t = t0`` (default 0), ``phi`` from the hanging
position on ``n_phi`` points ``phi_i = -pi + 2*pi*i/n_phi`` covering ``[-pi, pi)``, ``phi'``
on ``n_dphi`` points spanning ``dphi_range`` (ends included). Each is integrated by the
vectorized engine of :mod:`parapend.dynamics.attractors` and labelled with the attractor
it reaches (0 = "other": chaotic or unresolved within the period budget).

Symmetry. Eq. 1 is invariant under ``(phi, phi') -> (-phi, -phi')`` and the RK4 map of
:mod:`.simulate` commutes with it exactly (every operation is odd in the state, rounding
included). On a grid symmetric under it (``dphi_range`` symmetric about 0, the whole
circle in ``phi``) the map is mirror-symmetric by construction: only the columns
``0 <= i <= n_phi/2`` are integrated, the two that are their own mirror image (``phi = -pi``
and, ``n_phi`` even, ``phi = 0``) only for ``phi' >= 0``, and every other point is the mirror
image of an integrated one, with each attractor replaced by its mirror (``P1 rotation (+)``
<-> ``P1 rotation (-)``). The integrated initial angles are ``theta_i = pi*m_i/n_phi``
(project convention, ``m_i`` an even integer in ``(-n_phi, n_phi]``) so that mirror pairs
are exact negatives; this is the same point as ``phi_i`` up to one rounding. (The column
``phi = 0``, ``theta = pi``, is the exception: its mirror ``theta = -pi`` is the same state
with other bits, so integrating both of its halves broke the symmetry where basins are
intertwined.)

Accuracy. Where basins are intertwined a label is not a property of the grid point: any
perturbation below the pixel size can change it. Every map re-runs a seeded random sample of
its integrated points (a) with twice the steps per period and (b) from the initial
condition moved by :data:`PERTURBATION`, and reports the share of labels that change as an
estimate of the mislabelled share with a 95 % interval (Wilson lower bound of the share
changed by both, upper bound of the share changed by either), and for each basin a bound on
the shift of its share (``basin_fraction_error``); see ``docs/dynamics.md``.
"""

from __future__ import annotations

import json
import math
import time

import numpy as np
import xarray as xr

from ..errors import ParameterError, check_finite, check_int
from .attractors import (
    Attractor,
    _check_engine,
    _check_search,
    _dist,
    _Entry,
    _finalize,
    _rerun,
    _resolve_workers,
    _run_search,
    _wrap,
)
from .simulate import CONVENTION, _check_params

__all__ = ["basin_map", "grid"]


def _range(name, rng):
    try:
        lo, hi = (check_finite(name, x) for x in rng)
    except TypeError:
        raise ParameterError(f"{name}: expected (low, high), got {rng!r}") from None
    if hi <= lo:
        raise ParameterError(f"{name}: expected low < high, got {rng!r}")
    return lo, hi


def grid(n_phi: int = 200, n_dphi: int = 200,
         dphi_range: tuple[float, float] = (-3.0, 3.0),
         phi_range: tuple[float, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Grid axes of :func:`basin_map`.

    Returns
    -------
    phi : ndarray, shape (n_phi,)
        ``-pi + 2*pi*i/n_phi`` (angle from hanging, Eq. 1 convention), covering ``[-pi, pi)``;
        with ``phi_range = (a, b)``, ``n_phi`` points from ``a`` to ``b``, ends included.
    dphi : ndarray, shape (n_dphi,)
        ``n_dphi`` points from ``dphi_range[0]`` to ``dphi_range[1]``, exactly antisymmetric
        when the range is symmetric about 0.
    """
    n_phi = check_int("n_phi", n_phi, 2)
    n_dphi = check_int("n_dphi", n_dphi, 2)
    lo, hi = _range("dphi_range", dphi_range)
    if phi_range is None:
        phi = math.pi * (2.0 * np.arange(n_phi) - n_phi) / n_phi
    else:
        a, b = _range("phi_range", phi_range)
        phi = a + (b - a) * np.arange(n_phi, dtype=float) / (n_phi - 1)
    j = np.arange(n_dphi, dtype=float)
    if lo == -hi:
        dphi = hi * (2.0 * j - (n_dphi - 1)) / (n_dphi - 1)
    else:
        dphi = lo + (hi - lo) * j / (n_dphi - 1)
    return phi, dphi


def _theta_grid(n_phi: int) -> np.ndarray:
    """``theta_i = pi*m_i/n`` with ``m_i = 2i`` wrapped into ``(-n, n]`` (mirror-exact)."""
    m = 2 * np.arange(n_phi)
    m = np.where(m <= n_phi, m, m - 2 * n_phi)
    return math.pi * m.astype(float) / n_phi


def _mirror_entries(entries: list[_Entry], match_tol: float) -> list[int]:
    """Index of the mirror image of each entry (appending mirrors not yet in the list)."""
    out = []
    n = len(entries)
    for e in range(n):
        ent = entries[e]
        mth, mv = _wrap(-ent.theta), -ent.v
        found = -1
        for f, other in enumerate(entries):
            if other.period == ent.period and other.winding == -ent.winding:
                d = np.min(np.maximum(np.abs(_wrap(other.theta - mth[0])),
                                      np.abs(other.v - mv[0])))
                if d < match_tol:
                    found = f
                    break
        if found < 0:
            entries.append(_Entry(ent.period, -ent.winding, mth, mv, ent.kind,
                                  refined=ent.refined, capture=ent.capture))
            found = len(entries) - 1
        out.append(found)
    return out


def _split(labels, phase, attractors):
    """One code per (attractor, phase); Poincare points rolled to start at that phase."""
    new_labels = np.zeros_like(labels)
    out = []
    for a in attractors:
        for j in range(a.period):
            code = len(out) + 1
            mask = (labels == a.code) & (phase == j)
            new_labels[mask] = code
            name = a.name if a.period == 1 else f"{a.name} [phase {j}]"
            out.append(Attractor(code, name, a.kind, a.period, a.winding, a.direction,
                                 np.roll(a.phi, -j), np.roll(a.dphi, -j),
                                 int(np.count_nonzero(mask)), a.capture_verified))
    legend = {0: "other"}
    legend.update({a.code: a.name for a in out})
    return new_labels, tuple(out), legend


#: relative move of the initial condition in the perturbed re-run of the accuracy check
PERTURBATION = 1e-6
_Z95 = 1.959963984540054        # standard normal quantile 0.975


def wilson_interval(k: float, n: int, z: float = _Z95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion ``k/n`` (95 % for the default ``z``).

    Returns ``(low, high)``; ``(0, 1)`` for ``n = 0``. ``k`` may be fractional (an average of
    two counts, as for mirror pairs).
    """
    if n <= 0:
        return 0.0, 1.0
    ph = k / n
    den = 1.0 + z * z / n
    centre = (ph + z * z / (2 * n)) / den
    half = z * math.sqrt(max(ph * (1 - ph), 0.0) / n + z * z / (4.0 * n * n)) / den
    lo = 0.0 if k <= 0 else max(0.0, centre - half)
    hi = 1.0 if k >= n else min(1.0, centre + half)
    return lo, hi


def _phases(entries, raw, used, end_th, end_v):
    """Phase of each point on its entry, as :func:`~.attractors._finalize` computes it."""
    phase = np.full(raw.shape, -1, dtype=np.int64)
    for e in np.unique(raw[raw >= 0]):
        ent = entries[e]
        roll = int(np.argmin(_wrap(ent.theta - math.pi)))
        th, v = np.roll(ent.theta, -roll), np.roll(ent.v, -roll)
        mine = np.flatnonzero(raw == e)
        d = np.array([_dist(end_th[mine], end_v[mine], a, b) for a, b in zip(th, v)])
        phase[mine] = (np.argmin(d, axis=0) - used[mine]) % ent.period
    return phase


def _recheck(entries, th0, v0, raw, used, end_th, end_v, n_check, seed, search, steps,
             engine):
    """Re-run a seeded random sample of the integrated points twice: (a) with twice the
    steps per period, (b) at the same steps from an initial condition moved by
    :data:`PERTURBATION` in a random direction. New attractors join ``entries``."""
    rng = np.random.default_rng(seed)
    k = min(n_check, th0.size)
    pick = np.sort(rng.choice(th0.size, size=k, replace=False))
    ang = rng.uniform(0.0, 2 * math.pi, size=k)
    out = {"pick": pick}
    out["orig"] = (raw[pick], used[pick], end_th[pick], end_v[pick])
    out["a"] = _rerun(th0[pick], v0[pick], entries, steps=2 * steps, engine=engine, **search)
    out["b"] = _rerun(th0[pick] + PERTURBATION * np.cos(ang),
                      v0[pick] + PERTURBATION * np.sin(ang), entries, steps=steps,
                      engine=engine, **search)
    return out


def _code_of_entries(entries, raw, labels):
    """Map code of each entry (-1: reached by no grid point); index -1 (raw "other") -> 0."""
    code_of = np.full(len(entries) + 1, -1, dtype=np.int64)
    code_of[-1] = 0
    flat_raw, flat_lab = raw.ravel(), labels.ravel()
    for e in range(len(entries)):
        hit = np.flatnonzero(flat_raw == e)
        if hit.size:
            code_of[e] = flat_lab[hit[0]]
    return code_of


def _accuracy(check, entries, code_of, mirror, split_code, ncode, parent, steps, n_check,
              seed, population, use_sym):
    """The ``accuracy`` record and the per-code bound on the basin-fraction error."""
    frac_err = np.full(ncode, np.nan)
    if check is None:
        return {"sample": 0, "method": "not estimated (accuracy_sample = 0)"}, frac_err
    n = check["pick"].size
    keys = {}
    changed = {}
    for name in ("orig", "a", "b"):
        raw, used, eth, ev = check[name][:4]
        keys[name] = (np.asarray(raw), _phases(entries, np.asarray(raw), np.asarray(used),
                                               np.asarray(eth), np.asarray(ev)))
    for name in ("a", "b"):
        ch = keys[name][0] != keys["orig"][0]
        if split_code is not None:
            ch |= keys[name][1] != keys["orig"][1]
        changed[name] = ch
    either = changed["a"] | changed["b"]
    both = changed["a"] & changed["b"]
    ka, kb, kab, k2 = (int(np.count_nonzero(x)) for x in (changed["a"], changed["b"], either,
                                                          both))
    lo = wilson_interval(k2, n)[0]
    hi = wilson_interval(kab, n)[1]
    # per attractor: the shift of its share when the sample is relabelled by (a) or (b),
    # d_i = [new label is c] - [old label is c]; bound |mean d| + z sqrt(p_hi/n), p_hi the
    # Wilson upper bound of the share of points whose change involves c (var d <= p); on a
    # symmetric grid each sampled point also stands for its mirror image
    unsplit = ncode if parent is None else int(parent.max()) + 1
    views = [lambda r: r]
    if use_sym and mirror is not None:
        views.append(lambda r: np.where(r >= 0, mirror[np.clip(r, 0, mirror.size - 1)], -1))
    err = np.zeros(unsplit)
    for name in ("a", "b"):
        for c in range(unsplit):
            d = np.zeros(n)
            inv = np.zeros(n)
            for view in views:
                old = code_of[view(keys["orig"][0])] == c
                new = code_of[view(keys[name][0])] == c
                if split_code is not None:     # a change of phase moves a point between codes
                    new &= keys[name][1] == keys["orig"][1]
                d += (new.astype(float) - old) / len(views)
                inv += (changed[name] & (old | new)) / len(views)
            p_hi = wilson_interval(float(inv.sum()), n)[1]
            err[c] = max(err[c], abs(d.mean()) + _Z95 * math.sqrt(p_hi / n))
    frac_err = err if parent is None else err[parent]
    record = {
        "method": ("a seeded random sample of the integrated initial conditions is re-run "
                   "(a) with twice the RK4 steps per period and (b) from the initial "
                   f"condition moved by {PERTURBATION:g} in a random direction; a label is "
                   "uncertain when it changes. Estimate: the mean of the fractions changed "
                   "by (a) and by (b); 95 % interval: from the Wilson lower bound of the "
                   "fraction changed by both to the Wilson upper bound of the fraction "
                   "changed by either"),
        "sample": n, "population": int(population), "seed": seed,
        "refined_steps_per_period": 2 * steps, "perturbation": PERTURBATION,
        "changed_refined": ka, "changed_perturbed": kb, "changed_both": k2,
        "changed_either": kab, "mislabel_fraction": (ka + kb) / (2 * n) if n else math.nan,
        "mislabel_interval": [lo, hi], "confidence": 0.95,
        "phases_compared": split_code is not None,
    }
    return record, frac_err


def basin_map(gamma: float, p: float, omega: float, *, n_phi: int = 200, n_dphi: int = 200,
              dphi_range: tuple[float, float] = (-3.0, 3.0),
              phi_range: tuple[float, float] | None = None, periods: int = 300,
              steps_per_period: int = 128, t0: float = 0.0, tol: float = 1e-6,
              max_period: int = 8, capture_radius: float = 0.05, symmetric: bool = True,
              split_phases: bool = False, pilot: bool = True, workers: int | None = None,
              engine: str = "numba", progress=None, accuracy_sample: int = 1000,
              accuracy_seed: int = 0) -> xr.Dataset:
    """Basins of attraction of paper Eq. 1 on an ``(phi, phi')`` grid at ``t = t0``.

    Parameters
    ----------
    gamma, p, omega : float
        Damping (>= 0), excitation strength and frequency (> 0) of Eq. 1.
    n_phi, n_dphi : int
        Grid size (see :func:`grid`).
    dphi_range : (float, float)
        Range of initial ``phi'`` (ends included).
    phi_range : (float, float), optional
        Range of initial ``phi`` (ends included); default the whole circle ``[-pi, pi)``
        (see :func:`grid`). A custom range is integrated without the symmetry.
    periods : int
        Budget of forcing periods per trajectory.
    steps_per_period, t0, tol, max_period, capture_radius, pilot
        As :func:`parapend.dynamics.find_attractors`.
    workers : int, optional
        Threads: default every core for ``engine="numba"``, 1 for ``"numpy"``. Labels do
        not depend on it.
    engine : {"numba", "numpy"}
        ``"numba"`` (default): the compiled kernel of :mod:`parapend.dynamics._kernel`,
        parallel over the points, the same RK4 arithmetic and the same decision rules
        (capture, lag-k convergence, budget) as the NumPy engine; the attractor catalogue
        (pilot and capture verification) is built first by the NumPy engine. ``"numpy"``:
        the vectorized engine of :func:`~parapend.dynamics.find_attractors`.
        The two give identical labels except, rarely, on fractal basin boundaries where
        the order in which capture becomes available differs (tested on small grids).
    progress : callable, optional
        ``progress(done, total)`` called as parts of the grid are finished (numba engine:
        after each kernel call of about half a second), for a progress display; the library
        itself never prints.
    symmetric : bool
        Use the ``(phi, phi') -> (-phi, -phi')`` symmetry when the grid allows it (halves
        the work; the labels are then exactly mirror-symmetric, see module docstring).
    split_phases : bool
        Give each phase of a period-k attractor its own code, i.e. label by the attractor
        of the ``k*T`` stroboscopic map: the point visited at ``t0 + m*T``, ``m = 0 mod k``
        (e.g. the P2 oscillation becomes ``"P2 oscillation [phase 0]"`` and ``[phase 1]``,
        whose basins are distinct sets). Off by default.
    accuracy_sample : int
        Integrated points re-run to estimate the uncertain labels (module docstring);
        default 1000, at most the integrated points; 0 skips the estimate (the record then
        says so and ``basin_fraction_error`` is NaN). It costs about 3 points each.
    accuracy_seed : int
        Seed of that sample and of the perturbations' directions.

    Returns
    -------
    xarray.Dataset
        Dimensions ``dphi`` (rows), ``phi`` (columns), ``code`` (0 = other, 1.. attractors)
        and ``point`` (Poincare points of an attractor, NaN-padded). Variables:

        - ``attractor`` (dphi, phi), int32: the code reached from each initial condition;
        - ``phase`` (dphi, phi), int32: index of the Poincare point of a period-k attractor
          visited at ``m = 0 mod k`` (-1 for "other");
        - ``periods_used`` (dphi, phi), int32: periods integrated before it was decided;
        - ``name``, ``kind``, ``direction`` (code), str; ``period``, ``winding`` (code), int;
        - ``basin_fraction`` (code): share of the grid;
        - ``poincare_phi``, ``poincare_dphi`` (code, point): the attractor on the section
          ``t0 + m*2*pi/omega`` (``phi`` wrapped to ``[-pi, pi)``).

        - ``basin_fraction_error`` (code): 95 % bound on the shift of ``basin_fraction``
          when the uncertain labels are recomputed (not the grid's resolution).

        Attributes: ``legend`` (JSON ``{code: name}``), the parameters, ``convention``,
        ``elapsed_s`` (wall time), ``stats`` (JSON work counters), ``symmetric_used`` and
        ``mirror_symmetric`` (1: exactly symmetric by construction), ``accuracy`` (JSON: the
        method, ``sample``, ``population``, ``seed``, ``refined_steps_per_period``,
        ``perturbation``, the counts ``changed_refined``, ``changed_perturbed``,
        ``changed_both``, ``changed_either``, ``mislabel_fraction``, ``mislabel_interval``,
        ``confidence``, ``phases_compared``), and ``mislabel_fraction``,
        ``mislabel_interval`` (the same two numbers as plain attributes).
    """
    started = time.perf_counter()
    gamma, p, omega = _check_params(gamma, p, omega)
    tol, kmax, periods, rcap, steps = _check_search(tol, max_period, periods, capture_radius,
                                                    steps_per_period)
    t0 = check_finite("t0", t0)
    engine = _check_engine(engine)
    workers = _resolve_workers(workers, engine)
    n_check = check_int("accuracy_sample", accuracy_sample, 0)
    seed = check_int("accuracy_seed", accuracy_seed, 0)
    phi, dphi = grid(n_phi, n_dphi, dphi_range, phi_range)
    n_phi, n_dphi = phi.size, dphi.size
    theta = _theta_grid(n_phi) if phi_range is None else phi + math.pi
    use_sym = bool(symmetric) and dphi[0] == -dphi[-1] and phi_range is None
    ncol = n_phi // 2 + 1 if use_sym else n_phi
    # integrated points: columns 0..ncol-1; on a symmetric grid the columns that are their
    # own mirror image (phi = -pi and, n_phi even, phi = 0) only for phi' >= 0
    integ = np.ones((n_dphi, ncol), dtype=bool)
    if use_sym:
        selfcols = [0] + ([n_phi // 2] if n_phi % 2 == 0 else [])
        for c in selfcols:
            integ[dphi < 0, c] = False
    rr, cc = np.nonzero(integ)
    th0 = theta[cc].copy()
    v0 = dphi[rr].copy()
    search = dict(gamma=gamma, p=p, omega=omega, periods=periods, t0=t0, tol=tol, kmax=kmax,
                  rcap=rcap, workers=workers)
    entries, raw_i, used_i, eth_i, ev_i, stats = _run_search(
        th0, v0, steps=steps, pilot=bool(pilot), engine=engine, progress=progress, **search)
    check = None
    if n_check:
        check = _recheck(entries, th0, v0, raw_i, used_i, eth_i, ev_i, n_check, seed, search,
                         steps, engine)
    full = [np.zeros((n_dphi, n_phi), dtype=np.int64), np.zeros((n_dphi, n_phi), np.int64),
            np.zeros((n_dphi, n_phi)), np.zeros((n_dphi, n_phi))]
    for arr, val in zip(full, (raw_i, used_i, eth_i, ev_i)):
        arr[rr, cc] = val
    raw, used, end_th, end_v = full
    mirror = None
    if use_sym:
        mirror = np.array(_mirror_entries(entries, max(1e3 * tol, 1e-2)) + [-1])
        # (row j, column i) is the mirror of (n_dphi - 1 - j, n_phi - i mod n_phi)
        mr = n_dphi - 1 - np.arange(n_dphi)
        mc = (n_phi - np.arange(n_phi)) % n_phi
        todo = np.ones((n_dphi, n_phi), dtype=bool)
        todo[rr, cc] = False
        tr, tc = np.nonzero(todo)
        sr, sc = mr[tr], mc[tc]
        raw[tr, tc] = mirror[raw[sr, sc]]
        used[tr, tc] = used[sr, sc]
        end_th[tr, tc] = -end_th[sr, sc]
        end_v[tr, tc] = -end_v[sr, sc]
    labels, phase, attractors, legend = _finalize(entries, raw.ravel(), used.ravel(),
                                                  end_th.ravel(), end_v.ravel())
    labels = labels.reshape(n_dphi, n_phi)
    phase = phase.reshape(n_dphi, n_phi)
    code_of = _code_of_entries(entries, raw, labels)
    split_code = parent = None
    if split_phases:
        labels, split_attractors, legend = _split(labels, phase, attractors)
        split_code = {}
        for a in attractors:
            for j in range(a.period):
                split_code[(a.code, j)] = len(split_code) + 1
        parent = np.array([0] + [a.code for a in attractors for _ in range(a.period)])
        attractors = split_attractors
    accuracy, frac_err = _accuracy(check, entries, code_of, mirror, split_code,
                                   len(attractors) + 1, parent,
                                   steps, n_check, seed, integ.sum(), use_sym)

    ncode = len(attractors) + 1
    kmax_pts = max([a.period for a in attractors], default=1)
    pphi = np.full((ncode, kmax_pts), np.nan)
    pdphi = np.full((ncode, kmax_pts), np.nan)
    for a in attractors:
        pphi[a.code, :a.period] = a.phi
        pdphi[a.code, :a.period] = a.dphi
    frac = np.bincount(labels.ravel(), minlength=ncode) / labels.size
    code = np.arange(ncode)
    elapsed = time.perf_counter() - started
    stats = dict(stats, grid_points=int(labels.size), integrated_points=int(th0.size))
    ds = xr.Dataset(
        data_vars={
            "attractor": (("dphi", "phi"), labels.astype(np.int32),
                          {"long_name": "attractor code (0 = other)"}),
            "phase": (("dphi", "phi"), phase.astype(np.int32),
                      {"long_name": "Poincare point visited at m = 0 mod period"}),
            "periods_used": (("dphi", "phi"), used.astype(np.int32),
                             {"long_name": "forcing periods integrated"}),
            "name": ("code", np.array([legend[c] for c in code], dtype=str)),
            "kind": ("code", np.array(["other"] + [a.kind for a in attractors], dtype=str)),
            "direction": ("code", np.array(["none"] + [a.direction for a in attractors],
                                           dtype=str)),
            "period": ("code", np.array([0] + [a.period for a in attractors], dtype=np.int32)),
            "winding": ("code", np.array([0] + [a.winding for a in attractors],
                                         dtype=np.int32)),
            "basin_fraction": ("code", frac),
            "basin_fraction_error": ("code", frac_err, {
                "long_name": "95 % bound on the shift of basin_fraction when its uncertain "
                             "labels are recomputed (see attrs accuracy)"}),
            "poincare_phi": (("code", "point"), pphi),
            "poincare_dphi": (("code", "point"), pdphi),
        },
        coords={"phi": ("phi", phi, {"long_name": "initial phi (from hanging)", "units": "rad"}),
                "dphi": ("dphi", dphi, {"long_name": "initial dphi/dt",
                                        "units": "rad per unit time"}),
                "code": ("code", code)},
        attrs={
            "title": "basins of attraction of paper Eq. 1",
            "legend": json.dumps({str(k): v for k, v in legend.items()}),
            "gamma": gamma, "p": p, "omega": omega, "t0": t0,
            "periods": periods, "steps_per_period": steps, "tol": tol,
            "max_period": kmax, "capture_radius": rcap, "pilot": int(bool(pilot)),
            "symmetric_used": int(use_sym), "split_phases": int(bool(split_phases)),
            "workers": workers, "engine": engine,
            "convention": CONVENTION,
            "method": ("fixed-step RK4 stroboscopic map (parapend.dynamics.attractors"
                       + (", compiled kernel parapend.dynamics._kernel)" if engine == "numba"
                          else ")")),
            "elapsed_s": elapsed,
            "stats": json.dumps(stats),
            "accuracy": json.dumps(accuracy),
            "mislabel_fraction": accuracy.get("mislabel_fraction", math.nan),
            "mislabel_interval": np.array(accuracy.get("mislabel_interval",
                                                       [math.nan, math.nan])),
            "mirror_symmetric": int(use_sym),
        },
    )
    return ds
