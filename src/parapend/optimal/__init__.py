"""Optimal period-1 rotations: one module per method (DESIGN.md section 3)."""

from .bvp import BVPSolution, solve_bvp_optimum
from .fourier import FourierProblem, solve_fourier
from .limit import LimitResult, limit

__all__ = ["BVPSolution", "FourierProblem", "LimitResult", "limit", "solve_bvp_optimum",
           "solve_fourier"]
