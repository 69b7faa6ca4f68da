r"""Design maps (``parapend sweep``, ``parapend map``): resumable parameter sweeps over
omega, delta, gamma, T_max and efficiency.

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

The package, in the order the data flow
    ``spec`` (the grid, :class:`SweepSpec`, what a map holds) -> ``compute`` (one block) ->
    ``store`` (the Zarr store, its check, :func:`open_sweep`) -> ``run`` (:func:`sweep`,
    local processes or Dask); ``figures`` (the heat maps) reads a store's Dataset.
"""

from __future__ import annotations

from .compute import compute_block
from .figures import MAP_QUANTITIES, map_data, plot_map, plot_sweep
from .run import SweepRun, sweep
from .spec import AXES, NOT_COMPUTED, STATUSES, VARIABLES, SweepSpec, parse_axis, sweep_spec
from .store import open_sweep

__all__ = ["AXES", "MAP_QUANTITIES", "NOT_COMPUTED", "STATUSES", "VARIABLES", "SweepRun",
           "SweepSpec", "compute_block", "map_data", "open_sweep", "parse_axis", "plot_map",
           "plot_sweep", "sweep", "sweep_spec"]
