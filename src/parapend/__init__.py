"""parapend: optimal energy extraction from period-1 rotations of a parametrically excited
pendulum (Nandakumar, Wiercigroch & Chatterjee, Mech. Res. Commun. 2012).

The public API mirrors the ``parapend`` command line::

    import parapend
    r = parapend.optimize(omega=1.8, delta=-0.3, harmonics=24)
    r.power, r.uniform_power, r.limit_power
    r = parapend.optimize(gamma=0.03, torque_limit=2.5)      # through a power take-off
    t = parapend.threshold(length=1, mass=10, frequency=0.9, amplitude=0.09)
    t.damping_threshold, t.damping_threshold_coefficient     # gamma*, and in N m s/rad

Every command of the ``parapend`` program is a function of the same name here (dashes as
underscores: ``damping_sweep``, ``pto_curve``), taking the command's options as keyword
arguments with the same defaults and returning a frozen result whose fields are the
command's ``--json`` keys (:mod:`parapend.commands`).

The names below are imported on first use (PEP 562), so ``import parapend`` is cheap and the
command line can answer Ctrl-C while it is still loading NumPy and SciPy; the subpackages
(``parapend.optimal``, ``parapend.dynamics``, ``parapend.maps``, ...) are reachable as
attributes as well.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: public name -> the module that defines it. One function per command of the command line
#: (parapend.commands: same name, dashes as underscores, the options as parameters).
_COMMANDS = ("optimize", "threshold", "damping_sweep", "harmonics", "figure", "reproduce",
             "pto_curve", "simulate", "basins", "rotations", "track", "sea", "sweep", "map",
             "power_matrix", "horizon")
_EXPORTS = {
    **{name: ".commands" for name in _COMMANDS},
    "EXCITATIONS": ".api", "build_excitation": ".api", "harmonic_table": ".api",
    "ParameterError": ".errors", "SolverError": ".errors",
    "fourier": ".excitation", "from_csv": ".excitation", "harmonic": ".excitation",
    "square": ".excitation", "two_harmonic": ".excitation",
    "BVPSolution": ".optimal.bvp", "solve_bvp_optimum": ".optimal.bvp",
    "limit": ".optimal.limit",
    "mean_power": ".power", "uniform_power": ".power",
    "OptimizeResult": ".results", "Record": ".results", "ThresholdResult": ".results",
    "SeaResult": ".irregular",
    "HorizonResult": ".control.horizon",
}
# the pendulum inside a floating buoy: ``parapend.buoy`` is the command's function, the
# subpackage that answers it is ``parapend.hydro`` (docs/layout.md)
_COMMANDS += ("buoy",)
_EXPORTS["buoy"] = ".commands"
_EXPORTS.update({"BuoyResult": ".hydro.result", "BuoySweepResult": ".hydro.result"})
# rotation persistence over sea states (parapend.dynamics.persistence)
_COMMANDS += ("persistence",)
_EXPORTS["persistence"] = ".commands"
_EXPORTS["PersistenceResult"] = ".dynamics.persistence"

# `map` is left out of the star import, which would hide the builtin: use parapend.map
__all__ = sorted([*(k for k in _EXPORTS if k != "map"), "__version__"])


def __getattr__(name: str):
    """Import a public name, or a subpackage, on first access."""
    where = _EXPORTS.get(name)
    if where is not None:
        value = getattr(importlib.import_module(where, __name__), name)
        globals()[name] = value
        return value
    if not name.startswith("__"):
        try:
            return importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS) | {"__version__"})
