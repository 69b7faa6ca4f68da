"""Running a sweep: :func:`sweep` (check, connect, lock, prepare, execute, write block by
block) on local worker processes or a Dask cluster, and its outcome :class:`SweepRun`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import os
import sys
import threading
import time

import numpy as np

from ..defaults import GAMMA
from ..errors import OutputError, ParameterError, SolverError, check_int
from ._forkserver import WorkerContext
from .compute import compute_block
from .spec import sweep_spec
from .store import (
    _check_store_path,
    _chunk_key,
    _damage_line,
    _locked,
    _prepare,
    _quiet_zarr,
    _short,
    _store_spec,
    _template,
    _verify,
    check_resumable,
    make_store_dir,
    open_sweep,
    stored_points,
)

__all__ = ["SweepRun", "run_spec", "sweep"]

log = logging.getLogger(__name__)


# -- running -------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class SweepRun:
    """Outcome of :func:`sweep`: the map and what this run did.

    ``dataset`` has one variable per quantity (see :data:`VARIABLES`) over the swept
    dimensions, plus ``done``; ``computed_points`` were computed by this run,
    ``resumed_points`` found finished in the store (``stopped``: a time limit ended the run
    before every block was computed); ``repaired_points`` (of the computed)
    were marked finished in the store but had missing or unreadable data. ``units``: the
    pendulum in SI given to :func:`sweep` (a :class:`parapend.units.Units`, or None; the
    map itself stays non-dimensional); ``netcdf``: the file the map was exported to.
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
    units: object = None
    netcdf: str | None = None
    #: the time limit stopped the run before every block was computed (``done`` says which
    #: were; a block cut mid-way is never marked done)
    stopped: bool = False


def _worker_init(parent: int, workers: int = 1) -> None:
    """A pool worker ignores Ctrl-C (the parent handles it) and exits when the parent is
    gone (``kill -9``: the pool's queues would keep it waiting for ever). Beside other
    workers it runs numba's parallel sections on one thread (unless ``NUMBA_NUM_THREADS``
    says otherwise; numba is not loaded yet): the processes already share the cores, and a
    section whose second thread waits for a busy core waits whole."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if workers > 1:
        os.environ.setdefault("NUMBA_NUM_THREADS", "1")

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
    """The local worker processes (a ``forkserver`` pool of :class:`ParapendWorker`, which
    never run the caller's main script: :mod:`parapend.maps._forkserver`), started in the
    background as soon as the sweep's parameters are checked: the server's imports and the
    workers' start (about a second) then overlap the preparation of the store instead of
    preceding the first block.
    """

    def __init__(self, workers: int, start: bool = True):
        self.workers = workers
        self.executor = None
        self.context = None
        self._boot = None
        self._first: list = []
        if start:
            self.start()

    def start(self):
        """Start the processes in the background (once)."""
        import concurrent.futures as cf
        import threading

        if self.executor is not None:
            return
        ctx = self.context = WorkerContext()
        # the first preload wraps the forkserver's `prepare`: its ParapendWorker children
        # do not import the caller's main script (parapend.maps._forkserver)
        ctx.set_forkserver_preload(["parapend.maps._forkserver", "parapend.maps",
                                    "parapend.api", "parapend.optimal.fourier",
                                    "parapend.optimal.batch"])
        self.executor = cf.ProcessPoolExecutor(max_workers=self.workers, mp_context=ctx,
                                               initializer=_worker_init,
                                               initargs=(os.getpid(), self.workers))
        self._boot = threading.Thread(target=self._submit_first, daemon=True)
        self._boot.start()

    def _submit_first(self):
        # Start every worker here, not in the caller's thread: a submit that finds no idle
        # worker spawns one, and a Ctrl-C (raised in the main thread only) landing inside
        # that spawn left a child that the pool did not know of, so it was neither stopped
        # nor waited for, and it printed a traceback once the parent had gone (its queues'
        # semaphores unlinked). Each submit here spawns a worker until all have started.
        ex = self.executor
        with contextlib.suppress(Exception):
            for _ in range(4 * self.workers):
                self._first.append(ex.submit(_ready))
                if len(getattr(ex, "_processes", None) or ()) >= self.workers:
                    break

    def started(self) -> bool:
        """Whether a worker has run a task (so the workers could start)."""
        return any(f.done() and not f.cancelled() and f.exception() is None
                   for f in self._first)

    def shutdown(self):
        if self.executor is not None:
            self._boot.join()
            self.executor.shutdown(wait=True, cancel_futures=True)


def _forkserver_available() -> bool:
    """Whether this platform has the ``forkserver`` start method (not on Windows)."""
    import multiprocessing as mp

    return "forkserver" in mp.get_all_start_methods()


def worker_death(pool, store: bool) -> str:
    """What ended the pool ``pool`` (shut down, so its processes' exit codes are known), in
    words, for the error of a broken pool; ``store``: whether finished blocks were kept.

    An exit status (a Python error in the worker, printed on stderr) is not a kill: only a
    signal is reported as one, and only then is the run worth repeating as it stands."""
    import signal

    codes = [p.exitcode for p in (pool.context.started if pool.context else ())]
    statuses = sorted({c for c in codes if c is not None and c > 0})
    signals = [-c for c in codes if c is not None and c < 0]
    resume = ("; the finished blocks are in the store: run the same command again to resume"
              if store else "")
    if statuses:
        status = ", ".join(map(str, statuses))
        if not pool.started():
            main = getattr(sys.modules.get("__main__"), "__file__", None)
            guard = (f"; if it is multiprocessing's 'bootstrapping phase' error, the "
                     f"forkserver was started before parapend's (without its preload) and "
                     f"the workers ran {os.path.basename(main)!r} again: put its top-level "
                     f"work under if __name__ == \"__main__\":" if main else "")
            return (f"the worker processes could not start (exit status {status}; their "
                    f"error is printed above{guard})")
        return f"a worker process failed (exit status {status}; its error is printed above)"
    killed = [s for s in signals if s != signal.SIGTERM] or signals
    if killed:
        try:
            name = signal.Signals(killed[0]).name
        except ValueError:
            name = f"signal {killed[0]}"
        why = (" (the system's out-of-memory killer sends it, as does kill -9)"
               if killed[0] == getattr(signal, "SIGKILL", None) else "")
        return f"a worker process was killed by {name}{why}{resume}"
    return "a worker process ended unexpectedly (its error, if any, is printed above)" + resume


def _ready() -> None:
    """A first task: it makes the pool start its processes."""


def _compile_kernels(spec) -> None:
    """Compile, or load from numba's disk cache, the power take-off kernels that the sweep's
    points use, here, before the worker processes start. On a cold cache every worker would
    otherwise compile the same kernels at the same time, with no notice (a two-worker sweep
    took 37 s against 8 s warm); compiled once here, the workers load them from the cache
    and the command line shows its first-use notice once. A tiny solve of each kind: about
    0.1 s each when the cache is warm."""
    from ..pto import optimize_pto

    if spec.values["torque_limit"] and not spec.values["efficiency"]:
        optimize_pto(torque_limit=2.5, gamma=0.03, harmonics=4)
    if spec.values["efficiency"]:
        optimize_pto(efficiency=0.9, gamma=0.03, harmonics=4)


def _run_local(spec, todo, pool, done_cb, store=False, until=None, state=None):
    import concurrent.futures as cf

    from ..deadline import expired

    if pool is None or len(todo) <= 1:
        for i, b in enumerate(todo):
            if i and expired(until):  # the time limit: stop before the next block
                state["stopped"] = True
                break
            done_cb(b, compute_block(spec, b))
        return "serial"
    pool.start()
    pool._boot.join()
    ex = pool.executor
    try:
        try:
            futs = {ex.submit(compute_block, spec, b): b for b in todo}
            pending, written = set(futs), 0
            while pending:
                # with a time limit, wait no longer than it (once a block is written)
                wait = (None if until is None or not written
                        else max(0.0, until - time.monotonic()))
                done, pending = cf.wait(pending, timeout=wait,
                                        return_when=cf.FIRST_COMPLETED)
                for f in done:
                    done_cb(futs[f], f.result())
                    written += 1
                if pending and written and expired(until):
                    # the time limit: the blocks still running are not waited for, nor
                    # written (a block cut mid-way is never marked done)
                    state["stopped"] = True
                    _stop_workers(ex)
                    break
        except cf.process.BrokenProcessPool:
            ex.shutdown(wait=True, cancel_futures=True)  # the exit codes are known after
            raise SolverError(worker_death(pool, store)) from None
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


def _run_dask(spec, todo, client, done_cb, until=None, state=None):
    from distributed import as_completed

    from ..deadline import expired

    futs = {client.submit(compute_block, spec, b, pure=False): b for b in todo}
    left = set(futs)
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
        left.discard(f)
        if left and expired(until):
            # the time limit: the blocks not yet returned are cancelled, never written
            state["stopped"] = True
            client.cancel(list(left))
            break
    return f"Dask cluster at {client.scheduler.address}"


def sweep(store=None, *, omega=1.8, delta=None, gamma=GAMMA["sweep"], torque_limit=None,
          efficiency=None, harmonics: int = 24, excitation=None, square_alpha=None,
          fourier=None, threshold: bool = False, workers: int | None = None, scheduler=None,
          overwrite: bool = False, command: str | None = None, progress=None,
          block_points: int | None = None, netcdf=None, length=None, mass=None, inertia=None,
          gravity=None):
    """A design map: the optimum (and more) at every point of a grid; see the module text.

    The parameters of the command ``sweep``, declared here once: ``parapend.sweep`` takes
    them as they are (and returns the command's result, a
    :class:`~parapend.results.Record` around this :class:`SweepRun`), and the command line
    reads its options' defaults from this signature.

    Parameters
    ----------
    store : path or None
        Zarr store (a directory, e.g. ``map.zarr``) written block by block and resumed when
        it already holds this sweep; None computes in memory (the command line's default
        is ``map.zarr``).
    omega, delta, gamma, torque_limit, efficiency : number, sequence, or str
        One value, a sequence, ``"START:STOP:COUNT"`` or ``"A,B,C"`` (:func:`parse_axis`).
        ``torque_limit`` or ``efficiency`` makes each point :func:`parapend.pto.optimize_pto`;
        with an efficiency ``power`` is the electrical power (the motion maximizes it) and
        ``mechanical_power`` the same motion's mechanical power, as ``parapend.optimize``.
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
        blocks run there, and are written here as they finish (not with ``workers``).
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
    netcdf : path or None
        Also export the finished map to this NetCDF file (atomically).
    length, mass, inertia, gravity : float or None
        A pendulum in SI (m, kg, kg m^2, m/s^2; docs/units.md): the map stays
        non-dimensional (one map serves every pendulum), the run carries the units
        (``units``) and ``parapend.sweep`` adds the largest power in W.

    Returns
    -------
    SweepRun
        (``parapend.sweep``: the command's :class:`~parapend.results.Record` around it; no
        return annotation here, as the command's signature is this one.)
    """
    from ..units import from_options

    units, _ = from_options(length=length, mass=mass, inertia=inertia, gravity=gravity)
    if scheduler is not None and workers is not None:
        raise ParameterError("workers: the processes are the cluster's with --scheduler; "
                             "drop --workers")
    if scheduler is not None:
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise ParameterError("scheduler: needs the 'distributed' package (python -m pip "
                                 "install distributed)") from None
    spec = sweep_spec(omega=omega, delta=delta, gamma=gamma, torque_limit=torque_limit,
                      efficiency=efficiency, harmonics=harmonics, excitation=excitation,
                      square_alpha=square_alpha, fourier=fourier, threshold=threshold,
                      block_points=block_points)
    seconds = estimate_seconds(spec) / (1 if scheduler is not None else max(
        1, min(workers or os.cpu_count() or 1, spec.blocks)))
    check_resumable(spec, store, overwrite)  # before the announcement
    stored = stored_points(spec, store, overwrite) if seconds > 60 else 0
    seconds *= (spec.points - stored) / spec.points
    if seconds > 60:  # announced on stderr by the command line, a terminal or not
        from ..deadline import duration

        log.info("sweep: %d points%s: roughly %s (the store resumes an interrupted run)",
                 spec.points, f" ({stored} of them in the store)" if stored else "",
                 duration(seconds))
    run = run_spec(spec, store, workers=workers, scheduler=scheduler, overwrite=overwrite,
                   command=command, progress=progress)
    if netcdf:
        from .. import fileio

        fileio.write_dataset(run.dataset, netcdf)
    return dataclasses.replace(run, units=units, netcdf=netcdf)


#: seconds of one point of a map at N = 24 (its cost grows as N^3), a torque-limited or lossy
#: point's, and gamma*'s at a point (measured on the shared cores: 2 ms, 7 s, 0.2 s)
POINT_SECONDS, PTO_POINT_SECONDS, THRESHOLD_SECONDS = 2e-3, 7.0, 0.25


def estimate_seconds(spec) -> float:
    """A rough single-process duration (s) of the sweep ``spec``, before any resume."""
    per = PTO_POINT_SECONDS if spec.pto else POINT_SECONDS * (spec.harmonics / 24) ** 3
    return spec.points * (per + (THRESHOLD_SECONDS if spec.threshold else 0.0))


def run_spec(spec, store=None, *, workers: int | None = None, scheduler=None,
             overwrite: bool = False, command: str | None = None,
             progress=None, deadline=None) -> SweepRun:
    """Run a checked spec (a :class:`SweepSpec`, or another product's spec with the same
    layout, e.g. :class:`parapend.performance.spec.MatrixSpec`) on the engine: store,
    resume, local processes or Dask; the parameters are :func:`sweep`'s. ``deadline`` (a
    ``time.monotonic`` time, :func:`parapend.deadline.deadline`): once it has passed no
    further block is started or waited for (after at least one), and the run says
    ``stopped``."""
    if workers is not None:
        # never more processes than blocks (--workers 256 started 57 processes for 4 bins)
        workers = min(check_int("workers", workers, 1, 256), max(1, spec.blocks))
    else:
        workers = max(1, min(os.cpu_count() or 1, spec.blocks))
    t0 = time.monotonic()
    client, own = _connect(scheduler) if scheduler is not None else (None, False)
    # the pool starts at once unless the store holds this sweep already (a resume, where
    # there may be nothing left to do): then only when blocks are left
    resume = (store is not None and not overwrite
              and _store_spec(_check_store_path(store)) == spec.to_json())
    local = client is None and workers > 1 and spec.blocks > 1
    if local and not _forkserver_available():
        log.info("no forkserver start method on this platform: the blocks run in this "
                 "process")
        local = False
    if local and spec.pto and not resume:
        _compile_kernels(spec)
    pool = _LocalPool(workers, start=not resume) if local else None
    try:
        return _sweep(spec, store, pool, client, overwrite, command, progress, t0, deadline)
    finally:
        if pool is not None:
            pool.shutdown()
        if own:
            _close(client)


def _sweep(spec, store, pool, client, overwrite, command, progress, t0,
           until=None) -> SweepRun:
    total = spec.points
    state = {"stopped": False}
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

        how = _execute(spec, _ordered(spec, range(spec.blocks)), pool, client, write,
                       until=until, state=state)
        for k, v in arrays.items():
            ds[k] = (spec.dims, v, ds[k].attrs)
        return SweepRun(ds, None, total, spec.blocks, counted[0], 0, time.monotonic() - t0,
                        how, stopped=state["stopped"])
    path = _check_store_path(store)
    make_store_dir(path)
    try:
        return _sweep_store(spec, path, pool, client, overwrite, command, progress, t0,
                            sizes, until, state)
    except OSError as exc:  # a full disk, a store made read-only, ...
        raise OutputError(f"cannot write {str(path)!r}: {_short_os(exc)}; the finished blocks "
                          "are in the store: run the same command again to resume") from None


def _ordered(spec, blocks) -> list:
    """``blocks`` in the spec's ``block_order`` (a product whose blocks differ in cost hands
    out the dear ones first), else as given."""
    blocks = list(blocks)
    order = getattr(spec, "block_order", None)
    if order is None:
        return blocks
    rank = {b: k for k, b in enumerate(order())}
    return sorted(blocks, key=rank.__getitem__)


def _short_os(exc: OSError) -> str:
    return " ".join(str(exc.strerror or exc).split())[:160]


def _sweep_store(spec, path, pool, client, overwrite, command, progress, t0, sizes,
                 until=None, state=None):
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
        todo = _ordered(spec, [b for b in range(spec.blocks) if not done[b]])
        repaired = sum(sizes[b] for b in damaged)
        resumed = total - sum(sizes[b] for b in todo)
        counted = [resumed]
        if progress is not None:
            progress(resumed, total)

        def write(b, vals):
            sl = spec.block_slices(b)
            for k in spec.variables:  # the data first, then the mask
                arrays[k][sl] = vals[k]
            # a product may leave points unfinished (a power matrix: a realization whose
            # solve raised), so that a resume computes their block again
            finished = getattr(spec, "finished", None)
            mask[sl] = (np.ones(vals["status"].shape, dtype=bool) if finished is None
                        else finished(vals))
            counted[0] += sizes[b]
            if progress is not None:
                progress(counted[0], total)

        how = (_execute(spec, todo, pool, client, write, store=True, until=until,
                        state=state) if todo else "nothing to do")
    ds = open_sweep(path)
    return SweepRun(ds, str(path), total, spec.blocks, counted[0] - resumed, resumed,
                    time.monotonic() - t0, how, repaired,
                    stopped=bool(state and state["stopped"]))


def _execute(spec, todo, pool, client, write, store=False, until=None, state=None) -> str:
    if client is not None:
        return _run_dask(spec, todo, client, write, until, state)
    return _run_local(spec, todo, pool, write, store, until, state)
