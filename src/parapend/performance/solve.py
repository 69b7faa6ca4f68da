"""One realization of one bin: :func:`parapend.irregular.sea` and the powers kept."""

from __future__ import annotations

import numpy as np

__all__ = ["electrical_power", "solve_bin"]


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
    if spec.device == "buoy":
        from .buoy_device import solve_buoy_bin

        return solve_buoy_bin(spec, i, j, r)
    from ..irregular import sea

    res = sea(**spec.sea_kwargs(i, j, r))
    out = {"power": res.power_w, "limit_power": res.limit_power_w,
           "uniform_power": res.uniform_power_w, "status": res.status}
    if spec.efficiency is not None:
        out["electrical_power"] = electrical_power(res, spec.efficiency)
    return out
