"""What a power matrix is asked, checked before any bin runs: every bin's record and
resolution (:func:`check_bins`), and the size of the whole (:func:`check_size`: bins,
solves, memory and worker processes), each refused in one line naming the option.

A bin whose inputs ``parapend sea`` (or ``parapend buoy``) would refuse used to be solved
anyway: every realization failed with a warning, the matrix came back empty with exit 0,
and a store marked those bins finished for good. Here the record of every bin is built (a
millisecond each) and checked as the solver checks it, before the first solve.
"""

from __future__ import annotations

import math
import os

from ..errors import ParameterError, check_range

__all__ = ["MAX_BINS", "MAX_SOLVES", "MIN_EFFICIENCY", "WORKER_BYTES", "check_bins",
           "check_efficiency", "check_size", "memory_available", "workers_for"]

#: most bins of one matrix (Hm0 x period): the store holds a chunk per bin and variable, and
#: the engine a task per bin (10 000 bins: about 0.3 GB and 10 s of bookkeeping)
MAX_BINS = 10_000
#: most solves (bins x realizations) of one matrix: a solve of a 50-wave record takes
#: seconds, so a million of them is days of a large cluster
MAX_SOLVES = 1_000_000
#: bookkeeping per bin (the engine's task and the lazy store's chunks: measured 12 kB)
_BIN_BYTES = 16 << 10
#: per solve (realization): the stored quantities, their statistics and the report
_SOLVE_BYTES = 128
#: memory of one worker process: Python, NumPy, SciPy and numba's kernels loaded (about
#: 200 MB measured) and one solve's arrays
WORKER_BYTES = 300 << 20


#: CPU seconds of one hull record of 9 waves (--dofs surge,heave,pitch; the default barge)
HULL_SOLVE_SECONDS = 100.0


#: the lowest power take-off efficiency a matrix takes: below it the motoring power p / eta
#: of a record overflows (a subnormal eta gave NaN bins); 1e-6 is far below any machine
MIN_EFFICIENCY = 1e-6


def check_efficiency(value) -> float:
    """A power take-off efficiency in ``[MIN_EFFICIENCY, 1]`` (one line naming it)."""
    return check_range("efficiency", value, MIN_EFFICIENCY, 1.0,
                       why="fraction of the power converted")


def _where(spec, i: int, j: int, r: int | None = None) -> str:
    pk = spec.period_kind
    return (f"the bin Hm0 {spec.hm0[i]:g} m, {pk} {spec.period[j]:g} s"
            + ("" if r is None else f" (realization {r}, seed {int(spec.seeds[r])})"))


#: CPU seconds of one causal run over a 50-wave record (and the 4-period warm-up) with each
#: forecast at the defaults, measured on the shared 2-core machine (one BLAS thread; 6.5 to
#: 7.1 s perfect at Hs 1 to 3 m, 9.9 s AR at Hs 2 m, Tp 8 s), rounded up; a run's cost
#: grows as its length
CAUSAL_SECONDS = {"perfect": 7.5, "ar": 10.5}


#: ``--device buoy``: CPU seconds of the buoy's causal run per peak period of run (warm-up
#: and record) at a horizon of 1 peak period and a plan every 1/8, per controller, rounded
#: up from the measurements of :data:`parapend.performance.causal.BUOY_CONTROLLER` (10-wave
#: records of the default buoy, the shared 2-core machine: plan 0.21 s; coupled 1.38 s at
#: Hs 0.5 m, Tp 2.5 s, 1.6 and 1.9 s at Hs 1 m, Tp 2.5 and 3 s; at a horizon of 2, 0.32 and
#: 3.06 s at Hs 0.5 m): taken as the horizon (at least half a peak period) over the update
#: interval, per forecast (the AR forecast's run cost the perfect one's: 23.3 s against 20.9
#: and 25.0 s of CPU, ``parapend buoy --hs 1 --tp 3 --repeat-period 30 --controller mpc``);
#: the hull's (``hull``, :func:`parapend.hydro.hull_control.hull_mpc`): its runs of the
#: embedded barge's default sea (benchmarks/hull_mpc_table.out.txt, 8 peak periods at a
#: horizon of 2, load 5 to 8) took 7 to 100 s (perfect) and 19 to 138 s (AR): 0.4 to 8.6 s
#: a peak period per unit of horizon; with the collocation planner (``hull-collocation``,
#: the default, its compiled solver) a 20-minute record of the default sea (204 peak
#: periods, horizon 2, perfect forecast) took 500 s of CPU at a load of 6 (the record's
#: optimum aside): 1.2 s; a bin of the 4 x 4 causal matrix of 200-peak-period records (Hs
#: 0.5 m, Te 5 s: the record's optimum and both forecasts' runs, one process of two on an
#: otherwise idle machine, one thread) took 14 min: 0.94 s; the whole matrix's bins took
#: about 15 minutes each at Hs 0.5 m and 20 to 25 at Hs 1 to 2 m (one process of two, the
#: machine shared): 1.3 s at the higher seas, priced 1.4
BUOY_CAUSAL_SECONDS = {"plan": 0.25, "coupled": 2.0, "hull": 4.5, "hull-collocation": 1.4}


def hull_record_seconds(waves: float, ideal: bool = True, kink: bool = False) -> float:
    """A rough CPU time (s) of one hull record of ``waves`` peak periods (its modes and
    their refinement: the rotation both ways and swinging, and on a short record the
    rotation's other turns, 17 to 24 s on the default sea's 4-peak-period records, seeds 0
    to 9, against the estimate's 44): the dense solver's
    :data:`parapend.performance.check.HULL_SOLVE_SECONDS` per 9 waves; an ideal take-off's
    records past ``hull.KRYLOV_HARMONICS`` solved matrix-free, near-linear in the length
    (benchmarks/bench_hull_record.out.txt, two runs on the shared 2-core machine at load 5
    to 6, CPU seconds: 8.2 to 8.6 at 10 waves, 16 to 18 at 25, 26 at 50, 33 at 100, 59 to
    63 at 200; a 2 x 2 matrix of 200-wave records, 72 s a record with one bin's retry on
    1.5 times the harmonics; taken as 15 s and 0.3 s a wave, above every one of them); a
    record of ``WINDING_SEARCH_WAVES`` or more also has its windings searched, priced
    :data:`SEARCH_FACTOR` times that (measured with the swinging first and the rest
    screened on every level, load 2 to 3 on the 2-core machine: 234-wave records 85 and 138
    s of CPU against the two modes' 56 and 67 s; the 200-wave bench record 51 s against 50
    to 63, the 25-wave one 38.5 s against 14 to 22; a 6 x 6 matrix of 200- to 217-wave
    records 109 s a record). ``kink``: an efficiency's record, whose smoothing's continuation
    climbs every mode from several starts and again on each doubling of the harmonics:
    :data:`EFFICIENCY_SECONDS` a peak period."""
    from ..hydro.hull import HARMONICS_PER_TURN, KRYLOV_HARMONICS
    from ..hydro.result import WINDING_SEARCH_WAVES

    waves = max(float(waves), 1.0)
    if kink:
        return EFFICIENCY_SECONDS * waves
    factor = SEARCH_FACTOR if waves >= WINDING_SEARCH_WAVES else 1.0
    if ideal and HARMONICS_PER_TURN * waves >= KRYLOV_HARMONICS:
        return (15.0 + 0.3 * waves) * factor
    return HULL_SOLVE_SECONDS * waves / 9.0 * factor


#: CPU seconds a peak period of an efficiency's hull record (:func:`hull_record_seconds`):
#: the default sea's 4-peak-period record at efficiency 0.9 (seed 0) took 525 s of CPU on
#: the idle 2-core machine, its three modes each refined from 60 to 240 harmonics (rounded
#: up: other seas refine as far, and a record's modes are as many)
EFFICIENCY_SECONDS = 150.0

#: a searched record's CPU time over its two modes' (:func:`hull_record_seconds`)
SEARCH_FACTOR = 1.75


def record_seconds(spec) -> float:
    """A rough CPU time (s) of the causal runs of one record of ``spec``
    (:data:`CAUSAL_SECONDS`, as the run's length; the buoy's :data:`BUOY_CAUSAL_SECONDS`);
    0 without a controller."""
    if getattr(spec, "controller", None) is None:
        return 0.0
    if spec.device == "buoy":
        return (BUOY_CAUSAL_SECONDS[spec.buoy_controller] * (spec.waves + spec.warm_up)
                * max(spec.horizon, 0.5) * (0.125 / spec.update_interval)
                * len(spec.forecasts))
    # the measured runs: 50 waves + 4 warm-up; the longest record's
    scale = (max(map(spec.record_waves, range(len(spec.tp)))) + spec.warm_up) / 54.0
    return sum(CAUSAL_SECONDS[f] for f in spec.forecasts) * scale


def _units(spec):
    """The pendulum's units (the buoy's at g = 9.81, as its spec holds)."""
    from ..units import Units

    return Units(spec.length, spec.mass, 9.81 if spec.device == "buoy" else spec.gravity,
                 spec.inertia)


def _record(spec, units, i: int, j: int, r: int):
    """The excitation of bin ``(i, j)``, realization ``r``, as ``sea`` builds it; its
    ParameterError reworded to name the bin and the options that set it."""
    from ..seas import sea_record, steepness_unchecked
    tp = spec.tp[j]
    response = (None if spec.response is None else tuple(spec.response))
    try:
        with steepness_unchecked():  # a rectangle of bins: corners no sea reaches
            return sea_record(units, hs=spec.hm0[i], tp=tp, spectrum=spec.spectrum,
                              gamma_peak=spec.gamma_peak,
                              repeat_period=spec.repeat_period(j),
                              seed=int(spec.seeds[r]), cutoff=spec.cutoff, response=response)
    except ParameterError as err:
        head, _, rest = str(err).partition(": ")
        if head == "sea":  # the record's q: set by hs, the cutoff and gravity
            head = "hs, cutoff, gravity" if spec.device != "buoy" else "hs, cutoff"
        raise ParameterError(f"{head}: {_where(spec, i, j, r)}: {rest}") from None


def check_bins(spec) -> None:
    """Every bin's record (each realization) and resolution, as the solver checks them;
    raises :class:`~parapend.errors.ParameterError` naming the option and the bin.

    A record scales with Hm0 (q is proportional to it), and the record's other checks do
    not depend on it: so the smallest and the largest Hm0 bin of each period bin stand for
    the rest (the smallest harmonic's floor, the cap on ``max |q(t)|``). The realizations
    differ only in their phases: the same amplitudes, so only the cap can differ, and it is
    checked on each of them only where the bound ``2 sum |q_k|`` (any phases) exceeds it."""
    from .. import limits
    from ..irregular import AUTO_FRACTIONS, HARMONICS_PER_WAVE

    units = _units(spec)
    cap = limits.MAX_AMPLITUDE * (1.0 + 1e-12)
    top = len(spec.hm0) - 1
    for j in range(len(spec.period)):
        for i in sorted({0, top}):
            exc = _record(spec, units, i, j, 0)
            if (i == top and spec.realizations > 1
                    and 2.0 * float(abs(exc.spectrum[1:]).sum()) > cap):
                for r in range(1, spec.realizations):
                    _record(spec, units, i, j, r)
            if spec.device == "buoy" or i:
                continue
            # the resolution (seed- and Hs-independent): sea's rule
            km = max(1, int(round(exc.mean_frequency_harmonic)))
            if isinstance(spec.winding, str):
                ks = sorted({1} | {max(1, int(round(f * km))) for f in AUTO_FRACTIONS})
            else:
                ks = [int(spec.winding)]
            n = (spec.harmonics if spec.harmonics is not None
                 else min(HARMONICS_PER_WAVE * max(km, max(ks)),
                          limits.SEA_MAX_HARMONICS // 2))
            if n < 2 * max(ks):
                raise ParameterError(
                    f"harmonics: expected at least 2 K = {2 * max(ks)} (K = {max(ks)} turns "
                    f"per record{', winding auto' if isinstance(spec.winding, str) else ''}) "
                    f"for {_where(spec, i, j)}, got {n}")


def memory_available() -> int | None:
    """Bytes of memory available to new work (``MemAvailable`` of /proc/meminfo), or None
    where it cannot be read."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def workers_for(spec, workers) -> int:
    """The local processes a matrix starts: ``min(workers, bins)`` (default: the CPUs)."""
    if workers is None:
        workers = os.cpu_count() or 1
    return max(1, min(int(workers), spec.blocks))


#: memory of one worker process solving a hull record with an efficiency: its problems are
#: dense up to the refinement's 256 harmonics (the default sea's 4-peak-period record, refined
#: to 240: 1.97 GB peak RSS)
HULL_DENSE_WORKER_BYTES = 2560 << 20


def _kink(spec) -> bool:
    """The hull with an efficiency below 1 (its kink: dense problems, the smoothing's
    continuation); a copper loss alone is smooth."""
    eta = getattr(spec, "efficiency", None)
    return getattr(spec, "dofs", "heave") != "heave" and eta is not None and float(eta) != 1.0


def worker_bytes(spec) -> int:
    """The memory of one worker process of ``spec``: :data:`WORKER_BYTES`, or
    :data:`HULL_DENSE_WORKER_BYTES` for the hull with an efficiency."""
    return HULL_DENSE_WORKER_BYTES if _kink(spec) else WORKER_BYTES


def check_size(spec, workers=None, scheduler=None, available=None) -> dict:
    """The size of the matrix before anything is allocated or started: refuses in one line
    (naming the option and the largest value that fits) more than :data:`MAX_BINS` bins,
    more than :data:`MAX_SOLVES` solves, or what needs more memory than is available
    (``available`` bytes; default :func:`memory_available`). Returns the estimate, with
    ``processes`` the local processes to start: ``min(workers, bins)``, and by default
    (``workers`` None) at most as many as the memory holds."""
    nh, npk, r = len(spec.hm0), len(spec.period), spec.realizations
    pk = spec.period_kind
    bins = nh * npk
    if bins > MAX_BINS:
        big, small, nb, ns = (("hs", pk, nh, npk) if nh >= npk else (pk, "hs", npk, nh))
        raise ParameterError(
            f"{big}: at most {MAX_BINS} bins in all, got {nh} Hm0 x {npk} {pk} = {bins}; "
            f"with {ns} {small} bins, --{big} may have at most {MAX_BINS // ns} bins")
    solves = bins * r
    # the causal column (--controller mpc): each record's runs counted as the solves of a
    # 50-wave record their time would buy (3 s each), so the cap bounds the work
    causal = record_seconds(spec)
    if causal and solves * (1.0 + causal / 3.0) > MAX_SOLVES:
        per = 1.0 + causal / 3.0
        raise ParameterError(
            f"realizations: at most {MAX_SOLVES} solves' work in all, and each record's "
            f"causal runs count as {per:.3g} solves: {bins} bins x {r} realizations is "
            f"{solves * per:.4g}; with {bins} bins, --realizations may be at most "
            f"{max(0, int(MAX_SOLVES // (bins * per)))} (or fewer forecasts)")
    if solves > MAX_SOLVES:
        raise ParameterError(
            f"realizations: at most {MAX_SOLVES} solves (bins x realizations) in all, got "
            f"{bins} bins x {r} = {solves}; with {bins} bins, --realizations may be at "
            f"most {MAX_SOLVES // bins}")
    procs = 0 if scheduler is not None else workers_for(spec, workers)
    base = bins * _BIN_BYTES + solves * _SOLVE_BYTES
    have = memory_available() if available is None else available
    each = worker_bytes(spec)
    fit = None if have is None else max(0, (have - base) // each)
    if workers is None and fit is not None and procs > max(1, fit):
        procs = max(1, int(fit))  # the default: as many processes as the memory holds
    need = base + procs * each
    if have is not None and need > have:
        if fit >= 1 and procs > fit:
            raise ParameterError(
                f"workers: {procs} processes need about {procs * each / 2**30:.3g} GB "
                f"({each >> 20} MB each), {have / 2**30:.3g} GB is available; "
                f"--workers may be at most {fit}")
        raise ParameterError(
            f"hs, {pk}, realizations: the matrix needs about {need / 2**30:.3g} GB, "
            f"{have / 2**30:.3g} GB is available; give fewer bins or realizations")
    # a rough time: a 50-wave record solves in about 3 s on one core, a 400-wave one in
    # about 9 s (measured on the shared 2-core machine): as the square root of the length
    seconds = (solves * (3.0 * math.sqrt(max(1.0, spec.waves / 50.0)) + causal)
               / max(1, procs or 1))
    if getattr(spec, "dofs", "heave") != "heave":
        # the hull: a record's time (both modes and their refinement; dense, or matrix-free
        # for an ideal take-off's long records): parapend.hydro.realizations.record_seconds
        ideal = (getattr(spec, "torque_limit", None) is None and not spec.lossy)
        longest = max(map(spec.record_waves, range(len(spec.tp))))
        seconds = (solves * (hull_record_seconds(longest, ideal, _kink(spec)) + causal)
                   / max(1, procs or 1))
    return {"bins": bins, "solves": solves, "processes": procs, "memory_bytes": need,
            "seconds": seconds if math.isfinite(seconds) else None,
            "causal_seconds": causal}
