"""What a power matrix computes (:class:`MatrixSpec`) and one block of it (one bin, all its
realizations): the spec the design-map engine (:mod:`parapend.maps`) runs, stores and
resumes like a sweep's.

A block is one bin: ``R`` records of ``W`` waves, realization ``r`` seeded ``seed + r`` (the
same phases in every bin: common random numbers), each solved by
:func:`parapend.irregular.sea` exactly as ``parapend sea`` would. The store holds the
per-realization powers (W) and statuses; the statistics are drawn from them afterwards.
"""

from __future__ import annotations

import dataclasses
import json
import logging

import numpy as np

from .hull_device import FAILURE_LONG_NAME, FAILURES

__all__ = ["FAILURES", "MatrixSpec", "QUANTITIES", "STORE_NAMES"]

log = logging.getLogger(__name__)

#: the stored per-realization quantities (W): name -> long name
QUANTITIES = {
    "power": "non-causal optimum over the record (parapend sea), mechanical power",
    "limit_power": "gamma -> 0 limit omega_r TV(q) / 2 pi: no motion extracts more",
    "uniform_power": "best uniform rotation at the mean wave frequency (K_m turns per record)",
    "electrical_power": "electrical power of the optimum's motion through a power take-off "
                        "of the given efficiency (generating x eta, motoring / eta)",
    # the coupled buoy (--device buoy)
    "radiation_bound_power": "radiation bound sum_k |F_k a_k|^2 / (8 B_k): no mechanism "
                             "inside the buoy absorbs more",
    "one_way_power": "one-way optimum: the pendulum's reaction on the buoy left out (the "
                     "pivot moves as the free buoy), its predicted power",
    # the hull (--dofs surge,heave,pitch): the generator's rating, from the motion itself
    "peak_torque": "largest |tau| of the record's optimum (located on its motion)",
    "peak_pivot_force": "largest bearing load |m (p'' + l (sin phi, cos phi)'') + m g| of the "
                        "record's optimum (located on its motion)",
}
#: the stored quantities' units (the rest: W)
UNITS = {"peak_torque": "N m", "peak_pivot_force": "N"}

#: the hull's per-realization mode (--dofs surge,heave,pitch): an int8 code, -1 not computed
MODE_LONG_NAME = ("best mode of the record: 0 rest, 1 rotation in the sense of a positive "
                  "pitch, 2 swinging (on a long record, possibly with a few net turns), 3 "
                  "rotation against it (reversed)")
_TITLE = "parapend design map"
#: every top-level name a power-matrix store holds (coordinates and variables)
STORE_NAMES = ("hm0", "te", "tp", "realization", "seed", "done", "status", "mode", "failure",
               *QUANTITIES, *(f"causal_{f}_{q}" for f in ("perfect", "ar")
                              for q in ("power", "harvested_power")))
#: the causal column's fields (left out of the JSON without a controller)
_CAUSAL_FIELDS = ("controller", "horizon", "forecasts", "update_interval", "warm_up",
                  "plan_samples", "speed_limit")
#: devices a matrix can be computed for
DEVICES = ("prescribed-heave", "buoy")
#: the spec's fields only the buoy uses (left out of a prescribed-heave spec's JSON)
_BUOY_FIELDS = ("body", "radius", "draft", "mesh", "hydro", "digest", "damping_coefficient",
                "band", "width", "water_density", "water_depth")
#: the buoy's water when nothing else is given (1025 kg/m^3, deep): left out of the JSON, so
#: that a store written before the body took the matrix's water still resumes
_DEFAULT_WATER = {"water_density": 1025.0, "water_depth": None}
#: how the hull's record optimum is found (in its stores' identity): rotation both ways and
#: swinging, on a long record the windings between them both ways
#: (:func:`parapend.hydro.result.hull_answer`'s search), on a short one the rotation's
#: turns climbed; a store of an earlier version (no marker, or another one: the forward
#: sense alone, "rotation, swinging and the windings searched"; the short records' turns
#: not climbed, "rotation both ways, swinging and the windings searched both ways") is
#: refused
RECORD_OPTIMUM = ("rotation both ways, swinging, the windings searched both ways and a "
                  "short record's turns climbed")
#: the hull's fields (--dofs surge,heave,pitch) at their defaults, the heaving buoy's: left
#: out of the JSON, so that a store written before the hull came still resumes
_DEFAULT_HULL = {"dofs": "heave", "pivot_height": None, "pivot_offset": None,
                 "hull_pitch_inertia": None, "barge_length": None, "barge_beam": None,
                 "barge_draft": None, "copper_loss": None, "torque_limit": None,
                 "bin_waves": None}


@dataclasses.dataclass(frozen=True)
class MatrixSpec:
    """The bins and everything a bin's solve depends on (its identity in the store)."""

    hm0: tuple
    period: tuple          # the bin centres of the period axis (te or tp)
    period_kind: str       # "te" or "tp"
    tp: tuple              # the peak period of each period bin (s)
    realizations: int
    waves: float
    seed: int
    spectrum: str
    gamma_peak: float
    cutoff: float
    response: tuple | None  # (f, gain, phase) tuples or None
    length: float
    mass: float
    inertia: float | None
    gravity: float
    gamma: float
    winding: object
    harmonics: int | None
    efficiency: float | None
    device: str = "prescribed-heave"
    # the coupled buoy: the body as ``parapend buoy`` takes it, the pendulum's damping
    # (N m s/rad), the BEM's frequency range (rad/s) covering every bin, the body's width
    body: str | None = None
    radius: float | None = None
    draft: float | None = None
    mesh: str | None = None
    hydro: str | None = None
    digest: str | None = None  # sha256 of the --mesh or --hydro file (a changed file is
    # another matrix: the store does not resume it)
    damping_coefficient: float | None = None
    band: tuple | None = None
    width: float | None = None
    # the water the buoy's body is solved in (kg/m^3; m, None deep): the waves' own
    # (--density, --depth), so the flux and the body see one sea
    water_density: float = 1025.0
    water_depth: float | None = None
    # the hull that surges, heaves and pitches (dofs "surge,heave,pitch"): the pivot (m),
    # the hull's pitch inertia (kg m^2), the barge (m), the take-off's copper loss
    # (W/(N m)^2) and torque limit (N m), as parapend buoy takes them (hydro/api.py)
    dofs: str = "heave"
    pivot_height: float | None = None
    pivot_offset: float | None = None
    hull_pitch_inertia: float | None = None
    barge_length: float | None = None
    barge_beam: float | None = None
    barge_draft: float | None = None
    copper_loss: float | None = None
    torque_limit: float | None = None
    # the causal column (--controller mpc, parapend.performance.causal): the horizon, update
    # interval and warm-up in peak periods, the forecasts, the planner's samples an interval
    controller: str | None = None
    horizon: float | None = None
    forecasts: tuple = ()
    update_interval: float | None = None
    warm_up: float | None = None
    plan_samples: int | None = None
    speed_limit: float | None = None  # the plans' rated-speed penalty, units sqrt(g / l)
    # --device buoy: which controller of parapend.hydro.control.buoy_mpc the column runs
    buoy_controller: str | None = None
    # each period bin's record in peak periods where they differ (None: ``waves`` in every
    # bin): the hull's default records are ``waves`` peak periods or 20 minutes, the longer
    # (as far as the hull's solver takes them)
    bin_waves: tuple | None = None

    kind = "power_matrix"
    pto = False

    # -- the layout the maps engine reads ------------------------------------------------
    @property
    def dims(self) -> tuple:
        return ("hm0", self.period_kind, "realization")

    @property
    def shape(self) -> tuple:
        return (len(self.hm0), len(self.period), self.realizations)

    @property
    def points(self) -> int:
        return int(np.prod(self.shape))

    @property
    def chunks(self) -> tuple:
        return (1, 1, self.realizations)

    @property
    def block_grid(self) -> tuple:
        return (len(self.hm0), len(self.period), 1)

    @property
    def blocks(self) -> int:
        return len(self.hm0) * len(self.period)

    def block_slices(self, block: int) -> tuple:
        i, j, _ = np.unravel_index(block, self.block_grid)
        return (slice(int(i), int(i) + 1), slice(int(j), int(j) + 1),
                slice(0, self.realizations))

    def block_order(self) -> list:
        """The blocks in the order the engine hands them out: the dearest first (the
        higher seas, then the longer records: more harmonics a wave and more waves), so
        that no worker is left with one dear bin at the end while the others idle (a
        6 x 6 hull matrix's Hs 3 m bins cost several times its Hs 0.5 m ones)."""
        return sorted(range(self.blocks),
                      key=lambda b: (-self.hm0[b // len(self.period)],
                                     -self.record_waves(b % len(self.period)), b))

    @property
    def lossy(self) -> bool:
        """A take-off with losses (an efficiency, or the hull's copper loss): the store holds
        the electrical power beside the mechanical one."""
        return self.efficiency is not None or self.copper_loss is not None

    @property
    def variables(self) -> tuple:
        if self.device == "buoy":
            e = ("electrical_power",) if self.lossy else ()
            m = (("peak_torque", "peak_pivot_force", "mode", "failure")
                 if self.dofs != "heave" else ())
            c = ()
            if self.controller is not None:
                from .causal import causal_quantities

                c = causal_quantities(self.forecasts)
            return ("power", "radiation_bound_power", "one_way_power", *e, *m, *c, "status")
        out = ["power", "limit_power", "uniform_power"]
        if self.efficiency is not None:
            out.append("electrical_power")
        if self.controller is not None:
            from .causal import causal_quantities

            out += causal_quantities(self.forecasts)
        return (*out, "status")

    @property
    def names(self) -> tuple:
        """Top-level names the store holds besides the variables and ``done``."""
        return ("hm0", "te", "tp", "realization", "seed")

    @property
    def seeds(self) -> np.ndarray:
        return self.seed + np.arange(self.realizations, dtype=np.int64)

    def to_json(self) -> str:
        d = dataclasses.asdict(self)
        d["kind"] = self.kind
        d["chunks"] = list(self.chunks)
        if self.device != "buoy":
            for k in _BUOY_FIELDS:
                d.pop(k)
        else:
            for k, v in _DEFAULT_WATER.items():
                if d[k] == v:
                    d.pop(k)
        for k, v in _DEFAULT_HULL.items():
            if d[k] == v:
                d.pop(k)
        if self.controller is None:  # a store written before the causal column resumes
            for k in _CAUSAL_FIELDS:
                d.pop(k)
        if d["buoy_controller"] is None:  # the same: the prescribed device's column
            d.pop("buoy_controller")
        if self.dofs != "heave":  # a hull store of an earlier version (two modes) is refused
            d["record_optimum"] = RECORD_OPTIMUM
        return json.dumps(d, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> MatrixSpec:
        d = json.loads(text)
        d.pop("kind")
        d.pop("chunks")
        d.pop("record_optimum", None)
        for k in ("hm0", "period", "tp"):
            d[k] = tuple(float(v) for v in d[k])
        if d["response"] is not None:
            d["response"] = tuple(tuple(float(v) for v in c) for c in d["response"])
        if d.get("band") is not None:
            d["band"] = tuple(float(v) for v in d["band"])
        if d.get("bin_waves") is not None:
            d["bin_waves"] = tuple(float(v) for v in d["bin_waves"])
        if "forecasts" in d:
            d["forecasts"] = tuple(d["forecasts"])
        return cls(**d)

    def coordinates(self) -> dict:
        """Coordinate name -> values (checked on resume)."""
        return {"hm0": np.array(self.hm0), self.period_kind: np.array(self.period),
                "realization": np.arange(self.realizations)}

    def record_waves(self, j: int) -> float:
        """The record's length in peak periods at period bin ``j``: ``waves``, or the
        bin's own (``bin_waves``: the hull's 20-minute records)."""
        return self.waves if self.bin_waves is None else self.bin_waves[j]

    def repeat_period(self, j: int) -> float:
        """The record's repeat period (s) at period bin ``j`` (:meth:`record_waves`)."""
        from .resource import repeat_period

        return repeat_period(self.record_waves(j), self.tp[j])

    def sea_kwargs(self, i: int, j: int, r: int) -> dict:
        """The arguments of :func:`parapend.irregular.sea` for bin (i, j), realization r."""
        tp = self.tp[j]
        kw = {"hs": self.hm0[i], "tp": tp, "spectrum": self.spectrum,
              "repeat_period": self.repeat_period(j), "seed": int(self.seeds[r]),
              "cutoff": self.cutoff, "length": self.length, "mass": self.mass,
              "inertia": self.inertia, "gravity": self.gravity, "gamma": self.gamma,
              "winding": self.winding, "harmonics": self.harmonics}
        if self.spectrum == "jonswap":
            kw["gamma_peak"] = self.gamma_peak
        if self.response is not None:
            kw["response"] = tuple(np.array(c) for c in self.response)
        return kw

    def long_names(self) -> dict:
        """Long names of the stored quantities (the causal column's included)."""
        if self.controller is None:
            return QUANTITIES
        from .causal import long_names

        return {**QUANTITIES, **long_names(self.forecasts)}

    # -- the store -------------------------------------------------------------------------
    def template(self, command: str | None):
        """The whole store as a lazy Dataset (dask arrays of fill values) and its encoding."""
        import dask.array as da
        import xarray as xr
        from zarr.codecs import ZstdCodec

        from .. import __version__
        from ..maps.spec import STATUSES

        data, enc = {}, {}
        for v in (*self.variables, "done"):
            if v == "done":
                arr, fill = da.zeros(self.shape, dtype=bool, chunks=self.chunks), False
                attrs = {"long_name": "bin finished (written after the bin's data)"}
            elif v == "mode":
                arr = da.full(self.shape, -1, dtype=np.int8, chunks=self.chunks)
                fill = -1
                attrs = {"long_name": MODE_LONG_NAME, "flag_values": [0, 1, 2, 3],
                         "flag_meanings": "rest rotation swinging rotation_reversed",
                         "comment": "-1: not computed"}
            elif v == "failure":
                arr = da.full(self.shape, -1, dtype=np.int8, chunks=self.chunks)
                fill = -1
                attrs = {"long_name": FAILURE_LONG_NAME,
                         "flag_values": list(range(len(FAILURES))),
                         "flag_meanings": " ".join(f.replace(" ", "_") for f in FAILURES),
                         "comment": "-1: not computed"}
            elif v == "status":
                arr = da.full(self.shape, -1, dtype=np.int8, chunks=self.chunks)
                fill = -1
                attrs = {"long_name": "solver status of the optimum",
                         "flag_values": list(range(len(STATUSES))),
                         "flag_meanings": " ".join(STATUSES),
                         "comment": "-1: not computed; success: converged"}
            else:
                arr = da.full(self.shape, np.nan, dtype=float, chunks=self.chunks)
                fill, attrs = np.nan, {"long_name": self.long_names()[v],
                                       "units": UNITS.get(v, "W")}
            data[v] = (self.dims, arr, attrs)
            enc[v] = {"chunks": self.chunks, "fill_value": fill,
                      "compressors": (ZstdCodec(level=0, checksum=True),)}
        pk = self.period_kind
        other = "tp" if pk == "te" else "te"
        from .resource import te_over_tp

        ratio = te_over_tp(self.spectrum, self.gamma_peak)
        others = (np.array(self.tp) * ratio if pk == "tp" else np.array(self.tp))
        coords = {
            "hm0": ("hm0", np.array(self.hm0),
                    {"long_name": "significant wave height Hm0 (bin centre)", "units": "m"}),
            pk: (pk, np.array(self.period),
                 {"long_name": ("energy period Te" if pk == "te" else "peak period Tp")
                  + " (bin centre)", "units": "s"}),
            other: (pk, others, {"long_name": ("peak period Tp" if other == "tp" else
                                               "energy period Te")
                                 + f" of the bin (Te = {ratio:.12g} Tp)", "units": "s"}),
            "realization": ("realization", np.arange(self.realizations),
                            {"long_name": "realization"}),
            "seed": ("realization", self.seeds, {"long_name": "seed of the record's phases"}),
        }
        attrs = {"title": _TITLE, "product": "power matrix", "parapend_version": __version__,
                 "command": command or "parapend.power_matrix()", "sweep": self.to_json(),
                 "device": self.device,
                 "te_over_tp": ratio,
                 "conventions": "powers in W, positive = harvested; per realization; "
                                "parapend.performance adds the statistics (docs/performance.md)"}
        return xr.Dataset(data, coords=coords, attrs=attrs), enc

    def finished(self, vals: dict) -> np.ndarray:
        """The points of a computed block the store marks finished: every realization but
        those whose solve raised (status "error"), so a rerun retries them rather than
        keeping the failure for good."""
        from ..maps.spec import _CODE

        return np.asarray(vals["status"]) != _CODE["error"]

    # -- one block ---------------------------------------------------------------------------
    def compute_block(self, block: int) -> dict:
        from ..maps.spec import _CODE
        from .solve import solve_bin, verdict

        i, j, _ = (s.start for s in self.block_slices(block))
        out = {v: (np.full(self.chunks, -1, dtype=np.int8) if v in ("status", "mode",
                                                                     "failure")
                   else np.full(self.chunks, np.nan)) for v in self.variables}
        for r in range(self.realizations):
            try:
                vals = solve_bin(self, i, j, r)
            except Exception as err:  # noqa: BLE001 - recorded as status "error"
                log.warning("power matrix bin hm0=%g %s=%g realization %d failed: %s: %s",
                            self.hm0[i], self.period_kind, self.period[j], r,
                            type(err).__name__, err)
                vals = {"status": "error"}
            checked = verdict(vals)  # no impossible number is a success
            if checked["status"] != vals["status"]:
                log.warning("power matrix bin hm0=%g %s=%g realization %d: %s (power %r W): "
                            "not a success", self.hm0[i], self.period_kind, self.period[j],
                            r, checked["status"], vals.get("power"))
            vals = checked
            if "failure" in out and vals["status"] in ("above_bound", "nonfinite", "error"):
                vals["failure"] = FAILURES.index("above the radiation bound"
                                                 if vals["status"] == "above_bound"
                                                 else "other")
            for k, v in vals.items():
                if k == "status":
                    out[k][0, 0, r] = _CODE.get(v, _CODE["other"])
                else:
                    out[k][0, 0, r] = v
        return out
