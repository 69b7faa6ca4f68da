"""Swing-up from any state (hanging at rest included) by energy pumping, and the catch.

With ``theta`` from the upright, Eq. 14 has the energy ``E = theta'^2/2 + cos(theta)``
(hanging at rest ``E = -1``, upright at rest ``E = 1``) and

    dE/dt = T theta' - gamma theta'^2 + q(t) sin(theta) theta'.

Below the top's energy (``E < 1 + catch_margin``) the pump applies
``T = T_p sign(theta')`` (``T_p = min(T_max, pump_level)``, forward when at rest): the
torque term is then ``T_p |theta'| >= 0``, the largest rate of energy input a torque
bounded by ``T_p`` can give, and the parametric term ``q sin(theta) theta'`` only adds to
or subtracts from it as the phase falls. Above it the pendulum rotates. Backwards
(``theta' < 0``) the pump brakes, pushing forward (``T = +T_p``) until the pendulum has
turned (``theta' >= 0``); the braking is held across the energy threshold, else the pump
would hover at ``E = 1 + catch_margin``, alternately braking and pumping backwards.
Forwards (``theta' > 0``) the tracking controller takes over (:mod:`.closedloop`), and
the rotation's phase is pulled onto the forcing by the tracking feedback on the wrapped
angle error. (A pump that only followed ``sign(theta')`` would spin a pendulum that a
noisy measurement started backwards ever faster backwards, never reaching the catch.)
"""

from __future__ import annotations

import math

__all__ = ["energy", "pump_torque", "ready_to_catch"]


def energy(theta: float, theta_dot: float) -> float:
    """``E = theta'^2 / 2 + cos(theta)`` of the unforced, undamped Eq. 14 (upright at rest
    is 1, hanging at rest -1)."""
    return 0.5 * theta_dot * theta_dot + math.cos(theta)


def pump_torque(theta: float, theta_dot: float, level: float, margin: float,
                braking: bool) -> tuple[float, bool]:
    """The pump's torque and its braking flag (module docstring): ``level * sign(theta')``
    (forward at rest), except ``+level`` while braking a backward rotation, which starts
    above the top's energy ``1 + margin`` and lasts until ``theta' >= 0``."""
    if theta_dot >= 0.0:
        return level, False
    if braking or energy(theta, theta_dot) > 1.0 + margin:
        return level, True
    return -level, False


def ready_to_catch(theta: float, theta_dot: float, margin: float) -> bool:
    """True when the pendulum rotates forward with energy above ``1 + margin``."""
    return theta_dot > 0.0 and energy(theta, theta_dot) > 1.0 + margin
