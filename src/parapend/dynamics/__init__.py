"""Uncontrolled dynamics of the parametrically excited pendulum (paper Eq. 1, Figs. 1-2).

All public functions use paper Eq. 1's convention: ``phi`` from the *hanging* position and
excitation strength ``p``::

    phi'' + gamma*phi' + (1 + p*cos(omega*t))*sin(phi) = 0

Internally the project's single model (``theta = phi + pi`` from the upright,
``theta'' + gamma*theta' - (1 + q)*sin(theta) = 0`` with ``q = p*cos(omega*t)``) is
integrated; conversion happens at the edges.

- :mod:`.simulate`: vectorized fixed-step RK4 stroboscopic map; dense DOP853 trajectories.
- :mod:`.attractors`: period-k oscillation / rotation classification, attractor search.
- :mod:`.basins`: basins of attraction on an initial-condition grid (xarray).
- :mod:`.continuation`: periodic orbits by shooting, Floquet multipliers, continuation of
  the period-1 rotation and its bifurcation curves J, G, E.
- :mod:`.motion`: one simulated motion, its time history and final classification.
- :mod:`._kernel`: compiled (numba) basin kernel, imported only when a basin map runs.
- :mod:`.figures`: paper Fig. 1 right, basin pictures, bifurcation curves.
"""

from .attractors import Attractor, AttractorSearch, Classification, classify, find_attractors
from .basins import basin_map, grid
from .continuation import (
    Bifurcation,
    Branch,
    PeriodicOrbit,
    RotationBoundaries,
    continue_rotation,
    floquet,
    periodic_orbit,
    rotation_boundaries,
    rotation_boundaries_at,
)
from .motion import Motion, simulate
from .simulate import (
    CONVENTION,
    Stroboscopic,
    Trajectory,
    energy,
    fast_sin,
    phi_to_theta,
    rhs,
    stroboscopic,
    theta_to_phi,
    trajectory,
)

__all__ = [
    "CONVENTION",
    "Attractor",
    "AttractorSearch",
    "Bifurcation",
    "Branch",
    "Classification",
    "Motion",
    "PeriodicOrbit",
    "RotationBoundaries",
    "Stroboscopic",
    "Trajectory",
    "basin_map",
    "classify",
    "continue_rotation",
    "energy",
    "fast_sin",
    "find_attractors",
    "floquet",
    "grid",
    "periodic_orbit",
    "phi_to_theta",
    "rhs",
    "rotation_boundaries",
    "rotation_boundaries_at",
    "simulate",
    "trajectory",
    "stroboscopic",
    "theta_to_phi",
]
