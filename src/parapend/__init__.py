"""parapend: optimal energy extraction from period-1 rotations of a parametrically excited
pendulum (Nandakumar, Wiercigroch & Chatterjee, Mech. Res. Commun. 2012).

The public API mirrors the ``parapend`` command line::

    import parapend
    r = parapend.optimize(omega=1.8, delta=-0.3, harmonics=24)
    r.power, r.uniform_power, r.limit_power

The names below are imported on first use (PEP 562), so ``import parapend`` is cheap and the
command line can answer Ctrl-C while it is still loading NumPy and SciPy; the subpackages
(``parapend.optimal``, ``parapend.dynamics``, ...) are reachable as attributes as well.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: public name -> the module that defines it
_EXPORTS = {
    "EXCITATIONS": ".api", "build_excitation": ".api", "damping_sweep": ".api",
    "harmonic_table": ".api", "optimize": ".api", "threshold": ".api",
    "ParameterError": ".errors", "SolverError": ".errors",
    "fourier": ".excitation", "from_csv": ".excitation", "harmonic": ".excitation",
    "square": ".excitation", "two_harmonic": ".excitation",
    "BVPSolution": ".optimal.bvp", "solve_bvp_optimum": ".optimal.bvp",
    "limit": ".optimal.limit",
    "mean_power": ".power", "uniform_power": ".power",
    "OptimizeResult": ".results", "ThresholdResult": ".results",
    "SeaResult": ".irregular", "sea": ".irregular",
}

__all__ = sorted([*_EXPORTS, "__version__"])


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
    return sorted(set(globals()) | set(__all__))
