"""parapend: optimal energy extraction from period-1 rotations of a parametrically excited
pendulum (Nandakumar, Wiercigroch & Chatterjee, Mech. Res. Commun. 2012).

The public API mirrors the ``parapend`` command line::

    import parapend
    r = parapend.optimize(omega=1.8, delta=-0.3, harmonics=24)
    r.power, r.uniform_power, r.limit_power
"""

from .api import EXCITATIONS, build_excitation, damping_sweep, harmonic_table, optimize, threshold
from .errors import ParameterError, SolverError
from .excitation import fourier, from_csv, harmonic, square, two_harmonic
from .optimal.bvp import BVPSolution, solve_bvp_optimum
from .optimal.limit import limit
from .power import mean_power, uniform_power
from .results import OptimizeResult, ThresholdResult
from .sea_api import SeaResult, sea

__version__ = "0.1.0"

__all__ = [
    "BVPSolution",
    "EXCITATIONS",
    "OptimizeResult",
    "ParameterError",
    "SeaResult",
    "SolverError",
    "ThresholdResult",
    "__version__",
    "build_excitation",
    "damping_sweep",
    "from_csv",
    "fourier",
    "harmonic",
    "harmonic_table",
    "limit",
    "mean_power",
    "optimize",
    "sea",
    "solve_bvp_optimum",
    "square",
    "threshold",
    "two_harmonic",
    "uniform_power",
]
