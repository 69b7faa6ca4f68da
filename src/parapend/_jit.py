"""Notice of a first-use compile of the numba kernels.

The compiled kernels (:mod:`parapend.optimal._hermite_kernel`, the interior point of
:mod:`parapend.optimal.collocation` and :mod:`parapend.dynamics._kernel`) are compiled by
numba the first time they run and cached on disk (``cache=True``, beside the sources or under
``NUMBA_CACHE_DIR``); later runs load them from the cache in a fraction of a second. The
compile itself takes seconds, inside LLVM, with nothing to show for it.

:func:`announce_compiles` registers, once per process, a listener on numba's
``"numba:compile"`` event. Numba fires that event only when it is about to compile: after
its disk cache missed for the signature (source changed, new signature, other processor or
numba version, or no cache yet), never on a cache hit. For the first such compile of each
kernel module in a process, the listener logs one ``INFO`` record on this module's logger
(``parapend._jit``) saying what is compiled and about how long it takes. The library only
logs; the command line prints these records on stderr (:mod:`parapend.cli._notice`). A
Python user sees them with ``logging.basicConfig(level=logging.INFO)``.
"""

from __future__ import annotations

import logging
import threading

__all__ = ["KERNELS", "announce_compiles"]

log = logging.getLogger(__name__)

#: what each kernel module is, and about how long its cold compile takes, in seconds: a CLI
#: run with an empty cache less the same run with a full one, numba 0.68 on two shared cores
#: at load 2 to 3 (Hermite 7 s, collocation 7 to 10 s, basin kernel 9 s; 12 s and more under
#: heavier load); rounded up, as a user would rather wait less than announced
KERNELS = {
    "parapend.optimal._hermite_kernel": ("the torque-limited solver's kernels", 10),
    "parapend.optimal.collocation": ("the efficiency solver's kernels", 10),
    "parapend.dynamics._kernel": ("the basin-map kernel", 15),
    "parapend.control._mpc_kernel": ("the receding-horizon controller's kernels", 10),
    # (the horizon solver: 27 s cold at load 5 to 6, of which 16.5 s its one large function)
    "parapend.control._plan_kernel": ("the receding-horizon controller's horizon solver", 20),
    "parapend.hydro._hull_kernel": ("the hull problem's kernels", 10),
    "parapend.hydro._buoy_plan_kernel": ("the buoy's motion planner", 60),
    "parapend.hydro._hull_collocation_kernel": ("the hull's collocation planner", 20),
    "parapend.hydro._hull_collocation_linalg": ("the hull's collocation planner's solves", 20),
    "parapend.hydro._hull_collocation_ldl": ("the hull's collocation planner's factors", 20),
}

_lock = threading.Lock()
_installed = False
_announced: set[str] = set()


def _module_of(data) -> str:
    disp = data.get("dispatcher") if isinstance(data, dict) else None
    return str(getattr(getattr(disp, "py_func", None), "__module__", "") or "")


def _on_compile(module: str) -> None:
    """Log the first compile of ``module`` in this process (nothing for other packages)."""
    if not module.startswith("parapend."):
        return
    with _lock:
        if module in _announced:
            return
        _announced.add(module)
    what, seconds = KERNELS.get(module, (f"the kernels of {module}", 10))
    log.info("compiling %s (first use only, about %d s)", what, seconds,
             extra={"kernel_module": module, "compile_seconds": seconds})


def announce_compiles() -> None:
    """Register (once per process) the listener that logs a compile of parapend's kernels.

    Called by each kernel module when it is imported; cheap and idempotent. Records go to the
    ``parapend._jit`` logger at ``INFO``, at most one per kernel module and process.
    """
    global _installed
    with _lock:
        if _installed:
            return
        _installed = True
    from numba.core import event

    class _Listener(event.Listener):
        def on_start(self, ev):
            _on_compile(_module_of(ev.data))

        def on_end(self, ev):
            pass

    event.register("numba:compile", _Listener())
