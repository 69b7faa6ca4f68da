r"""A hull's sea state over several realizations: ``parapend buoy --dofs surge,heave,pitch --hs
--tp --realizations R``.

Realization ``r`` (``r = 0 .. R-1``) is the periodic record of the sea state seeded
``seed + r``: exactly the record ``parapend buoy`` solves alone with ``--seed seed + r``
(the same builder, :func:`.inputs._irregular_wave`), solved by the same function
(:func:`.api.solve_record`). The sea state's mean power is the mean of the resolved
realizations' powers, with its 95 % t-interval (:func:`parapend.confidence.t_interval`); a
realization without a resolved answer (its ``headline_reason``) is left out of the mean and
named. The work is estimated before the hull's BEM (:data:`parapend.performance.check.
HULL_SOLVE_SECONDS` a record of 9 waves, as its length); past
:data:`parapend.limits.MAX_UNTIMED_SECONDS` it needs ``time_limit``, and the realizations
finished by then are the answer, marked ``time_limit``.
"""

from __future__ import annotations

import dataclasses
import logging
import math

from .. import limits
from ..errors import ParameterError, check_int

__all__ = ["check_realizations", "record_seconds", "solve_realizations"]

log = logging.getLogger(__name__)


def record_seconds(waves: float, ideal: bool = True, kink: bool = False) -> float:
    """A rough CPU time (s) of one hull record of ``waves`` peak periods:
    :func:`parapend.performance.check.hull_record_seconds`."""
    from ..performance.check import hull_record_seconds

    return hull_record_seconds(waves, ideal, kink)


def check_realizations(value, opts: dict, time_limit=None) -> int:
    """``realizations`` checked (1 to :data:`parapend.limits.HULL_MAX_REALIZATIONS`, a sea
    state given by ``hs`` and ``tp``, not a measured record) and its work estimated before
    the BEM: refused in one line past the untimed cap without ``time_limit``."""
    from ..deadline import refuse_untimed
    from ..defaults import HULL

    r = check_int("realizations", value, 1, limits.HULL_MAX_REALIZATIONS)
    if opts.get("record") is not None:
        raise ParameterError("realizations: a measured record (--record) has one realization; "
                             "drop --realizations or give a sea state (--hs, --tp)")
    if not any(opts.get(k) is not None for k in ("hs", "tp", "repeat_period", "seed")):
        raise ParameterError("realizations: needs an irregular sea state: give --hs and --tp")
    tp = opts.get("tp") or HULL["tp"]
    rp = opts.get("repeat_period")
    waves = HULL["repeat_periods"] if rp is None else float(rp) / float(tp)
    from .pto import efficiency_pair

    eta = efficiency_pair(opts.get("efficiency"))
    kink = eta is not None and eta[0] * eta[1] != 1
    ideal = opts.get("torque_limit") is None and not opts.get("copper_loss") and not kink
    each = record_seconds(waves, ideal, kink)
    most = int(limits.MAX_UNTIMED_SECONDS // each)
    refuse_untimed("realizations", f"{r} hull records of {waves:.3g} peak periods",
                   r * each, f"use --realizations at most {most}" if most >= 1 else
                   "use a shorter record (--repeat-period)", time_limit)
    from ..deadline import duration

    log.info("buoy: %d hull records of %.3g peak periods: roughly %s on one core%s", r, waves,
             duration(r * each), "" if time_limit is None else
             f" (time limit {float(time_limit):g} s: the realizations finished by then)")
    return r


def _num(v) -> float:
    return math.nan if v is None else float(v)


def solve_realizations(solve, problem: dict, record, seed, realizations: int, *,
                       time_limit=None, deadline=None, progress=None):
    """Solve the records ``record(seed + r)`` (``(wave, info)`` each) of ``problem``
    (:func:`.api.hull_problem`) for ``r < realizations`` with ``solve``
    (:func:`.api.solve_record`, as ``buoy`` solves one record alone): the first record's
    :class:`~.result.BuoyResult` with the statistics over all of them; ``deadline`` stops
    the loop after the realization that passes it (the first always solved);
    ``progress(done, total)`` after each."""
    from ..confidence import METHOD, t_interval
    from ..deadline import expired

    seed0 = 0 if seed is None else int(seed)
    results = []
    for r in range(realizations):
        if results and expired(deadline):
            break
        results.append(solve(problem, *record(seed0 + r)))
        if progress is not None:
            progress(r + 1, realizations)
    powers = [_num(res.power_w) for res in results]
    ci = t_interval(powers)
    first = results[0]
    done = len(results)
    warnings = list(first.warnings)
    reasons = [res.headline_reason for res in results]
    failed = [seed0 + r for r, why in enumerate(reasons) if why]
    if failed:
        warnings.append(f"realizations: {len(failed)} of {done} without a resolved answer "
                        f"(seeds {', '.join(map(str, failed[:8]))}"
                        f"{', ...' if len(failed) > 8 else ''}) left out of the mean")
    if ci["count"] < 2:
        warnings.append("realizations: fewer than 2 resolved records: no confidence interval")
    fields = {}
    if done < realizations:
        fields = {"status": "time_limit", "success": False}
        warnings.append(f"time limit: {done} of {realizations} realizations solved within "
                        f"{time_limit:g} s; the mean and its interval are theirs (PARTIAL)")
    return dataclasses.replace(
        first, realizations=realizations, realizations_solved=int(ci["count"]),
        realization_seeds=[seed0 + r for r in range(done)], realization_powers_w=powers,
        realization_reasons=reasons,
        realization_peak_torques_nm=[_num(res.peak_torque_nm) for res in results],
        realization_peak_pivot_forces_n=[_num(res.peak_pivot_force_n) for res in results],
        mean_power_w=ci["mean"], power_std_w=ci["std"],
        power_ci_w=None if ci["low"] is None else [ci["low"], ci["high"]],
        power_ci_half_width_w=ci["half_width"], power_ci_method=METHOD, warnings=warnings,
        **fields)
