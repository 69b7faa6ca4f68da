"""The pendulum inside a floating buoy, coupled both ways (docs/buoy.md).

The package is itself callable: ``parapend.buoy(...)`` is :func:`parapend.buoy.api.buoy`
(the command ``parapend buoy``), whichever of its modules was imported first (importing
``parapend.buoy.hydro`` binds the name ``parapend.buoy`` to this package, so the package
answers the call)::

    import parapend
    r = parapend.buoy()                      # the embedded default design
    r.power_w, r.one_way_power_w, r.radiation_bound_w, r.bound_fraction

Modules: :mod:`.hydro` (the body's linear potential-flow coefficients, Capytaine, cache),
:mod:`.timedomain` (Cummins' equation coupled with the pendulum), :mod:`.coupled` and
:mod:`.optimum` (the coupled Fourier kernel and its optimum), :mod:`.api` (the command's
function and its result), :mod:`.design` (power against wave period, the best pendulum),
:mod:`.figures`.
"""

from __future__ import annotations

import importlib
import sys
import types

__all__ = ["BuoyResult", "BuoySweepResult", "DesignResult", "buoy"]

_EXPORTS = {"buoy": ".api", "BuoyResult": ".api", "BuoySweepResult": ".api",
            "DesignResult": ".design"}


def __getattr__(name: str):
    where = _EXPORTS.get(name)
    if where is not None:
        value = getattr(importlib.import_module(where, __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _CallablePackage(types.ModuleType):
    """``parapend.buoy(...)``: the package answers a call with the command's function."""

    def __call__(self, *args, **kwargs):
        from ..commands import buoy

        return buoy(*args, **kwargs)

    @property
    def __signature__(self):
        import inspect

        from ..commands import buoy

        return inspect.signature(buoy)


sys.modules[__name__].__class__ = _CallablePackage
