"""Worker processes that never run the caller's main script: the engine's local pool.

``multiprocessing`` starts a ``spawn`` or ``forkserver`` child by executing the parent's
main script again (as ``__mp_main__``), so that functions defined there can be unpickled.
A script that calls :func:`parapend.sweep` or :func:`parapend.power_matrix` at its top
level, without ``if __name__ == "__main__":``, would then call it again in every worker,
which stops with multiprocessing's "bootstrapping phase" error; a guarded script still runs
its imports and definitions once per worker. The engine's workers need nothing from the
main script (a block's task is :func:`parapend.maps.compute.compute_block` on a spec of plain
data), so they skip it:

- the pool's processes are :class:`ParapendWorker` (their names start ``ParapendWorker-``),
  made by :class:`WorkerContext`, a ``forkserver`` context that also remembers them (their
  exit codes name the cause when one dies);
- the forkserver imports this module as a preload; there, and only there (:func:`_install`
  checks that it is called from ``multiprocessing.forkserver.main``), it wraps
  ``multiprocessing.spawn.prepare`` so that a child whose name starts ``ParapendWorker-``
  does not import the main module. Every other child of that server (a user's own pool on
  the same forkserver) is prepared as before.

``forkserver`` is used on Linux and macOS alike (never ``fork``, unsafe with the threads of
BLAS and macOS's frameworks). Where the forkserver was started before parapend's first
pool (by the caller's own ``forkserver`` pool), the wrapper is absent and the workers import
the main script as multiprocessing always does: a guarded script works, an unguarded one
gets the error that says so (:func:`parapend.maps.run.worker_death`).
"""

from __future__ import annotations

import sys
from multiprocessing import context

#: the start of the name of every worker process of the engine's local pool
WORKER_NAME = "ParapendWorker-"
#: the warning filter the resource tracker is started with: after the main process is
#: killed (``kill -9``) the tracker frees the pool's semaphores itself, and its "leaked
#: semaphore objects" warning was a line of noise after the kill's own report
QUIET_TRACKER = "ignore:resource_tracker:UserWarning"


def quiet_resource_tracker() -> None:
    """Start multiprocessing's resource tracker (where it is not running yet) with
    :data:`QUIET_TRACKER`: a child process gets the parent's ``sys.warnoptions`` as ``-W``
    options (``multiprocessing.util._args_from_interpreter_flags``)."""
    if QUIET_TRACKER not in sys.warnoptions:
        sys.warnoptions.append(QUIET_TRACKER)


class ParapendWorker(context.ForkServerProcess):
    """A worker of the engine's local pool: a ``forkserver`` process whose name, which the
    forkserver's children receive first, tells the forkserver's ``prepare`` to leave the
    main module alone."""


class WorkerContext(context.ForkServerContext):
    """A ``forkserver`` context whose processes are :class:`ParapendWorker`; ``started``
    lists them in order (their ``exitcode`` after the pool has shut down)."""

    def __init__(self):
        quiet_resource_tracker()
        self.started: list[ParapendWorker] = []

    def Process(self, *args, **kwargs):  # noqa: N802 - multiprocessing's name
        proc = ParapendWorker(*args, **kwargs)
        self.started.append(proc)
        return proc


def _prepare_without_main(prepare):
    """``prepare`` that, for a parapend worker, drops the request to import the main
    module."""

    def wrapped(data):
        if str(data.get("name", "")).startswith(WORKER_NAME):
            data = {k: v for k, v in data.items()
                    if k not in ("init_main_from_path", "init_main_from_name")}
        return prepare(data)

    wrapped.parapend_workers = True
    return wrapped


def _install() -> bool:
    """Wrap ``multiprocessing.spawn.prepare`` in this process if it is a forkserver (this
    module imported as its preload); True if it is wrapped."""
    from multiprocessing import forkserver, spawn

    frame = sys._getframe(1)
    while frame is not None and frame.f_code is not forkserver.main.__code__:
        frame = frame.f_back
    if frame is None:  # not the forkserver: change nothing
        return False
    if not getattr(spawn.prepare, "parapend_workers", False):
        spawn.prepare = _prepare_without_main(spawn.prepare)
    return True


_install()
