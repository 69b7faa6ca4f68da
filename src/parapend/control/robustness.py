"""Seeded batches of closed-loop runs: model error, measurement noise, irregular excitation.

Run ``i`` of a batch seeded ``seed`` draws from its own generator,
``numpy.random.default_rng(SeedSequence(seed).spawn(runs)[i])``: the plant's relative
damping and excitation errors uniformly in ``[-gamma_error, gamma_error]`` and
``[-delta_error, delta_error]``, then (in the run) the irregular record and the measurement
noise. The design (target and gains) is the same for every run: the controller never knows
the plant. A batch is reproducible bit for bit, and run ``i`` does not depend on ``runs``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import limits
from ..errors import ParameterError, check_int, check_range
from ..results import _Result
from .track import AVERAGE_PERIODS, simulate_design

__all__ = ["RobustnessResult", "track_runs"]


@dataclass(frozen=True, eq=False, repr=False)
class RobustnessResult(_Result):
    """A seeded batch (fields = JSON keys of ``parapend track --runs N --json``).

    ``fraction_locked``: runs that end locked; ``mean_power``: the mean over the runs of
    each run's ``mean_power`` (:class:`.track.TrackResult`: from its lock, else over its last
    10 periods, the stored energy's change counted; ``power_min``, ``power_max`` the extremes);
    ``locked_mean_power``: the same over the locked runs only; ``lock_period_max``: the
    latest lock among the locked runs. The per-run values are in ``run_*``.
    """

    runs: int
    seed: int
    fraction_locked: float
    mean_power: float
    locked_mean_power: float | None
    power_min: float
    power_max: float
    predicted_power: float
    optimum_at_torque_limit: float | None
    lock_period_max: int | None
    peak_torque: float
    gamma: float
    omega: float
    torque_limit: float | None
    design_torque_limit: float | None
    periods: int
    gamma_error: float
    delta_error: float
    noise_theta: float
    noise_speed: float
    irregular: bool
    lock_tolerance: float
    open_loop_multipliers: list
    closed_loop_multipliers: list
    run_power: list = field(default_factory=list)
    run_locked: list = field(default_factory=list)
    run_lock_period: list = field(default_factory=list)
    run_gamma_error: list = field(default_factory=list)
    run_delta_error: list = field(default_factory=list)
    success: bool = True
    status: str = "done"
    message: str = ""
    excitation: dict = field(default_factory=dict)
    units: dict | None = None
    mean_power_w: float | None = None
    predicted_power_w: float | None = None
    peak_torque_nm: float | None = None
    torque_limit_nm: float | None = None
    period_s: float | None = None

    command = "track"
    headline = ("runs", "fraction_locked", "mean_power", "mean_power_w", "predicted_power")

    def _series(self):
        import numpy as np
        import xarray as xr

        ds = xr.Dataset({"run_power": ("run", np.asarray(self.run_power, dtype=float)),
                         "run_locked": ("run", np.asarray(self.run_locked, dtype=bool)),
                         "run_gamma_error": ("run", np.asarray(self.run_gamma_error,
                                                               dtype=float)),
                         "run_delta_error": ("run", np.asarray(self.run_delta_error,
                                                               dtype=float))},
                        coords={"run": np.arange(len(self.run_power))})
        ds["run_lock_period"] = ("run", np.asarray(
            [np.nan if v is None else v for v in self.run_lock_period], dtype=float))
        return ds

    def _figure(self):
        """Mean power of each run against its plant's damping error, locked runs filled."""
        import numpy as np

        from ..plotting import plt
        from ..style import figure_style

        p = np.asarray(self.run_power, dtype=float)
        locked = np.asarray(self.run_locked, dtype=bool)
        g = np.asarray(self.run_gamma_error, dtype=float)
        with figure_style():
            fig, ax = plt.subplots(figsize=(6.5, 4.2))
            ax.plot(g[locked], p[locked], "o", color="C0", label="locked")
            ax.plot(g[~locked], p[~locked], "o", mfc="none", color="C3", label="not locked")
            ax.axhline(self.predicted_power, color="k", ls="--", lw=0.8,
                       label=f"predicted {self.predicted_power:.4g}")
            ax.set_xlabel(r"damping error of the plant, $\Delta\gamma$")
            ax.set_ylabel(r"mean power from the lock, else last 10 periods ($mgl/t_0$)")
            ax.set_title(f"track: {self.runs} runs, {100 * self.fraction_locked:.3g} % "
                         f"locked", fontsize=10)
            ax.legend(loc="best")
            fig.tight_layout()
        from ..units import Units, si_figure

        return si_figure(fig, Units.from_description(self.units))


def track_runs(*, runs: int = 20, seed: int = 0, periods: int = 100, torque_limit=None,
               torque_margin: float = 0.1, gamma_error: float = 0.0,
               delta_error: float = 0.0, noise_theta: float = 0.0, noise_speed: float = 0.0,
               irregular: bool = False, lock_tolerance: float = 0.1, r_weight: float = 0.1,
               progress=None, design=None, **optimize_args) -> RobustnessResult:
    """``runs`` seeded closed-loop runs from hanging rest (module docstring); the other
    parameters as :func:`parapend.control.track` (the errors are the bounds of the draws).
    At most ``runs * periods <= 10000`` (:data:`parapend.limits.MAX_TRACK_WORK`);
    ``design``: a :func:`~parapend.control.prepare` result to reuse."""
    from .track import _design, _multipliers

    runs = check_int("runs", runs, 1, 1000)
    periods = check_int("periods", periods, 2 * AVERAGE_PERIODS, limits.MAX_TRACK_PERIODS)
    if runs * periods > limits.MAX_TRACK_WORK:
        raise ParameterError(f"runs: expected runs * periods <= {limits.MAX_TRACK_WORK} "
                             f"(about 20 s), got {runs} * {periods}")
    seed = check_int("seed", seed, 0, 2**63 - 1)
    ge = abs(check_range("gamma-error", gamma_error, -0.9, 0.9))
    de = abs(check_range("delta-error", delta_error, -0.9, 0.9))
    nt = check_range("noise-theta", noise_theta, 0.0, 1.0)
    ns = check_range("noise-speed", noise_speed, 0.0, 10.0)
    tol = check_range("lock-tolerance", lock_tolerance, 1e-6, math.pi)
    d = _design(design, torque_limit, torque_margin, r_weight, optimize_args)
    if d.status == "infeasible":
        raise ParameterError(f"torque-limit: no rotation within the design limit "
                             f"{d.design_limit:g} ({d.message})")
    power, locked, lock_at, gerr, derr, peak = [], [], [], [], [], 0.0
    for i, child in enumerate(np.random.SeedSequence(seed).spawn(runs)):
        rng = np.random.default_rng(child)
        g_i = float(rng.uniform(-ge, ge)) if ge > 0 else 0.0
        d_i = float(rng.uniform(-de, de)) if de > 0 else 0.0
        _, f = simulate_design(d, periods=periods, gamma_error=g_i, delta_error=d_i,
                               noise_theta=nt, noise_speed=ns, irregular=irregular,
                               lock_tolerance=tol, rng=rng)
        power.append(f["mean_power"])
        locked.append(f["locked"])
        lock_at.append(f["lock_period"])
        gerr.append(g_i)
        derr.append(d_i)
        peak = max(peak, f["peak_torque"])
        if progress is not None:
            progress(i + 1, runs)
    p = np.array(power)
    lk = np.array(locked)
    tg = d.target
    return RobustnessResult(
        runs=runs, seed=seed, fraction_locked=float(lk.mean()), mean_power=float(p.mean()),
        locked_mean_power=float(p[lk].mean()) if lk.any() else None,
        power_min=float(p.min()), power_max=float(p.max()), predicted_power=tg.power,
        optimum_at_torque_limit=d.optimum_at_torque_limit,
        lock_period_max=max((v for v in lock_at if v is not None), default=None),
        peak_torque=peak, gamma=tg.gamma, omega=tg.omega, torque_limit=d.torque_limit,
        design_torque_limit=d.design_limit, periods=periods, gamma_error=ge,
        delta_error=de, noise_theta=nt, noise_speed=ns, irregular=bool(irregular),
        lock_tolerance=tol, open_loop_multipliers=_multipliers(d.lqr.open_loop_multipliers),
        closed_loop_multipliers=_multipliers(d.lqr.closed_loop_multipliers),
        run_power=power, run_locked=locked, run_lock_period=lock_at, run_gamma_error=gerr,
        run_delta_error=derr,
        message=f"{int(lk.sum())} of {runs} runs locked", excitation=tg.excitation.describe())
