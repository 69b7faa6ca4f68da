"""Causality of the buoy's receding-horizon controller (issue 31's acceptance, on
:func:`parapend.hydro.control.buoy_mpc`): altering the sea only after ``t0 + H`` leaves
every torque held before ``t0`` bit-identical (perfect forecast, the only one the buoy's
controller has), for the default ``coupled`` controller and the experimental ``plan``; a
controller that peeks one horizon further fails the same check. The shape of the pendulum's
test in tests/test_power_matrix_causal.py.

The sea is altered where the run reads it: the excitation force on the plant's half-step
nodes (:func:`parapend.hydro.control.force_nodes`, the plant's and the perfect forecast's one
source), replaced here by a monkeypatch, so ``buoy_mpc`` is called through its public
arguments only. On the synthetic, exactly causal dataset of tests/buoy_synthetic.py (no BEM).
"""

import math

import numpy as np
import pytest
from buoy_synthetic import synthetic

from parapend.hydro import control as bc
from parapend.hydro.coupled import Pendulum, Wave

SYN = synthetic()
TR, TP = 5.0, 2.5  # a record of 5 s: components of 2.5 s and 1.67 s
AMPS = np.zeros(6, complex)
AMPS[1], AMPS[2] = 0.25, 0.12j
WAVE = Wave(2 * math.pi / TR, AMPS)
PENDULUM = Pendulum(20.0, 0.3, 1.8, 0.25)
OPTS = {"peak_period": TP, "horizon": 0.5, "update_interval": 0.125, "warmup": 1.0,
        "samples": 32, "memory": 8.0}
#: the controllers' own options: the default one as buoy_mpc has it, ``plan`` as its tests
REPEATS = 1
CONTROLLERS = {"coupled": {}, "plan": {"controller": "plan", "iterations": 1}}


def _run(monkeypatch, controller, cut=None, peek=False):
    """A short closed loop (a warm-up of one peak period, one repeat of the 5 s record) with
    the excitation altered from plant node ``cut`` on (None: not); ``peek``: the controller
    is handed, beside its horizon's force, a trace (1e-3) of the force one horizon further
    on."""
    real = bc.force_nodes
    store = {}

    def altered(*a):
        fn = real(*a).copy()
        if cut is not None:
            fn[cut:] += 500.0 * np.sin(0.7 * np.arange(fn.size - cut))
        store["fn"] = fn
        return fn
    monkeypatch.setattr(bc, "force_nodes", altered)

    def further(plant, fseg):
        # the update's first node is 2 j ps = 2 k0 (k0: the plant's steps so far)
        fn, a, w = store["fn"], 2 * plant.k0, fseg.size - 1
        far = fn[a + w:a + 2 * w + 1]
        return fseg + 1e-3 * np.pad(far, (0, fseg.size - far.size))

    if peek and controller == "coupled":
        plan = bc._plan_coupled

        def peeking(plant, prob, u0, fseg, *rest):
            return plan(plant, prob, u0, further(plant, fseg), *rest)
        monkeypatch.setattr(bc, "_plan_coupled", peeking)
    elif peek:
        plan = bc._MotionPlanner.plan

        def peeking(self, plant, u0, fseg, *rest):
            return plan(self, plant, u0, further(plant, fseg), *rest)
        monkeypatch.setattr(bc._MotionPlanner, "plan", peeking)
    return bc.buoy_mpc(SYN, PENDULUM, WAVE, **OPTS, **CONTROLLERS[controller],
                       repeats=REPEATS)


@pytest.mark.parametrize("controller, peek, causal", [
    ("coupled", False, True),   # altered after t0 + H: nothing before t0 changes
    ("coupled", True, False),   # a controller that looks further ahead fails the test
    ("plan", False, True),
    ("plan", True, False),
])
def test_torques_before_t0_ignore_the_sea_after_t0_plus_h(monkeypatch, controller, peek,
                                                           causal):
    """``t0`` an update's sample three updates after the catch: the torques before it were
    planned at ``t0 - u`` at the latest (``u`` the update interval), on the force up to
    ``t0 - u + H``, its plant half-step nodes up to ``2 (j0 - m + n) ps``; the sea altered
    from the next node on leaves them bit-identical; the same check fails for a controller
    that peeks one horizon further (the test has the power to see such a look)."""
    base = _run(monkeypatch, controller, peek=peek)
    assert base.success and base.catch_time_s is not None
    dt, ps = base.dt_s, bc.PLANT_STEPS
    n = int(round(base.horizon_s / dt))
    m = int(round(base.update_interval_s / dt))
    j0 = int(round(base.catch_time_s / dt)) + 3 * m
    assert j0 + 2 * n < base.series["torque"].size
    last = 2 * (j0 - m + n) * ps
    after = _run(monkeypatch, controller, cut=last + 1, peek=peek)
    a, b = base.series["torque"][:j0], after.series["torque"][:j0]
    assert np.any(a != 0)
    assert np.array_equal(a, b) is causal
