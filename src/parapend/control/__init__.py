"""Closed-loop realization of an optimal rotation.

- :mod:`.target`: the tracked orbit and its feedforward torque (Eq. 14 on the motion).
- :mod:`.riccati`: the sampled linearization and the discrete periodic Riccati equation
  (periodic LQR gains, open- and closed-loop Floquet multipliers).
- :mod:`.swingup`: energy pumping from rest and the hand-over to tracking.
- :mod:`.closedloop`: the sampled closed loop on the full nonlinear Eq. 14.
- :mod:`.track`: the entry point :func:`track` and its result; the irregular sea of a
  robustness run (:func:`.track.design_sea`, a record of :mod:`parapend.seas`).
- :mod:`.robustness`: seeded batches of runs with model error, noise and irregular seas.
"""

from .robustness import RobustnessResult, track_runs
from .track import TrackResult, prepare, track

__all__ = ["RobustnessResult", "TrackResult", "prepare", "track", "track_runs"]
