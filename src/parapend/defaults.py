"""The defaults of every command, in one place (docs/defaults.md gives the reasons).

The signatures of the commands' functions (:mod:`parapend.commands`) read their defaults
from here, and the command line's parsers read theirs from those signatures
(``tests/test_declared_once.py``). A number that stands for the paper's case is named for
it.
"""

from __future__ import annotations

__all__ = ["Default", "given", "OMEGA", "DELTA", "GAMMA", "DYNAMICS", "SEA", "BUOY", "HULL",
           "PERSISTENCE", "POWER_MATRIX"]


class Default(float):
    """A default value, told apart from the same number given by the user (the command
    line's type functions return a plain float), so that ``--omega 1.8 --frequency 0.9`` is
    refused as a contradiction while ``--frequency 0.9`` alone is not. It compares equal to
    the plain number."""

    def __repr__(self) -> str:
        return repr(float(self))


def given(value) -> bool:
    """True when a value came from the user, not from its default."""
    return value is not None and not isinstance(value, Default)


#: the paper's case: q = delta sin(omega t), delta = -0.3, omega = 1.8 (Tables 1-3, Figs. 4-10)
OMEGA = Default(1.8)
DELTA = -0.3

#: viscous damping gamma by command (docs/defaults.md: why they differ)
GAMMA = {
    # the paper's optima (Tables 1-3, Figs. 4, 8, 9) are undamped
    "optimize": Default(0.0), "harmonics": Default(0.0), "track": Default(0.0),
    "sweep": "0",
    # the power take-off: at gamma = 0 the efficiency optimum's torque is impulsive (its peak
    # grows with the mesh) and the ideal optimum is reached only by ever faster flips
    "pto-curve": Default(0.03),
    # a lightly damped pendulum on a buoy; gamma = 0 would ask for ever more harmonics per
    # wave over a long record
    "sea": 0.01,
    # the paper's coexistence case of Eq. 1 (Section 1, Figs. 1 and 2)
    "simulate": 0.1, "basins": 0.1, "rotations": 0.1,
}

#: the uncontrolled pendulum (paper Eq. 1): the coexistence case of Section 1 and Fig. 1
DYNAMICS = {"gamma": GAMMA["simulate"], "p": 0.8, "omega": 2.1}

#: the sea state and the pendulum of ``sea`` (a 1 m, 10 kg pendulum on a small buoy)
SEA = {"hs": 2.0, "tp": 8.0, "seed": 0, "length": 1.0, "mass": 10.0, "gravity": 9.81,
       "gamma": GAMMA["sea"]}

#: the embedded design of ``buoy`` (docs/defaults.md): a heavy pendulum in a small floating
#: cylinder, in a regular wave near the buoy's heave resonance, where the pendulum's reaction
#: changes the answer. SI units; ``design_bounds`` are the ranges ``--optimize-design`` searches
#: without ``--<name>-bounds``, as factors of the design's value (damping: N m s/rad).
BUOY = {"wave_height": 0.2, "wave_period": 1.8, "hs": 0.5, "tp": 2.5,
        "radius": 0.5, "draft": 0.5, "mass": Default(80.0), "length": Default(0.3),
        "inertia": None, "damping_coefficient": Default(1.0),
        "design_bounds": {"mass": (0.25, 4.0), "length": (0.25, 4.0), "inertia": (1.0, 4.0),
                          "damping_coefficient": (0.0, 20.0)}}

#: ``buoy --dofs surge,heave,pitch``: the embedded hull design (docs/hull.md): a 10 m x 4 m
#: x 1 m box barge, a 2 t pendulum of 1 m on a pivot 0.5 m above the waterline at midship,
#: in a 1 m, 6 s regular wave (or a sea state of Hs 1 m, Tp 6 s in a record of 4 peak
#: periods); the pendulum's options given to ``buoy`` replace these; ``--body cylinder`` or
#: ``sphere`` in place of the barge: radius 2 m, draft 1 m (the pendulum fits inside)
HULL = {"wave_height": 1.0, "wave_period": 6.0, "hs": 1.0, "tp": 6.0, "repeat_periods": 4,
        "barge_length": 10.0, "barge_beam": 4.0, "barge_draft": 1.0,
        "mass": 2000.0, "length": 1.0, "inertia": None, "damping_coefficient": 50.0,
        "pivot_height": 0.5, "pivot_offset": 0.0, "radius": 2.0, "draft": 1.0,
        # the power matrix's hull column: each realization's record, in peak periods. IEC TS
        # 62600-100 and WEC-Sim use realizations of 20 to 30 minutes: 200 peak periods and
        # at least 20 minutes (``matrix_record_s``: 217 peak periods at Tp 5.54 s, at most
        # the hull's 300), for an ideal take-off (its records are solved matrix-free, about
        # 50 s of CPU each: benchmarks/bench_hull_record.out.txt); a take-off with an
        # efficiency, a copper loss or a torque limit is solved far slower (at most about 30
        # waves with a torque limit or a copper loss, 10 with an efficiency): its records
        # stay 4 peak periods (the single record's)
        "matrix_waves": 200.0, "matrix_record_s": 1200.0, "matrix_waves_lossy": 4.0}
#: ``power-matrix --waves`` of the prescribed pendulum and the heaving buoy (peak periods)
POWER_MATRIX = {"waves": 50.0}

#: ``horizon``: the horizons (peak periods), forecasts and baselines of the curve, the
#: number of seeded records and the update interval of the receding-horizon controller; each
#: record ``repeat_periods`` peak periods long without ``--repeat-period`` (20 waves: the
#: curve of docs/control.md; the 100 of ``sea``'s record cost ten receding-horizon runs of
#: 3200 updates, estimated at 9 minutes, past the 2 minutes a command runs untimed; the
#: horizon 4, 40 % of the estimate, took the curve to 118 s at a load of 8 and is left out)
HORIZON = {"horizons": "0.25,0.5,1,2", "forecasts": "perfect,ar",
           "baselines": "tracker,extremum", "records": 1, "update_interval": 0.03125,
           "warm_up": 0.0, "speed_limit": None, "repeat_periods": 20}

#: ``horizon --device buoy``: the buoy's curve without the options: horizons (peak periods),
#: each record's length in peak periods, the update interval and the warm-up (peak periods;
#: ``parapend buoy --controller mpc``'s). Ten waves a record: three horizons and two
#: forecasts of the default ``plan`` planner are estimated at about 40 s
#: (``parapend.hydro.horizon.BUOY_MPC_SECONDS``), inside the two minutes a command runs
#: untimed
BUOY_HORIZON = {"horizons": "0.5,1,2", "repeat_periods": 10, "update_interval": 0.125,
                "warm_up": 4.0}

#: ``track --controller``: the regular-wave controller by default; with ``mpc`` the horizon
#: and the update interval (peak periods) and the wave forecast of the receding-horizon
#: controller (docs/control.md)
TRACK = {"controller": "lqr", "horizon": 2.0, "update_interval": 0.03125, "forecast": "perfect",
         "speed_limit": None}

#: ``persistence``: a 0.3 m, 1 kg pendulum (small-swing period T0 = 1.1 s) on a light bearing
#: with a light generator (total damping time I / (c + c_g) = 130 s), in a wave-flume sea
#: (Hs 2 cm, Tp 0.3 s, Tp / T0 = 0.27) where its rotation persists on part of the records:
#: one sea state of 100 realizations of the 1200 s record (a few seconds);
#: docs/persistence.md chooses a map's grid from T0
PERSISTENCE = {"mass": 1.0, "length": 0.3, "damping_coefficient": 2e-4,
               "generator_damping": 5e-4, "hs": 0.02, "tp": 0.3, "duration": 1200.0,
               "realizations": 100}
