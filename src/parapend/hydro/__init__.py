"""The floating body: the pendulum inside a buoy, coupled both ways (docs/buoy.md).

The command is the plain function ``parapend.buoy`` (:func:`parapend.commands.buoy`, which
calls :func:`parapend.hydro.api.buoy`); this subpackage holds what answers it::

    import parapend
    r = parapend.buoy()                      # the embedded default design
    r.power_w, r.one_way_power_w, r.radiation_bound_w, r.bound_fraction

Modules: :mod:`.bem` (the body's linear potential-flow coefficients: BEM through Capytaine,
the cache, datasets), :mod:`.timedomain` (Cummins' equation coupled with the pendulum),
:mod:`.coupled` and :mod:`.optimum` (the coupled Fourier kernel and its optimum), :mod:`.pto`
(the electrical optimum, the torque limit), :mod:`.result` (the results and one wave's
answer), :mod:`.api` (the command's function: input, body, wave), :mod:`.design` (power
against wave period, the best pendulum), :mod:`.control` (receding-horizon control),
:mod:`.horizon` (its curve against the horizon, ``parapend horizon --device buoy``),
:mod:`.figures`.
"""

from __future__ import annotations

import importlib

__all__ = ["BuoyResult", "BuoySweepResult", "DesignResult"]

_EXPORTS = {"BuoyResult": ".result", "BuoySweepResult": ".result", "DesignResult": ".design"}


def __getattr__(name: str):
    where = _EXPORTS.get(name)
    if where is not None:
        value = getattr(importlib.import_module(where, __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
