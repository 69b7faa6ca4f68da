r"""What a persistence map computes (:class:`PersistenceSpec`) and one block of it: the
product that the design-map engine (:mod:`parapend.maps.run`: Zarr store, lock, resume,
local processes or Dask) runs, stores and resumes like a sweep.

The store holds per realization (dimensions ``tp, hs, generator, realization``: the blocks
run Hs after Hs within a Tp, whose cells share their unit records; a block is one cell's
run of ``block`` realizations, one chunk; on the GPU path a whole Tp column, one chunk):
``rho``, ``throughout`` (1 or 0), ``power`` (W), the four energies of the energy identity
(J), the generator damping used (N m s/rad) and a ``status``; optionally the omniscient
optimum and a causal controller's power (W). The statistics are drawn from them afterwards
(:mod:`.persistence`).

Records. Realization ``r`` of every cell is seeded ``seed + r`` (common random numbers over
the cells and the generator dampings), its phases drawn exactly as
:func:`parapend.seas.sea_record` draws them: ``numpy.random.default_rng(seed + r).uniform(0,
2 pi, K + 1)`` with ``K = floor(cutoff T_r / Tp)``. So a realization is the record of
``parapend sea --hs HS --tp TP --repeat-period T_r --cutoff C --seed SEED+r`` (where that
command's ranges allow it; to rounding, as the kernel takes the record of unit Hs times Hs),
and the numbers are reproducible bit for bit on one machine.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math

import numpy as np

__all__ = ["PersistenceSpec"]

log = logging.getLogger(__name__)

#: the per-realization variables of the store: name -> (long name, units)
STORED = {
    "rho": ("rotation ratio: net forward turns per peak period over the window", "1"),
    "throughout": ("rotating throughout: every 2 Tp window advanced at least pi (1) or not (0)",
                   "1"),
    "power": ("mean harvested power c_g <theta'^2> over the window", "W"),
    "harvested_energy": ("harvested energy c_g int theta'^2 dt over the window", "J"),
    "dissipated_energy": ("energy dissipated in the bearing, c int theta'^2 dt", "J"),
    "base_work": ("work of the base acceleration, m l int z'' sin(theta) theta' dt", "J"),
    "stored_energy_change": ("change of I theta'^2 / 2 + m g l cos(theta) over the window",
                             "J"),
    "generator_damping": ("generator damping c_g of the run", "N m s/rad"),
}
OPTIONAL = {
    "omniscient_power": ("omniscient optimum of the record (parapend sea), mechanical "
                         "power; NaN where not computed", "W"),
    "controller_power": ("causal controller on the record (the regular-wave tracker of "
                         "parapend track --irregular); NaN where not computed", "W"),
}
_TITLE = "parapend design map"
#: top-level names of a persistence store besides its variables and ``done``
NAMES = ("hs", "tp", "generator", "realization", "seed", "generator_damping_setting")


@dataclasses.dataclass(frozen=True)
class PersistenceSpec:
    """The cells and everything a realization's run depends on (its identity in a store)."""

    hs: tuple
    tp: tuple
    generator: tuple        # N m s/rad each, or ("best",)
    realizations: int
    block: int
    seed: int
    spectrum: str
    gamma_peak: float
    cutoff: float
    response: tuple | None
    duration: float
    transient: float | None  # s; None: 10 Tp
    mass: float
    length: float
    inertia: float | None
    gravity: float
    damping_coefficient: float
    omniscient: int = 0
    controller: str | None = None
    gpu: bool = False

    kind = "persistence"
    pto = False

    # -- the layout the maps engine reads ------------------------------------------------
    @property
    def dims(self) -> tuple:
        return ("tp", "hs", "generator", "realization")

    @property
    def shape(self) -> tuple:
        return (len(self.tp), len(self.hs), len(self.generator), self.realizations)

    @property
    def points(self) -> int:
        return int(np.prod(self.shape))

    @property
    def chunks(self) -> tuple:
        if self.gpu:  # a block is a whole Tp column: one launch (run_column)
            return (1, len(self.hs), len(self.generator), self.realizations)
        return (1, 1, 1, self.block)

    @property
    def block_grid(self) -> tuple:
        return tuple(-(-n // c) for n, c in zip(self.shape, self.chunks))

    @property
    def blocks(self) -> int:
        return int(np.prod(self.block_grid))

    def block_slices(self, block: int) -> tuple:
        at = (int(x) for x in np.unravel_index(block, self.block_grid))
        return tuple(slice(b * c, min(n, (b + 1) * c))
                     for b, c, n in zip(at, self.chunks, self.shape))

    @property
    def best(self) -> bool:
        return self.generator == ("best",)

    @property
    def variables(self) -> tuple:
        extra = (("omniscient_power",) if self.omniscient else ()) + (
            ("controller_power",) if self.controller else ())
        return (*STORED, *extra, "status")

    @property
    def names(self) -> tuple:
        return NAMES

    @property
    def seeds(self) -> np.ndarray:
        return self.seed + np.arange(self.realizations, dtype=np.int64)

    def to_json(self) -> str:
        d = dataclasses.asdict(self)
        d["kind"] = self.kind
        d["chunks"] = list(self.chunks)
        return json.dumps(d, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> PersistenceSpec:
        d = json.loads(text)
        d.pop("kind")
        d.pop("chunks")
        for k in ("hs", "tp"):
            d[k] = tuple(float(v) for v in d[k])
        d["generator"] = tuple(v if isinstance(v, str) else float(v) for v in d["generator"])
        if d["response"] is not None:
            d["response"] = tuple(tuple(float(v) for v in c) for c in d["response"])
        return cls(**d)

    def coordinates(self) -> dict:
        """Coordinate name -> values (checked on resume)."""
        return {"hs": np.array(self.hs), "tp": np.array(self.tp),
                "generator": np.arange(len(self.generator)),
                "realization": np.arange(self.realizations)}

    # -- the store -------------------------------------------------------------------------
    def template(self, command: str | None):
        """The whole store as a lazy Dataset (dask arrays of fill values) and its encoding."""
        import dask.array as da
        import xarray as xr
        from zarr.codecs import ZstdCodec

        from .. import __version__
        from ..maps.spec import STATUSES

        data, enc = {}, {}
        long = {**STORED, **OPTIONAL}
        for v in (*self.variables, "done"):
            if v == "done":
                arr, fill = da.zeros(self.shape, dtype=bool, chunks=self.chunks), False
                attrs = {"long_name": "block finished (written after the block's data)"}
            elif v == "status":
                arr = da.full(self.shape, -1, dtype=np.int8, chunks=self.chunks)
                fill = -1
                attrs = {"long_name": "status of the realization's run",
                         "flag_values": list(range(len(STATUSES))),
                         "flag_meanings": " ".join(STATUSES),
                         "comment": "-1: not computed; converged: a finite run"}
            else:
                arr = da.full(self.shape, np.nan, dtype=float, chunks=self.chunks)
                fill, attrs = np.nan, {"long_name": long[v][0], "units": long[v][1]}
            data[v] = (self.dims, arr, attrs)
            enc[v] = {"chunks": self.chunks, "fill_value": fill,
                      "compressors": (ZstdCodec(level=0, checksum=True),)}
        setting = [math.nan if isinstance(g, str) else g for g in self.generator]
        coords = {
            "hs": ("hs", np.array(self.hs), {"long_name": "significant wave height Hs",
                                             "units": "m"}),
            "tp": ("tp", np.array(self.tp), {"long_name": "peak period Tp", "units": "s"}),
            "generator": ("generator", np.arange(len(self.generator)),
                          {"long_name": "generator setting"}),
            "generator_damping_setting": (
                "generator", np.array(setting, dtype=float),
                {"long_name": "generator damping given (NaN: best, searched per cell)",
                 "units": "N m s/rad"}),
            "realization": ("realization", np.arange(self.realizations),
                            {"long_name": "realization"}),
            "seed": ("realization", self.seeds, {"long_name": "seed of the record's phases"}),
        }
        attrs = {"title": _TITLE, "product": "rotation persistence",
                 "parapend_version": __version__,
                 "command": command or "parapend.persistence()", "sweep": self.to_json(),
                 "conventions": "I theta'' + c theta' - m l (g + z'') sin(theta) = -c_g "
                                "theta', theta from the upright; SI; per realization; "
                                "parapend.persistence adds the statistics "
                                "(docs/persistence.md)"}
        return xr.Dataset(data, coords=coords, attrs=attrs), enc

    # -- one block ---------------------------------------------------------------------------
    def compute_block(self, block: int) -> dict:
        from ..maps.spec import _CODE
        from ._persist_cells import best_damping, cell_plan, run_cell, run_column

        sl = self.block_slices(block)
        j, i, k = sl[0].start, sl[1].start, sl[2].start  # tp, hs, generator
        r0, r1 = sl[3].start, sl[3].stop
        if self.gpu:  # the whole column: cells [hs][generator]
            cells = run_column(self, j)
        else:
            plan = cell_plan(self, i, j)
            cg = (best_damping(self, plan) if self.best else float(self.generator[k]))
            cells = [[run_cell(self, plan, cg, range(r0, r1))]]
        shape = (1, len(cells), len(cells[0]), r1 - r0)

        def stack(v, dtype=float):
            return np.array([[np.asarray(c[v], dtype=dtype) for c in row] for row in cells]
                            ).reshape(shape)

        out = {v: stack(v) for v in STORED}
        out["status"] = np.where(stack("finite", bool), _CODE["converged"],
                                 _CODE["nonfinite"]).astype(np.int8)
        for v in self.variables:
            if v in OPTIONAL:
                out[v] = stack(v)
        return out
