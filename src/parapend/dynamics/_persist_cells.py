r"""One cell of a persistence map: its records, the step, the batched runs of the kernel
and what each realization gives (:func:`run_cell`), the search of the best generator
damping, the omniscient optimum and the controller on a record, and the step-halving check.
The model and the definitions: :mod:`parapend.dynamics.persistence`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["acceleration", "best_damping", "cell_plan", "choose_step", "controller_power",
           "energy_residual", "omniscient_power", "record_heave", "run_cell", "run_column",
           "step_check"]

#: steps of RK4 per period of the highest component of the record
STEPS_PER_CUTOFF_PERIOD = 10
#: steps per period of the fastest small swing, ``2 pi / sqrt(m l (g + 4 sigma_z'') / I)``
STEPS_PER_SWING = 24
#: realizations of the hardest cell that the step-halving check runs
STEP_CHECK_REALIZATIONS = 16
#: generator dampings searched by ``best``: multiples of I 2 pi / Tp, a coarse grid in
#: log10 then a fine one around its best
BEST_COARSE = np.linspace(-4.0, 1.0, 11)
BEST_FINE = np.linspace(-0.5, 0.5, 9)
#: realizations of a cell that the search of ``best`` uses (common random numbers)
BEST_REALIZATIONS = 64
#: the kernel is fed records in batches of at most this many bytes of z''
BATCH_BYTES = 64 << 20


# -- records and the step -------------------------------------------------------------------

def record_heave(spec, hs: float, tp: float, seed: int) -> np.ndarray:
    """The complex heave spectrum (m) of realization ``seed``: ``z = Re sum_k Z_k e^{2 pi i k
    t / T_r}``, drawn as :func:`parapend.seas.sea_record` draws it (same generator calls),
    through the response table if any."""
    return record_heaves(spec, hs, tp, [seed])[0]


def record_heaves(spec, hs: float, tp: float, seeds) -> np.ndarray:
    """:func:`record_heave` of every seed of ``seeds``, one row each (the amplitudes once)."""
    from ..seas import jonswap, pierson_moskowitz

    tr = spec.duration
    kmax = int(math.floor(spec.cutoff * tr / tp))
    f = np.arange(kmax + 1) / tr
    s = (jonswap(f, hs, tp, spec.gamma_peak) if spec.spectrum == "jonswap"
         else pierson_moskowitz(f, hs, tp))
    s[0] = 0.0
    amp = np.sqrt(2.0 * s / tr)
    phase = np.array([np.random.default_rng(int(sd)).uniform(0.0, 2 * math.pi, kmax + 1)
                      for sd in seeds]).reshape(len(seeds), kmax + 1)
    z = amp * np.exp(1j * phase)
    z[:, 0] = 0.0
    if spec.response is not None:  # in sea_record's order of operations
        rf, rg, rp = (np.asarray(c) for c in spec.response)
        z = z * np.interp(f, rf, rg, left=0.0, right=0.0) * np.exp(1j * np.interp(f, rf, rp))
    return z


def _amplitudes(spec, hs: float, tp: float) -> np.ndarray:
    """``|Z_k|`` of every realization (the phases aside)."""
    z = record_heave(spec, hs, tp, 0)
    return np.abs(z)


def choose_step(spec, hs: float, tp: float) -> tuple[int, float]:
    """``(M, h)``: the RK4 steps over the record and the step (s), ``h = T_r / M``.

    ``h`` is at most a tenth of the period of the highest component (``Tp / cutoff``) and a
    24th of the fastest small swing, ``2 pi / sqrt(m l (g + 4 sigma) / I)`` with ``sigma``
    the standard deviation of ``z''`` (its peaks rarely exceed 4 sigma); ``2 M`` is then
    rounded up to a length the FFT takes fast."""
    from scipy.fft import next_fast_len

    amp = _amplitudes(spec, hs, tp)
    w = 2 * math.pi * np.arange(amp.size) / spec.duration
    sigma = math.sqrt(float(np.sum((w**2 * amp) ** 2)) / 2.0)
    inertia = spec.inertia if spec.inertia is not None else spec.mass * spec.length**2
    swing = 2 * math.pi / math.sqrt(spec.mass * spec.length * (spec.gravity + 4 * sigma)
                                    / inertia)
    hmax = min(tp / spec.cutoff / STEPS_PER_CUTOFF_PERIOD, swing / STEPS_PER_SWING)
    m = next_fast_len(2 * int(math.ceil(spec.duration / hmax)), real=True)
    m += m % 2
    return m // 2, spec.duration / (m // 2)


def cell_plan(spec, i: int, j: int, refine: int = 1) -> dict:
    """Everything a run of cell ``(i, j)`` needs: the sea state, the step (``refine``
    times finer), the window and the pendulum's constants."""
    hs, tp = spec.hs[i], spec.tp[j]
    m, h = choose_step(spec, hs, tp)
    tr = spec.duration
    t_tr = 10.0 * tp if spec.transient is None else spec.transient
    k0 = int(round(t_tr / h)) * refine  # the same window start at every refinement
    m, h = m * refine, h / refine
    window = tr - k0 * h
    inertia = spec.inertia if spec.inertia is not None else spec.mass * spec.length**2
    return {"hs": hs, "tp": tp, "m": m, "h": h, "k0": k0, "window": window,
            "nwin": int(math.floor(window / (2 * tp) * (1 + 1e-12))), "inertia": inertia,
            "a": spec.mass * spec.length / inertia, "om0": 2 * math.pi / tp}


def acceleration(spec, plan: dict, seeds) -> np.ndarray:
    """``z''`` (m/s^2) of the realizations ``seeds`` at the half steps, one row each: one
    inverse real FFT per record of unit ``Hs`` (exact at the grid's points for the periodic
    record), times ``Hs`` (the spectrum's amplitudes are proportional to ``Hs``: the records
    of every ``Hs`` of a ``Tp`` share their unit record, to rounding :func:`record_heave`'s)."""
    z = record_heaves(spec, 1.0, plan["tp"], seeds)
    return plan["hs"] * _unit_acceleration(spec, z, 2 * plan["m"])


def _unit_acceleration(spec, z, n: int):
    """``z''`` on ``n`` points per record of the heave spectra ``z`` (one a row): on the GPU
    by CuPy when asked for and there (a CuPy array), else by SciPy."""
    if spec.gpu:
        from ._persist_gpu import acceleration_gpu

        out = acceleration_gpu(z, n, spec.duration)
        if out is not None:
            return out
    from scipy import fft

    from ._persist_kernel import threads

    w2 = (2 * math.pi * np.arange(z.shape[1]) / spec.duration) ** 2
    spec_n = np.zeros((z.shape[0], n // 2 + 1), dtype=complex)
    spec_n[:, :z.shape[1]] = -w2 * z * (n / 2)
    return fft.irfft(spec_n, n, axis=1, workers=threads())


#: unit records in the kernel's layout, kept for the next cells of the same Tp (the blocks
#: run Hs after Hs within a Tp): key -> array, least recently used first
_UNIT: dict = {}
#: at most this many bytes of them
UNIT_CACHE_BYTES = 384 << 20


def _grouped_unit(spec, plan: dict, seeds):
    """The unit records of ``seeds`` (``acceleration`` at ``Hs = 1``) in the kernel's
    grouped layout (:func:`._persist_kernel.group`), from the cache when there."""
    from ._persist_kernel import group

    key = (spec.duration, spec.cutoff, spec.spectrum, spec.gamma_peak, spec.response,
           plan["tp"], plan["m"], tuple(int(x) for x in seeds))
    hit = _UNIT.pop(key, None)
    if hit is None:
        hit = group(acceleration(spec, {**plan, "hs": 1.0}, seeds))
    if hit.nbytes <= UNIT_CACHE_BYTES:
        _UNIT[key] = hit
        while sum(a.nbytes for a in _UNIT.values()) > UNIT_CACHE_BYTES:
            _UNIT.pop(next(iter(_UNIT)))
    return hit


def _batch(spec, plan: dict) -> int:
    from ._persist_kernel import LANES

    if spec.gpu:  # every realization of the block in one launch
        return max(LANES, spec.block)
    rows = max(LANES, BATCH_BYTES // (16 * plan["m"]))
    return rows - rows % LANES


def _integrate(spec, plan: dict, zdd, bdamp, lanes=None):
    """The kernel on ``zdd`` (one record a row; or grouped, with ``lanes`` records)."""
    kw = {"a": plan["a"], "g": spec.gravity, "th0": math.pi, "om0": plan["om0"],
          "h": plan["h"], "k0": plan["k0"], "twin": 2 * plan["tp"], "nwin": plan["nwin"]}
    if spec.gpu:
        from ._persist_gpu import run_batch_gpu

        return run_batch_gpu(zdd, bdamp, **kw)
    from ._persist_kernel import run_batch

    return run_batch(zdd, bdamp, lanes=lanes, **kw)


def _summaries(spec, plan: dict, cg, out, flags) -> dict:
    """Per-realization quantities from the kernel's output (``cg``: per lane or one)."""
    inertia, tp, window = plan["inertia"], plan["tp"], plan["window"]
    cg = np.broadcast_to(np.asarray(cg, dtype=float), flags.shape)
    ml = spec.mass * spec.length
    s2 = out[:, 4]
    harvested = cg * s2
    de = (0.5 * inertia * (out[:, 3] ** 2 - out[:, 1] ** 2)
          + ml * spec.gravity * (np.cos(out[:, 2]) - np.cos(out[:, 0])))
    return {"rho": (out[:, 2] - out[:, 0]) * tp / (2 * math.pi * window),
            "throughout": (flags == 1).astype(float), "power": harvested / window,
            "harvested_energy": harvested,
            "dissipated_energy": spec.damping_coefficient * s2,
            "base_work": ml * out[:, 5], "stored_energy_change": de,
            "generator_damping": np.array(cg, dtype=float), "finite": flags >= 0}


def run_cell(spec, plan: dict, cg: float, realizations, *, extras: bool = True) -> dict:
    """Run the realizations ``realizations`` (indices) of a cell at generator damping ``cg``:
    per-realization arrays of :data:`._persist_spec.STORED` and ``finite``, and the optional
    columns (omniscient optimum, controller) for the realizations that get them."""
    idx = list(realizations)
    seeds = [spec.seed + r for r in idx]
    bd = (spec.damping_coefficient + cg) / plan["inertia"]
    step = _batch(spec, plan)
    parts = []
    for s in range(0, len(seeds), step):
        batch = seeds[s:s + step]
        if spec.gpu:
            parts.append(_integrate(spec, plan, acceleration(spec, plan, batch), bd))
        else:  # the unit records shared by the cells of this Tp, times Hs
            zg = plan["hs"] * _grouped_unit(spec, plan, batch)
            parts.append(_integrate(spec, plan, zg, bd, lanes=len(batch)))
    out = np.concatenate([p[0] for p in parts])
    flags = np.concatenate([p[1] for p in parts])
    vals = _summaries(spec, plan, cg, out, flags)
    return _extras(spec, plan, vals, idx) if extras else vals


def _extras(spec, plan: dict, vals: dict, idx) -> dict:
    """``vals`` with the optional columns (omniscient optimum, controller) of the
    realizations ``idx`` that get them."""
    if spec.omniscient:
        vals["omniscient_power"] = np.array([
            omniscient_power(spec, plan, spec.seed + r) if r < spec.omniscient else math.nan
            for r in idx])
    if spec.controller:
        vals["controller_power"] = np.array([
            controller_power(spec, plan, spec.seed + r) if r < _controlled(spec) else math.nan
            for r in idx])
    return vals


#: the GPU path takes at most this many bytes of unit records per launch (with the FFT's
#: buffers and the transposed copy, about four times this on the GPU)
GPU_RECORD_BYTES = 1 << 30


def run_column(spec, j: int) -> list:
    """GPU: every cell of the ``Tp`` column ``j`` (all ``Hs``, generator settings and
    realizations), each as :func:`run_cell` gives it, in lists indexed ``[i][k]`` (``Hs``,
    generator). One launch per batch of realizations (:data:`GPU_RECORD_BYTES` of unit
    records; the acceptance map's columns take one): the phases drawn once, the unit
    records made on the GPU once per step size among the column's cells, each lane
    scaled by its cell's ``Hs``."""
    from ._persist_gpu import run_column_gpu

    nh, ng, nr = len(spec.hs), len(spec.generator), spec.realizations
    plans = [cell_plan(spec, i, j) for i in range(nh)]
    cgs = np.array([[best_damping(spec, plans[i]) if spec.best else float(spec.generator[k])
                     for k in range(ng)] for i in range(nh)])
    steps: dict = {}  # the step sizes of the column's cells, in order of appearance
    group = [steps.setdefault(p["m"], len(steps)) for p in plans]
    ms = list(steps)
    cells = {"group": np.repeat(group, ng), "scale": np.repeat([p["hs"] for p in plans], ng),
             "bdamp": ((spec.damping_coefficient + cgs) / plans[0]["inertia"]).ravel()}
    for key in ("h", "k0", "nwin"):
        cells[key] = np.repeat([p[key] for p in plans], ng)
    out = np.empty((nh, ng, nr, 6))
    flags = np.empty((nh, ng, nr), dtype=np.int8)
    per = max(1, GPU_RECORD_BYTES // (16 * sum(ms)))
    for r0 in range(0, nr, per):
        r1 = min(nr, r0 + per)
        z = record_heaves(spec, 1.0, plans[0]["tp"], [spec.seed + r for r in range(r0, r1)])
        o, f = run_column_gpu([_unit_acceleration(spec, z, 2 * m) for m in ms], cells,
                              a=plans[0]["a"], g=spec.gravity, th0=math.pi,
                              om0=plans[0]["om0"], twin=2 * plans[0]["tp"])
        out[:, :, r0:r1] = o.reshape(nh, ng, r1 - r0, 6)
        flags[:, :, r0:r1] = f.reshape(nh, ng, r1 - r0)
    idx = list(range(nr))
    return [[_extras(spec, plans[i], _summaries(spec, plans[i], cgs[i, k], out[i, k],
                                                flags[i, k]), idx)
             for k in range(ng)] for i in range(nh)]


def _controlled(spec) -> int:
    """Realizations of each cell the controller runs on: the omniscient's, or 8."""
    return spec.omniscient or min(spec.realizations, 8)


def best_damping(spec, plan: dict) -> float:
    """The generator damping (N m s/rad) that maximizes the mean power of the cell's first
    ``BEST_REALIZATIONS`` realizations (common random numbers): a coarse grid of
    ``c_g = I (2 pi / Tp) 10^x``, ``x`` in :data:`BEST_COARSE`, then a fine grid of
    :data:`BEST_FINE` around its best."""
    n = min(spec.realizations, BEST_REALIZATIONS)
    zdd = acceleration(spec, plan, [spec.seed + r for r in range(n)])
    ref = plan["inertia"] * plan["om0"]

    def best_of(xs):
        mean = []
        for x in xs:
            cg = ref * 10.0**x
            out, flags = _integrate(spec, plan, zdd, (spec.damping_coefficient + cg)
                                    / plan["inertia"])
            p = _summaries(spec, plan, cg, out, flags)["power"]
            mean.append(float(np.mean(p)) if np.all(np.isfinite(p)) else -np.inf)
        return xs[int(np.argmax(mean))]

    x = best_of(BEST_COARSE)
    x = best_of(x + BEST_FINE)
    return float(ref * 10.0**x)


def _similar(spec, tp: float) -> float:
    """The length scale ``lambda`` of the similar pendulum on which ``parapend sea`` (whose
    peak periods start at 1 s) solves a record of peak period ``tp``: 1 for ``tp >= 1.25 s``."""
    return 1.0 if tp >= 1.25 else (1.25 / tp) ** 2


def omniscient_power(spec, plan: dict, seed: int) -> float:
    """The omniscient optimum (W) of the record ``seed``: :func:`parapend.irregular.sea`
    (winding 1, the bearing's damping ``c``, any torque), on the similar pendulum (lengths
    times ``lambda``, inertia ``lambda^2``, damping ``lambda^{3/2}``, times
    ``sqrt(lambda)``: the same non-dimensional problem) when ``Tp < 1.25 s``; its power
    divided by ``sqrt(lambda)``."""
    from ..irregular import sea

    tp = plan["tp"]
    lam = _similar(spec, tp)
    r = sea(hs=plan["hs"] * lam, tp=tp * math.sqrt(lam), spectrum=spec.spectrum,
            gamma_peak=spec.gamma_peak, repeat_period=spec.duration * math.sqrt(lam),
            seed=int(seed), cutoff=spec.cutoff, length=spec.length * lam, mass=spec.mass,
            inertia=plan["inertia"] * lam**2, gravity=spec.gravity,
            damping_coefficient=spec.damping_coefficient * lam**1.5)
    return r.power_w / math.sqrt(lam) if r.status == "converged" else math.nan


def controller_power(spec, plan: dict, seed: int) -> float:
    """The causal controller's mean power (W) on the record ``seed``: the regular-wave
    tracker of ``parapend track --irregular``
    (:func:`parapend.control.baselines.tracker_baseline`, lossless, no torque limit) from
    the same start, over the whole record."""
    import dataclasses

    from ..control.baselines import tracker_baseline
    from ..units import Units

    u = Units(spec.length, spec.mass, spec.gravity, spec.inertia)
    n = 8 * plan["m"]
    zdd = acceleration(dataclasses.replace(spec, gpu=False), {**plan, "m": n // 2}, [seed])[0]
    tgrid = np.arange(n + 1) * spec.duration / n
    zq = np.append(zdd, zdd[0]) / spec.gravity

    def q(t):
        ts = np.mod(np.asarray(t, dtype=float) * u.time, spec.duration)
        return np.interp(ts, tgrid, zq)

    run = tracker_baseline(q, peak_omega=2 * math.pi * u.time / plan["tp"],
                           gamma=u.gamma(spec.damping_coefficient),
                           t_end=spec.duration / u.time, theta0=math.pi,
                           theta_dot0=plan["om0"] * u.time)
    return u.to_watts(run.mean_power) if run.success else math.nan


# -- the step check ---------------------------------------------------------------------------

def step_check(spec, cg=None) -> dict:
    """Run the first realizations of the hardest cell (largest Hs, shortest Tp) at the
    chosen step and at half of it. Reported: the largest change of theta after the first
    peak period (``theta_change_rad``: the step's error over one Tp, before the motion's
    sensitivity takes over; Richardson: the error at the step is about 16/15 of it), the
    largest relative residual of the energy identity (2) at the step, and, over the
    window, the change of the mean power (relative), the largest change of ``rho`` and the
    fraction of realizations whose ``rho`` agree within 0.01 (a chaotic realization need
    not agree: only its statistics are comparable, within their intervals)."""
    i, j = len(spec.hs) - 1, 0
    n = min(spec.realizations, STEP_CHECK_REALIZATIONS)
    res, first = [], []
    for refine in (1, 2):
        plan = cell_plan(spec, i, j, refine)
        if cg is None:
            cg = best_damping(spec, plan) if spec.best else float(spec.generator[0])
        zdd = acceleration(spec, plan, [spec.seed + r for r in range(n)])
        bd = (spec.damping_coefficient + cg) / plan["inertia"]
        out, flags = _integrate(spec, plan, zdd, bd)
        res.append(_summaries(spec, plan, cg, out, flags))
        # the first peak period alone (z'' cut after it; its state is the "window start")
        k1 = max(1, int(round(plan["tp"] / plan["h"] / refine))) * refine
        short = _integrate(spec, {**plan, "k0": k1, "nwin": 0}, zdd[:, :2 * k1 + 1], bd)
        first.append(short[0][:, 0])
    a, b = res
    ok = a["finite"] & b["finite"]
    pa, pb = np.mean(a["power"][ok]), np.mean(b["power"][ok])
    drho = np.abs(a["rho"] - b["rho"])[ok]
    plan = cell_plan(spec, i, j)
    dth = np.abs(first[0] - first[1])[ok]
    return {"hs_m": spec.hs[i], "tp_s": spec.tp[j], "generator_damping_nm_s_per_rad": cg,
            "realizations": int(n), "step_s": plan["h"],
            "steps_per_peak_period": plan["tp"] / plan["h"],
            "theta_change_rad": float(np.max(dth)) if dth.size else math.nan,
            "energy_residual_max": float(np.max(energy_residual(a)[ok])) if ok.any()
            else math.nan,
            "power_change_relative": float(abs(pa - pb) / max(abs(pb), 1e-300)),
            "rho_change_max": float(np.max(drho)) if drho.size else math.nan,
            "rho_agreeing_fraction": float(np.mean(drho < 0.01)) if drho.size else math.nan}


def energy_residual(v: dict) -> np.ndarray:
    """Relative residual of the energy identity (2) per realization: ``|H + D - (W - dE)|``
    over ``max(H + D, |W|, |dE|)``."""
    lhs = np.asarray(v["harvested_energy"]) + np.asarray(v["dissipated_energy"])
    w, de = np.asarray(v["base_work"]), np.asarray(v["stored_energy_change"])
    scale = np.maximum(np.maximum(lhs, np.abs(w)), np.abs(de))
    return np.abs(lhs - (w - de)) / np.where(scale > 0, scale, 1.0)
