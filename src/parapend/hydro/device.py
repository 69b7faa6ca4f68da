"""Inputs that compose: a sea, a pendulum, a body, a power take-off and a controller, small
frozen objects built once and handed to every question asked of the floating body.

Each parameter is declared once, as a field of one of these objects with its unit, default,
bounds and help (:mod:`parapend.hydro.declared`, :func:`declaration`); its name is the
keyword of :func:`parapend.buoy` and the command line's flag (dashes for underscores). The
commands take the objects (``parapend.buoy(sea=..., device=...)``, ``parapend.horizon``,
``parapend.power_matrix``). A field left None takes the command's default (the embedded
buoy's or hull's design, ``parapend.defaults``), and the command checks it, so a value is
refused in the same one line whichever way it came::

    from parapend.hydro.device import Body, Device, Pendulum, PowerTakeOff, Sea

    sea = Sea.state(hs=1.0, tp=6.0, repeat_period=24.0, seed=0)
    device = Device(Body.barge(), Pendulum(mass=2000.0, length=1.0), PowerTakeOff())
    best = device.optimum(sea)                      # the coupled non-causal optimum
    run = device.with_dofs("heave").causal(sea)     # heave alone: its causal controller
    matrix = device.power_matrix(hs="0.5,1", tp="5,6", realizations=1, waves=4)

The functions below (:func:`optimum`, :func:`causal`, :func:`horizon`,
:func:`power_matrix`) hand the objects to the command's function;
``RUN_OPTIONS`` names the options of ``buoy``, ``horizon`` and ``power-matrix`` that are
not properties of the device or the sea but of the run (its resolution, its limits, its
outputs).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from .declared import (
    PRESCRIBED_OPTIONS,
    RUN_OPTIONS,
    Body,
    Controller,
    Pendulum,
    PowerTakeOff,
    Sea,
    declaration,
    declarations,
    option_help,
)
from .declared import DeviceInputs as _DeviceInputs

__all__ = ["Body", "Controller", "Device", "PRESCRIBED_OPTIONS", "Pendulum", "PowerTakeOff",
           "RUN_OPTIONS", "Sea",
           "causal", "declaration", "declarations", "horizon", "option_help", "optimum",
           "power_matrix"]


def optimum(sea: Sea, pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
            **run):
    """The coupled non-causal optimum (:func:`parapend.buoy`) of the device in ``sea``;
    ``run``: ``RUN_OPTIONS`` of ``buoy`` (``winding``, ``harmonics``, ...)."""
    from .api import buoy

    return buoy(sea=sea, pendulum=pendulum, body=body, pto=pto, **run)


def causal(sea: Sea, pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
           controller: Controller | None = None, **run):
    """A causal run (:func:`parapend.buoy` with ``controller``; default the receding-horizon
    controller planned on the coupled model) of the device in ``sea``. A hull has no causal
    controller yet: refused in one line; its heave-only model runs
    (``body.with_dofs("heave")``)."""
    from .api import buoy

    return buoy(sea=sea, pendulum=pendulum, body=body, pto=pto,
                controller=controller or Controller.receding_horizon(), **run)


def horizon(sea: Sea, pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
            controller: Controller | None = None, **run):
    """The causal power against the forecast horizon (:func:`parapend.horizon`,
    ``device="buoy"``): the curve sweeps the horizons and forecasts (``run``: ``horizons``,
    ``forecasts``, ``planner``, ...); of ``controller`` it takes the update interval."""
    from ..control.horizon import horizon_curve

    return horizon_curve(device="buoy", sea=sea, pendulum=pendulum, body=body, pto=pto,
                         controller=controller, **run)


def power_matrix(pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
                 controller: Controller | None = None, **run):
    """The device's power matrix (:func:`parapend.power_matrix`, ``device="buoy"``: its
    :class:`~parapend.results.Record`) over the bins of ``run`` (``hs``, ``tp`` or ``te``,
    ``realizations``, ``waves``, ...)."""
    from .. import commands

    return commands.power_matrix(device="buoy", pendulum=pendulum, body=body, pto=pto,
                                 controller=controller, **run)


@dataclass(frozen=True)
class Device(_DeviceInputs):
    """A pendulum in a floating body through a power take-off, built once: its optimum, a
    causal run, the horizon curve and the power matrix in any sea."""

    def with_dofs(self, dofs) -> Device:
        """The same device with the body's other degrees of freedom (``"heave"``)."""
        return dataclasses.replace(self, body=self.body.with_dofs(dofs))

    def optimum(self, sea: Sea, **run):
        return optimum(sea, self.pendulum, self.body, self.pto, **run)

    def causal(self, sea: Sea, controller: Controller | None = None, **run):
        return causal(sea, self.pendulum, self.body, self.pto, controller, **run)

    def horizon(self, sea: Sea, controller: Controller | None = None, **run):
        return horizon(sea, self.pendulum, self.body, self.pto, controller, **run)

    def power_matrix(self, controller: Controller | None = None, **run):
        return power_matrix(self.pendulum, self.body, self.pto, controller, **run)
