"""Swing-up from any state (hanging at rest included) by energy pumping, and the catch.

With ``theta`` from the upright, Eq. 14 has the energy ``E = theta'^2/2 + cos(theta)``
(hanging at rest ``E = -1``, upright at rest ``E = 1``) and

    dE/dt = T theta' - gamma theta'^2 + q(t) sin(theta) theta'.

The pump applies ``T = T_p sign(theta')`` (``T_p = min(T_max, pump_torque)``, forward
when at rest): the torque term is then ``T_p |theta'| >= 0``, the largest rate of energy
input a torque bounded by ``T_p`` can give, and the parametric term ``q sin(theta)
theta'`` only adds to or subtracts from it as the phase falls (with ``T_p`` above
``gamma |theta'| + |q|`` the energy grows on every swing). Once the pendulum passes over
the top forward with energy above ``1 + catch_margin`` (``theta' > 0``), it rotates, and
the tracking controller takes over (:mod:`.closedloop`); the rotation's phase is pulled
onto the forcing by the tracking feedback on the wrapped angle error.
"""

from __future__ import annotations

import math

__all__ = ["energy", "pump_torque", "ready_to_catch"]


def energy(theta: float, theta_dot: float) -> float:
    """``E = theta'^2 / 2 + cos(theta)`` of the unforced, undamped Eq. 14 (upright at rest
    is 1, hanging at rest -1)."""
    return 0.5 * theta_dot * theta_dot + math.cos(theta)


def pump_torque(theta_dot: float, level: float) -> float:
    """``level * sign(theta')``, forward (+level) at rest: the energy-pumping torque."""
    return level if theta_dot >= 0.0 else -level


def ready_to_catch(theta: float, theta_dot: float, margin: float) -> bool:
    """True when the pendulum rotates forward with energy above ``1 + margin``."""
    return theta_dot > 0.0 and energy(theta, theta_dot) > 1.0 + margin
