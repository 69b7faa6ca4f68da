"""One realization of one bin: :func:`parapend.irregular.sea` and the powers kept."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["BOUND_TOL", "electrical_power", "solve_bin", "verdict"]

#: relative margin of the bounds' checks in :func:`verdict`: the discretization's 0.1 %
#: (as ``parapend buoy``'s radiation-bound check)
BOUND_TOL = 1e-3


def electrical_power(result, efficiency: float) -> float:
    """Mean electrical power (W) of ``sea``'s optimal motion through a power take-off of
    efficiency ``eta``: the instantaneous power ``p = -T theta'`` on the record's uniform
    grid, ``eta p`` where it generates and ``p / eta`` where it motors. The motion is the
    ideal take-off's optimum, so this is what that motion yields, a lower bound on the
    lossy take-off's own optimum."""
    from ..irregular import sea_samples

    p = sea_samples(result)["power"][:-1]
    return float(np.mean(np.where(p > 0, efficiency * p, p / efficiency)))


def solve_bin(spec, i: int, j: int, r: int) -> dict:
    from ..seas import steepness_unchecked

    with steepness_unchecked():  # a rectangle of bins: corners no sea reaches
        return _solve_bin(spec, i, j, r)


def _solve_bin(spec, i: int, j: int, r: int) -> dict:
    if spec.device == "buoy" and spec.dofs != "heave":
        from .hull_device import solve_hull_bin

        start = [] if spec.controller is not None else None
        out = solve_hull_bin(spec, i, j, r, start)
        if spec.controller is not None:
            from .causal import solve_causal

            # the same record, run causally from its optimum's motion
            out.update(solve_causal(spec, i, j, r, mode=start[0]))
        return out
    if spec.device == "buoy":
        from .buoy_device import solve_buoy_bin

        out = solve_buoy_bin(spec, i, j, r)
    else:
        from ..irregular import sea

        res = sea(**spec.sea_kwargs(i, j, r))
        out = {"power": res.power_w, "limit_power": res.limit_power_w,
               "uniform_power": res.uniform_power_w, "status": res.status}
        if spec.efficiency is not None:
            out["electrical_power"] = electrical_power(res, spec.efficiency)
    if spec.controller is not None:
        from .causal import solve_causal

        out.update(solve_causal(spec, i, j, r))  # the same record, run causally
    return out


def verdict(vals: dict) -> dict:
    """One realization's values with a status that never calls an impossible number a
    success: a NaN or infinite power (or bound) is "nonfinite"; a power above the bound of
    its device (the gamma -> 0 limit ``limit_power`` for the prescribed heave, the radiation
    bound for the buoy, beyond :data:`BOUND_TOL`) or an electrical power above the
    mechanical one is "above_bound". Other statuses are kept."""
    if vals.get("status") not in ("converged", "no_power"):
        return vals
    names = [k for k in ("power", "electrical_power", "limit_power", "radiation_bound_power")
             if k in vals]
    if not all(math.isfinite(vals[k]) for k in names):
        return {**vals, "status": "nonfinite"}
    p = vals["power"]
    bound = vals.get("radiation_bound_power", vals.get("limit_power"))
    e = vals.get("electrical_power")
    if (bound is not None and p > 0 and p > bound * (1.0 + BOUND_TOL)) or \
            (e is not None and e > 0 and e > p + 1e-9 * abs(p)):
        return {**vals, "status": "above_bound"}
    return vals
