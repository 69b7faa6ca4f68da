"""Basins of attraction of paper Eq. 1 on a grid of initial conditions (paper Fig. 2 right).

Initial conditions ``(phi, phi')`` at ``t = t0`` (default 0), ``phi`` from the hanging
position on ``n_phi`` points ``phi_i = -pi + 2*pi*i/n_phi`` covering ``[-pi, pi)``, ``phi'``
on ``n_dphi`` points spanning ``dphi_range`` (ends included). Each is integrated by the
vectorized engine of :mod:`parapend.dynamics.attractors` and labelled with the attractor
it reaches (0 = "other": chaotic or unresolved within the period budget).

Symmetry. Eq. 1 is invariant under ``(phi, phi') -> (-phi, -phi')`` and the RK4 map of
:mod:`.simulate` commutes with it exactly (every operation is odd in the state, rounding
included). On a grid symmetric under it (``dphi_range`` symmetric about 0) only the half
``0 <= i <= n_phi/2`` is integrated and the other half is the mirror image, with each
attractor replaced by its mirror (``P1 rotation (+)`` <-> ``P1 rotation (-)``). The
integrated initial angles are ``theta_i = pi*m_i/n_phi`` (project convention, ``m_i`` an
even integer in ``(-n_phi, n_phi]``) so that mirror pairs are exact negatives; this is the
same point as ``phi_i`` up to one rounding.
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
    _Entry,
    _finalize,
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


def basin_map(gamma: float, p: float, omega: float, *, n_phi: int = 200, n_dphi: int = 200,
              dphi_range: tuple[float, float] = (-3.0, 3.0),
              phi_range: tuple[float, float] | None = None, periods: int = 300,
              steps_per_period: int = 128, t0: float = 0.0, tol: float = 1e-6,
              max_period: int = 8, capture_radius: float = 0.05, symmetric: bool = True,
              split_phases: bool = False, pilot: bool = True, workers: int | None = None,
              engine: str = "numba", progress=None) -> xr.Dataset:
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
        As :func:`parapend.dynamics.attractors.find_attractors`.
    workers : int, optional
        Threads: default every core for ``engine="numba"``, 1 for ``"numpy"``. Labels do
        not depend on it.
    engine : {"numba", "numpy"}
        ``"numba"`` (default): the compiled kernel of :mod:`parapend.dynamics._kernel`,
        parallel over the points, the same RK4 arithmetic and the same decision rules
        (capture, lag-k convergence, budget) as the NumPy engine; the attractor catalogue
        (pilot and capture verification) is built first by the NumPy engine. ``"numpy"``:
        the vectorized engine of :func:`~parapend.dynamics.attractors.find_attractors`.
        The two give identical labels except, rarely, on fractal basin boundaries where
        the order in which capture becomes available differs (tested on small grids).
    progress : callable, optional
        ``progress(done, total)`` called as parts of the grid are finished (numba engine:
        up to 20 parts), for a progress display; the library itself never prints.
    symmetric : bool
        Use the ``(phi, phi') -> (-phi, -phi')`` symmetry when the grid allows it (halves
        the work; identical labels, see module docstring).
    split_phases : bool
        Give each phase of a period-k attractor its own code, i.e. label by the attractor
        of the ``k*T`` stroboscopic map: the point visited at ``t0 + m*T``, ``m = 0 mod k``
        (e.g. the P2 oscillation becomes ``"P2 oscillation [phase 0]"`` and ``[phase 1]``,
        whose basins are distinct sets). Off by default.

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

        Attributes: ``legend`` (JSON ``{code: name}``), the parameters, ``convention``,
        ``elapsed_s`` (wall time), ``stats`` (JSON work counters) and ``symmetric_used``.
    """
    started = time.perf_counter()
    gamma, p, omega = _check_params(gamma, p, omega)
    tol, kmax, periods, rcap, steps = _check_search(tol, max_period, periods, capture_radius,
                                                    steps_per_period)
    t0 = check_finite("t0", t0)
    engine = _check_engine(engine)
    workers = _resolve_workers(workers, engine)
    phi, dphi = grid(n_phi, n_dphi, dphi_range, phi_range)
    n_phi, n_dphi = phi.size, dphi.size
    theta = _theta_grid(n_phi) if phi_range is None else phi + math.pi
    use_sym = bool(symmetric) and dphi[0] == -dphi[-1] and phi_range is None
    ncol = n_phi // 2 + 1 if use_sym else n_phi
    th0 = np.broadcast_to(theta[None, :ncol], (n_dphi, ncol)).ravel().copy()
    v0 = np.broadcast_to(dphi[:, None], (n_dphi, ncol)).ravel().copy()
    entries, raw, used, end_th, end_v, stats = _run_search(
        th0, v0, gamma, p, omega, periods=periods, steps=steps, t0=t0, tol=tol, kmax=kmax,
        rcap=rcap, workers=workers, pilot=bool(pilot), engine=engine,
        progress=progress)
    raw, used, end_th, end_v = (a.reshape(n_dphi, ncol) for a in (raw, used, end_th, end_v))
    if use_sym:
        mirror = np.array(_mirror_entries(entries, max(1e3 * tol, 1e-2)) + [-1])
        src = n_phi - np.arange(ncol, n_phi)      # mirror of column i is n_phi - i
        raw = np.concatenate((raw, mirror[raw[::-1, src]]), axis=1)
        used = np.concatenate((used, used[::-1, src]), axis=1)
        end_th = np.concatenate((end_th, -end_th[::-1, src]), axis=1)
        end_v = np.concatenate((end_v, -end_v[::-1, src]), axis=1)
    labels, phase, attractors, legend = _finalize(entries, raw.ravel(), used.ravel(),
                                                  end_th.ravel(), end_v.ravel())
    labels = labels.reshape(n_dphi, n_phi)
    phase = phase.reshape(n_dphi, n_phi)
    if split_phases:
        labels, attractors, legend = _split(labels, phase, attractors)

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
        },
    )
    return ds
