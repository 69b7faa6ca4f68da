r"""Does the rotation survive a real sea? ``parapend.persistence`` (command ``persistence``;
docs/persistence.md).

The model (SI, theta from the upright, hanging = pi)::

    I theta'' + c theta' - m l (g + z''(t)) sin(theta) = T,    T = -c_g theta'     (1)

a passive generator of damping ``c_g`` (harvested power ``c_g theta'^2``) on a bearing of
damping ``c``; ``z(t)`` the periodic sea record of ``parapend sea`` (JONSWAP or
Pierson-Moskowitz, components ``f_k = k / T_r`` up to ``cutoff / Tp``, amplitudes
``sqrt(2 S(f_k) / T_r)``, uniform phases; :mod:`._persist_spec` says how realizations are
seeded), or the heave of a buoy through a response table, as ``sea`` takes it.

Start ``theta(0) = pi``, ``theta'(0) = 2 pi / Tp``. Per realization over the window
``[t_tr, T_r]`` (``t_tr`` the transient, default ``10 Tp``, rounded to the step grid;
``T_r`` the record's length, ``duration``):

- ``rho``: net forward turns per peak period, ``(theta(T_r) - theta(t_tr)) Tp / (2 pi
  (T_r - t_tr))``;
- the mean harvested power ``c_g int theta'^2 dt / (T_r - t_tr)``;
- rotating throughout: the window cut into consecutive ``2 Tp`` windows from ``t_tr`` (a
  last partial one dropped), each advancing at least ``pi``.

Per sea state: ``P_rot`` (the fraction of realizations with ``rho >= 0.5``), the fraction
rotating throughout, the mean ``rho`` and the mean power, with 95 % confidence intervals:
Wilson's for the fractions, Student's t for the means.

The energy identity (1) times ``theta'``, integrated over the window::

    c_g int theta'^2 + c int theta'^2 = m l int z'' sin(theta) theta' - Delta E,
    E = I theta'^2 / 2 + m g l cos(theta)                                           (2)

holds for every realization to the integrator's accuracy (the kernel integrates the
quadratures with the same RK4 stages as the state).

The integration (:mod:`._persist_kernel`): classical RK4 with a fixed step ``h = T_r / M``,
``z''`` at the half steps by one inverse real FFT of the record's spectrum (exact for the
periodic record: every component below the grid's Nyquist frequency). The step is chosen
from the problem (:func:`choose_step`) and checked once by halving it (``step_check``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import limits
from ..defaults import PERSISTENCE
from ..errors import ParameterError, check_int, check_positive, check_range
from ..results import Result
from ._persist_cells import (  # noqa: F401 - the cell's functions, for the API's users
    acceleration,
    best_damping,
    cell_plan,
    choose_step,
    energy_residual,
    record_heave,
    run_cell,
    step_check,
)
from .basins import wilson_interval as _wilson

__all__ = ["PersistenceResult", "choose_step", "persistence", "wilson_interval",
           "t_interval"]

#: RK4 steps a second on one core (the kernel on the two-core reference machine), for the
#: work estimate
STEP_RATE = 5e6
_Z95 = 1.959963984540054
CONTROLLERS = ("track",)


# -- statistics ------------------------------------------------------------------------------

def wilson_interval(successes: int, n: int, z: float = _Z95) -> tuple[float, float]:
    """Wilson's score interval of a binomial fraction (95 % by default); (nan, nan) for n = 0.

    :func:`parapend.dynamics.basins.wilson_interval`'s, whose ends are exactly 0 for no
    success and 1 for all.
    """
    if n <= 0:
        return (math.nan, math.nan)
    return _wilson(successes, n, z)


def t_interval(x) -> tuple[float, float]:
    """Student's t 95 % interval of the mean of ``x`` (finite values); (nan, nan) below two."""
    from scipy.stats import t as student

    x = np.asarray(x, dtype=float)
    n = x.size
    if n < 2:
        return (math.nan, math.nan)
    m = float(np.mean(x))
    half = float(student.ppf(0.975, n - 1)) * float(np.std(x, ddof=1)) / math.sqrt(n)
    return (m - half, m + half)


# -- inputs ------------------------------------------------------------------------------------

def _values(flag: str, value, lo: float, hi: float, what: str) -> tuple:
    """A number, a sequence, ``START:STOP:COUNT`` or ``A,B,C``, each value in [lo, hi]."""
    if isinstance(value, str):
        text = value.strip()
        try:
            if text.count(":") == 2:
                a, b, c = text.split(":")
                count = int(c)
                if not 1 <= count <= limits.PERSISTENCE_MAX_AXIS:
                    raise ParameterError(f"{flag}: expected a COUNT of 1 to "
                                         f"{limits.PERSISTENCE_MAX_AXIS}, got {count}")
                vals = np.linspace(float(a), float(b), count).tolist()
            else:
                vals = [float(p) for p in text.split(",")]
        except ValueError:
            raise ParameterError(f"{flag}: expected a number, START:STOP:COUNT or a comma "
                                 f"list, got {value!r:.60}") from None
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        vals = [float(value)]
    else:
        try:
            vals = [float(v) for v in value]
        except (TypeError, ValueError):
            raise ParameterError(f"{flag}: expected numbers, got {value!r:.60}") from None
    if not vals or len(vals) > limits.PERSISTENCE_MAX_AXIS:
        raise ParameterError(f"{flag}: expected 1 to {limits.PERSISTENCE_MAX_AXIS} values, "
                             f"got {len(vals)}")
    for v in vals:
        if not (math.isfinite(v) and lo <= v <= hi):
            raise ParameterError(f"{flag}: expected {what} in [{lo:g}, {hi:g}], got {v!r}")
    return tuple(vals)


def _generator(value) -> tuple:
    if isinstance(value, str) and value.strip() == "best":
        return ("best",)
    vals = _values("generator-damping", value, -math.inf, math.inf, "N m s/rad")
    for v in vals:
        if v < 0 or v > limits.PERSISTENCE_MAX_DAMPING:
            raise ParameterError(f"generator-damping: expected N m s/rad in [0, "
                                 f"{limits.PERSISTENCE_MAX_DAMPING:g}] or 'best', got {v!r}")
    return vals


# -- the statistics of a map -----------------------------------------------------------------

def cell_statistics(values: dict, done) -> dict:
    """The JSON statistics of one cell from its per-realization values (finished and finite
    only)."""
    ok = np.asarray(done, dtype=bool) & (np.asarray(values["status"]) == 0)
    n = int(ok.sum())
    rho = np.asarray(values["rho"])[ok]
    thr = np.asarray(values["throughout"])[ok]
    pw = np.asarray(values["power"])[ok]
    k_rot = int(np.sum(rho >= 0.5))
    k_thr = int(np.sum(thr == 1.0))
    d = {"p_rot": k_rot / n if n else math.nan, "p_rot_ci": list(wilson_interval(k_rot, n)),
         "p_throughout": k_thr / n if n else math.nan,
         "p_throughout_ci": list(wilson_interval(k_thr, n)),
         "rho_mean": float(np.mean(rho)) if n else math.nan,
         "rho_mean_ci": list(t_interval(rho)),
         "power_mean_w": float(np.mean(pw)) if n else math.nan,
         "power_mean_ci_w": list(t_interval(pw)), "realizations": n,
         "nonfinite": int(np.sum(np.asarray(done, dtype=bool)
                                 & (np.asarray(values["status"]) != 0))),
         "energy_residual_max": float(np.max(energy_residual(
             {k: np.asarray(values[k])[ok] for k in ("harvested_energy", "dissipated_energy",
                                                     "base_work", "stored_energy_change")})))
         if n else math.nan,
         "generator_damping_nm_s_per_rad": float(np.asarray(values["generator_damping"])[ok][0])
         if n else math.nan}
    if "omniscient_power" in values:
        om = np.asarray(values["omniscient_power"])[ok]
        sel = np.isfinite(om)
        d["omniscient_realizations"] = int(sel.sum())
        d["omniscient_power_mean_w"] = float(np.mean(om[sel])) if sel.any() else math.nan
        d["passive_fraction_of_omniscient"] = (float(np.mean(pw[sel]) / np.mean(om[sel]))
                                               if sel.any() else math.nan)
    if "controller_power" in values:
        cp = np.asarray(values["controller_power"])[ok]
        sel = np.isfinite(cp)
        d["controller_realizations"] = int(sel.sum())
        d["controller_power_mean_w"] = float(np.mean(cp[sel])) if sel.any() else math.nan
        d["controller_passive_power_mean_w"] = (float(np.mean(pw[sel])) if sel.any()
                                                else math.nan)
        if "omniscient_power" in values:
            om = np.asarray(values["omniscient_power"])[ok]
            both = sel & np.isfinite(om)
            d["controller_fraction_of_omniscient"] = (
                float(np.mean(cp[both]) / np.mean(om[both])) if both.any() else math.nan)
    return d


@dataclass(frozen=True, eq=False, repr=False)
class PersistenceResult(Result):
    """A rotation persistence map (field names = JSON keys of ``parapend persistence``).

    Attributes
    ----------
    sea_states : list of dict
        One per sea state and generator setting: ``hs_m``, ``tp_s``, ``tp_over_t0``,
        ``generator_damping_nm_s_per_rad`` (the one used), ``p_rot``, ``p_rot_ci``,
        ``p_throughout``, ``p_throughout_ci``, ``rho_mean``, ``rho_mean_ci``,
        ``power_mean_w``, ``power_mean_ci_w`` (intervals ``[low, high]``, 95 %),
        ``realizations`` (finite runs counted), ``nonfinite``, ``energy_residual_max``,
        ``step_s``; with the options, the omniscient optimum and the controller.
    small_swing_period_s : float
        ``T0 = 2 pi sqrt(I / (m g l))``.
    step_check : dict
        The step-halving check (``step_check``).
    status : str
        ``"done"`` or ``"time_limit"`` (a partial map: the cells not finished are NaN).
    """

    sea_states: list
    small_swing_period_s: float
    mass_kg: float
    length_m: float
    inertia_kg_m2: float
    gravity_m_per_s2: float
    damping_coefficient_nm_s_per_rad: float
    generator_damping: list
    spectrum: str
    gamma_peak: float | None
    cutoff: float
    duration_s: float
    transient_s: float | None
    realizations: int
    seed: int
    seeds: str
    step_check: dict
    cells: int
    cells_finished: int
    status: str
    success: bool
    message: str
    executor: str
    store: str | None
    seconds: float
    _dataset: object = field(default=None, repr=False)

    command = "persistence"
    headline = ("cells", "realizations", "status")

    @property
    def dataset(self):
        """The per-realization Dataset (the store's variables)."""
        return self._dataset

    def _series(self):
        return persistence_dataset(self)

    def to_dataset(self):
        from ..results import annotate

        ds = persistence_dataset(self)
        for k, v in self.to_dict().items():
            if k == "sea_states":
                continue
            if isinstance(v, (bool, int, float)) and not isinstance(v, bool):
                ds[k] = ((), np.asarray(v, dtype=np.int64 if isinstance(v, int) else float))
            elif v is not None:
                from ..results import _attr_value

                ds.attrs[k] = _attr_value(v)
        return annotate(ds, self.command)

    def _figure(self):
        return plot_persistence(self)


_GRID_KEYS = ("p_rot", "p_throughout", "rho_mean", "power_mean_w")


def persistence_dataset(r: PersistenceResult):
    """The statistics over ``hs_m x tp_s x generator`` (CIs as ``*_ci_low``/``*_ci_high``)."""
    import xarray as xr

    hs = sorted({s["hs_m"] for s in r.sea_states})
    tp = sorted({s["tp_s"] for s in r.sea_states})
    ng = len(r.generator_damping)
    shape = (len(hs), len(tp), ng)
    names = {}
    for key in _GRID_KEYS:
        names[key] = key
        ci = key.replace("_w", "") + "_ci" + ("_w" if key.endswith("_w") else "")
        base = key[:-2] if key.endswith("_w") else key
        unit = "_w" if key.endswith("_w") else ""
        names[ci + ":0"] = f"{base}_ci_low{unit}"
        names[ci + ":1"] = f"{base}_ci_high{unit}"
    names["generator_damping_nm_s_per_rad"] = "generator_damping_nm_s_per_rad"
    extra = [k for k in ("omniscient_power_mean_w", "passive_fraction_of_omniscient",
                         "controller_power_mean_w", "controller_fraction_of_omniscient")
             if r.sea_states and k in r.sea_states[0]]
    for k in extra:
        names[k] = k
    arrays = {v: np.full(shape, np.nan) for v in names.values()}
    for n, s in enumerate(r.sea_states):
        idx = (hs.index(s["hs_m"]), tp.index(s["tp_s"]), n % ng)
        for src, dst in names.items():
            key, _, pos = src.partition(":")
            v = s.get(key)
            if pos:
                v = None if v is None else v[int(pos)]
            arrays[dst][idx] = math.nan if v is None else v
    long = {"p_rot": "P_rot: fraction of realizations with rho >= 0.5",
            "p_throughout": "fraction of realizations rotating throughout",
            "rho_mean": "mean rotation ratio rho (turns per peak period)",
            "power_mean_w": "mean harvested power"}
    ds = xr.Dataset(
        {k: (("hs_m", "tp_s", "generator"), v,
             {"long_name": long.get(k, k.replace("_", " ")) + (
                 " (95 % interval)" if "_ci_" in k else "")})
         for k, v in arrays.items()},
        coords={"hs_m": ("hs_m", np.array(hs), {"units": "m",
                                                "long_name": "significant wave height Hs"}),
                "tp_s": ("tp_s", np.array(tp), {"units": "s", "long_name": "peak period Tp"}),
                "generator": ("generator", np.arange(ng),
                              {"units": "1", "long_name": "generator setting"})})
    ds["tp_over_t0"] = ("tp_s", np.array(tp) / r.small_swing_period_s,
                        {"units": "1", "long_name": "Tp / T0"})
    return ds


def plot_persistence(r: PersistenceResult, generator: int = 0):
    """Maps of P_rot and of the mean power over ``Tp / T0 x Hs`` (the first generator
    setting), each beside the width of its 95 % interval."""
    import matplotlib.pyplot as plt

    ds = persistence_dataset(r).isel(generator=generator)
    x = ds["tp_over_t0"].values
    y = ds["hs_m"].values
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), constrained_layout=True)
    panels = [("p_rot", "P_rot (rho >= 0.5)", (0, 1), "viridis"),
              (None, "P_rot: 95 % interval width", None, "magma"),
              ("power_mean_w", "mean harvested power, W", None, "viridis"),
              (None, "mean power: 95 % interval, relative width", None, "magma")]
    widths = [ds["p_rot_ci_high"] - ds["p_rot_ci_low"],
              (ds["power_mean_ci_high_w"] - ds["power_mean_ci_low_w"])
              / abs(ds["power_mean_w"])]
    for n, (ax, (key, title, lim, cmap)) in enumerate(zip(axes.flat, panels)):
        z = ds[key].values if key else widths[n // 2].values
        kw = {"vmin": lim[0], "vmax": lim[1]} if lim else {}
        m = ax.pcolormesh(x, y, z, shading="nearest", cmap=cmap, **kw)
        fig.colorbar(m, ax=ax)
        ax.set_xlabel("Tp / T0")
        ax.set_ylabel("Hs (m)")
        ax.set_title(title)
    g = r.sea_states[generator]["generator_damping_nm_s_per_rad"] if r.sea_states else None
    fig.suptitle(f"rotation persistence: {r.realizations} realizations of "
                 f"{r.duration_s:g} s records, T0 = {r.small_swing_period_s:.3g} s"
                 + ("" if g is None or len(r.generator_damping) > 1 or r.generator_damping
                    == ["best"] else f", c_g = {g:.3g} N m s/rad"))
    return fig


# -- the command -------------------------------------------------------------------------------

def persistence_spec(*, mass, length, inertia, gravity, damping_coefficient,
                     generator_damping, hs, tp, spectrum, gamma_peak, cutoff, response,
                     duration, transient, realizations, seed, omniscient, controller,
                     gpu, block=None):
    """Check every input and make the map's :class:`._persist_spec.PersistenceSpec`."""
    from ..seas import check_response, check_spectrum, read_response
    from ..units import Units
    from ._persist_spec import PersistenceSpec

    u = Units(length, mass, gravity, inertia)
    c = check_range("damping-coefficient", damping_coefficient, 0.0,
                    limits.PERSISTENCE_MAX_DAMPING, why="N m s/rad")
    gens = _generator(generator_damping)
    hs_v = _values("hs", hs, -math.inf, math.inf, "m")
    for v in hs_v:
        if not 0 < v <= limits.SEA_MAX_HS:
            raise ParameterError(f"hs: expected a significant wave height in (0, "
                                 f"{limits.SEA_MAX_HS:g}] m, got {v!r}")
    lo, hi = limits.PERSISTENCE_TP_RANGE
    tp_v = _values("tp", tp, -math.inf, math.inf, "s")
    for v in tp_v:
        if not lo <= v <= hi:
            raise ParameterError(f"tp: expected a peak period in [{lo:g}, {hi:g}] s (the "
                                 f"spectra's range here), got {v!r}")
    gamma_peak, cutoff = check_spectrum(spectrum, gamma_peak, cutoff)
    duration = check_positive("duration", duration)
    if transient is not None:
        transient = check_range("transient", transient, 0.0, math.inf, why="s")
    longest = max(10 * max(tp_v) if transient is None else transient, 0.0)
    if duration < longest + 2 * max(tp_v):
        raise ParameterError(f"duration: expected a record longer than the transient "
                             f"({longest:g} s) by at least one 2 Tp window "
                             f"({2 * max(tp_v):g} s), got {duration:g} s")
    waves = duration / min(tp_v)
    if waves > limits.PERSISTENCE_MAX_WAVES:
        raise ParameterError(f"duration: expected at most {limits.PERSISTENCE_MAX_WAVES:g} "
                             f"peak periods ({min(tp_v):g} s each), got {duration:g} s = "
                             f"{waves:.4g}")
    realizations = check_int("realizations", realizations, 1, limits.PERSISTENCE_MAX_REALIZATIONS)
    seed = check_int("seed", seed, 0, 2**62)
    omniscient = check_int("omniscient", omniscient, 0, realizations)
    if controller is not None and controller not in CONTROLLERS:
        raise ParameterError(f"controller: expected one of {', '.join(CONTROLLERS)}, got "
                             f"{controller!r:.60}")
    resp = None
    if response is not None:
        if isinstance(response, str):
            resp = read_response(response)
        else:
            try:
                rf, rg, rp = response
            except (TypeError, ValueError):
                raise ParameterError("response: expected a CSV path or three arrays (f, "
                                     "gain, phase)") from None
            resp = check_response(rf, rg, rp)
        resp = tuple(tuple(float(x) for x in a) for a in resp)
    if omniscient:
        if resp is not None:
            raise ParameterError("omniscient: not with --response (the optimum of parapend "
                                 "sea is solved for the surface's heave)")
        for v in tp_v:
            if duration / v > limits.SEA_WAVES_RANGE[1]:
                raise ParameterError(f"omniscient: parapend sea solves records of at most "
                                     f"{limits.SEA_WAVES_RANGE[1]:g} peak periods; got "
                                     f"{duration / v:.4g} at Tp = {v:g} s (shorten "
                                     "--duration)")
    if gpu:
        from ._persist_gpu import available

        why = available()
        if why:
            raise ParameterError(f"gpu: {why}")
    if block is None:
        # the search of best needs the whole cell; a GPU launch takes it whole as well
        block = realizations if gens == ("best",) or gpu else min(realizations, 256)
    spec = PersistenceSpec(hs=hs_v, tp=tp_v, generator=gens, realizations=realizations,
                           block=int(block), seed=seed, spectrum=spectrum,
                           gamma_peak=float(gamma_peak), cutoff=float(cutoff),
                           response=resp, duration=float(duration),
                           transient=None if transient is None else float(transient),
                           mass=u.mass, length=u.length, inertia=u.inertia,
                           gravity=u.gravity, damping_coefficient=float(c),
                           omniscient=omniscient, controller=controller, gpu=bool(gpu))
    for j in range(len(tp_v)):
        kmax = int(math.floor(cutoff * duration / tp_v[j]))
        if kmax > limits.PERSISTENCE_MAX_COMPONENTS:
            raise ParameterError(f"duration: {kmax} components at Tp = {tp_v[j]:g} s (at "
                                 f"most {limits.PERSISTENCE_MAX_COMPONENTS}); shorten the "
                                 "record or the cutoff")
    return spec


def estimate_steps(spec) -> float:
    """RK4 steps of the whole map (one lane-step each), the search of ``best`` and the step
    check included."""
    from ._persist_cells import BEST_COARSE, BEST_FINE, BEST_REALIZATIONS

    steps = 0.0
    per = len(spec.generator) * spec.realizations
    if spec.best:
        per += min(spec.realizations, BEST_REALIZATIONS) * (BEST_COARSE.size + BEST_FINE.size)
    for i in range(len(spec.hs)):
        for j in range(len(spec.tp)):
            steps += per * choose_step(spec, spec.hs[i], spec.tp[j])[0]
    return steps


def persistence(*, mass: float = PERSISTENCE["mass"], length: float = PERSISTENCE["length"],
                inertia: float | None = None, gravity: float = 9.81,
                damping_coefficient: float = PERSISTENCE["damping_coefficient"],
                generator_damping=PERSISTENCE["generator_damping"], hs=PERSISTENCE["hs"],
                tp=PERSISTENCE["tp"], spectrum: str = "jonswap", gamma_peak: float = 3.3,
                cutoff: float = 3.0, response=None,
                duration: float = PERSISTENCE["duration"], transient: float | None = None,
                realizations: int = PERSISTENCE["realizations"], seed: int = 0,
                omniscient: int = 0, controller: str | None = None, store=None,
                overwrite: bool = False, workers: int | None = None, scheduler=None,
                gpu: bool = False, time_limit: float | None = None, command=None,
                progress=None) -> PersistenceResult:
    """Rotation persistence over a grid of sea states: passive generator, and optionally the
    omniscient optimum and a causal controller on the same records (command
    ``persistence``: ``parapend.persistence`` is this function; docs/persistence.md).

    Parameters
    ----------
    mass, length, inertia, gravity : float
        The pendulum (kg, m, kg m^2 about the pivot, default ``m l^2``; m/s^2).
    damping_coefficient : float
        Bearing damping ``c``, N m s/rad (Eq. 1).
    generator_damping : float, sequence, str
        ``c_g`` (N m s/rad): one value, a list (``"A,B,C"``, ``"START:STOP:COUNT"``), or
        ``"best"``: per sea state the damping of the largest mean power, by a 1-D search on
        the same records (``best_damping``).
    hs, tp : float, sequence or str
        The sea states (m, s): a value, ``"A,B,C"`` or ``"START:STOP:COUNT"``.
    spectrum, gamma_peak, cutoff, response :
        The record, as ``parapend sea`` takes it (``cutoff`` in units of ``1/Tp``).
    duration : float
        The record's length ``T_r`` (s), its repeat period.
    transient : float or None
        ``t_tr`` (s) left out before the window; None: ``10 Tp``.
    realizations : int
        ``R`` records per sea state; realization ``r`` is seeded ``seed + r``.
    seed : int
        Seed of realization 0.
    omniscient : int
        On the first ``omniscient`` realizations of each cell also the omniscient optimum
        (``omniscient_power``: ``parapend sea``'s record optimum; records of at most 400
        peak periods), and the passive power as a fraction of it (default 0: not computed).
    controller : {"track", None}
        Also a causal controller on the same records (the first ``omniscient``, or 8):
        ``track``, the regular-wave tracker of ``parapend track --irregular``.
    store : path or None
        Zarr store of the per-realization results (resumed when it holds this map).
    overwrite : bool
        Replace a store that holds another map.
    workers : int or None
        Local processes (default: one, the kernel's threads over the realizations).
    scheduler : str or None
        A Dask scheduler's address: the blocks run there.
    gpu : bool
        Integrate on the GPU (numba.cuda; refused without one).
    time_limit : float or None
        Seconds after which no block is started: a partial map marked ``time_limit``.
    command : str or None
        The command line, recorded in the store.
    progress : callable or None
        ``progress(done, total)`` realizations.
    """
    import os
    import time

    from ..deadline import check_time_limit, deadline, refuse_untimed
    from ..deadline import duration as words
    from ..maps.run import run_spec

    t_start = time.monotonic()
    time_limit = check_time_limit(time_limit)
    until = deadline(time_limit)
    spec = persistence_spec(mass=mass, length=length, inertia=inertia, gravity=gravity,
                            damping_coefficient=damping_coefficient,
                            generator_damping=generator_damping, hs=hs, tp=tp,
                            spectrum=spectrum, gamma_peak=gamma_peak, cutoff=cutoff,
                            response=response, duration=duration, transient=transient,
                            realizations=realizations, seed=seed, omniscient=omniscient,
                            controller=controller, gpu=gpu)
    if workers is not None:
        workers = check_int("workers", workers, 1, 256)
    cores = os.cpu_count() or 1
    seconds = estimate_steps(spec) / (STEP_RATE * (1 if gpu else cores))
    if spec.omniscient or spec.controller:  # measured: 3 s a record of 100 peak periods
        per = 1.0 + 0.03 * spec.duration / min(spec.tp)
        seconds += len(spec.hs) * len(spec.tp) * per * (
            spec.omniscient + (0 if not spec.controller else spec.omniscient or
                               min(spec.realizations, 8)))
    if store is None and not gpu:
        refuse_untimed("realizations", f"a persistence map of {len(spec.hs)} x "
                       f"{len(spec.tp)} sea states x {len(spec.generator)} generator "
                       f"setting(s) x {spec.realizations} realizations", seconds,
                       "use fewer --realizations or sea states, or --store (resumable "
                       "work)", time_limit)
    if seconds > 60:
        import logging

        logging.getLogger(__name__).info(
            "persistence: %d sea states x %d realizations: roughly %s", len(spec.hs)
            * len(spec.tp), spec.realizations, words(seconds))
    run = run_spec(spec, store, workers=1 if workers is None and scheduler is None
                   else workers, scheduler=scheduler, overwrite=overwrite,
                   command=command, progress=progress, deadline=until)
    ds = run.dataset
    done = np.asarray(ds["done"].values, dtype=bool)
    states, finished = [], 0
    t0 = 2 * math.pi * math.sqrt((spec.inertia or spec.mass * spec.length**2)
                                 / (spec.mass * spec.gravity * spec.length))
    for i, h in enumerate(spec.hs):
        for j, p in enumerate(spec.tp):
            plan = cell_plan(spec, i, j)
            for k in range(len(spec.generator)):
                vals = {v: np.asarray(ds[v].values[j, i, k]) for v in spec.variables}
                cell_done = done[j, i, k]
                finished += int(cell_done.all())
                st = cell_statistics(vals, cell_done) if cell_done.all() else \
                    cell_statistics(vals, np.zeros_like(cell_done))
                states.append({"hs_m": h, "tp_s": p, "tp_over_t0": p / t0, **st,
                               "step_s": plan["h"],
                               "transient_s": plan["k0"] * plan["h"]})
    check = step_check(spec) if finished else {}
    stopped = bool(run.stopped)
    cells = len(spec.hs) * len(spec.tp) * len(spec.generator)
    msg = (f"time limit reached: {finished} of {cells} cells finished (the rest NaN)"
           + ("; run the same command again to compute them" if store else "")
           if stopped else f"{cells} cells of {spec.realizations} realizations")
    return PersistenceResult(
        sea_states=states, small_swing_period_s=t0, mass_kg=spec.mass,
        length_m=spec.length,
        inertia_kg_m2=spec.inertia if spec.inertia is not None else spec.mass
        * spec.length**2, gravity_m_per_s2=spec.gravity,
        damping_coefficient_nm_s_per_rad=spec.damping_coefficient,
        generator_damping=list(spec.generator), spectrum=spec.spectrum,
        gamma_peak=spec.gamma_peak if spec.spectrum == "jonswap" else None,
        cutoff=spec.cutoff, duration_s=spec.duration, transient_s=spec.transient,
        realizations=spec.realizations, seed=spec.seed,
        seeds=f"realization r of every sea state: numpy default_rng(seed + r), seed = "
              f"{spec.seed}, phases as parapend sea draws them",
        step_check=check, cells=cells, cells_finished=finished,
        status="time_limit" if stopped else "done", success=not stopped, message=msg,
        executor=run.executor, store=run.store, seconds=time.monotonic() - t_start,
        _dataset=ds)
