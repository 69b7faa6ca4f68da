"""The inputs of ``parapend buoy`` that every degree-of-freedom set shares (:mod:`.api`):
the wave periods, the pendulum, an irregular sea's periodic record."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, check_int, check_positive
from .declared import check, default_of

__all__ = ["parse_periods"]

#: at most this many periods in a sweep
MAX_PERIODS = 200


def parse_periods(text) -> np.ndarray | None:
    """``"FROM:TO:N"`` -> N periods from FROM to TO (s); a comma list ``"T1,T2,..."`` -> those
    periods (s), in the order given; a plain number -> None."""
    if not isinstance(text, str) or (":" not in text and "," not in text):
        return None
    if ":" not in text:
        parts = [s.strip() for s in text.split(",")]
        if not 1 <= len(parts) <= MAX_PERIODS:
            raise ParameterError(f"wave-period: expected at most {MAX_PERIODS} periods, got "
                                 f"{len(parts)}")
        return np.array([_period(s) for s in parts])
    parts = text.split(":")
    if len(parts) != 3:
        raise ParameterError(f"wave-period: expected a period in s, T1,T2,... or FROM:TO:N, "
                             f"got {text!r:.60}")
    try:
        lo, hi = float(parts[0]), float(parts[1])
        n = int(parts[2])
    except ValueError:
        raise ParameterError(f"wave-period: expected FROM:TO:N (two periods in s, a count), "
                             f"got {text!r:.60}") from None
    lo = check_positive("wave-period", lo)
    hi = check_positive("wave-period", hi)
    n = check_int("wave-period", n, 2, MAX_PERIODS)
    if not hi > lo:
        raise ParameterError(f"wave-period: expected FROM < TO, got {text!r:.60}")
    return np.linspace(lo, hi, n)


def _period(value) -> float:
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            raise ParameterError(f"wave-period: expected a period in s, T1,T2,... or "
                                 f"FROM:TO:N, got {value!r:.60}") from None
    return check("wave_period", value, why="wave period, s")


# --- the pieces -----------------------------------------------------------------------------
def _pendulum(mass, length, inertia, damping_coefficient, kind="buoy"):
    """The keywords' pendulum: :meth:`.declared.Pendulum.checked` (``kind``: whose declared
    defaults, the embedded ``"buoy"``'s or ``"hull"``'s)."""
    from .declared import Pendulum

    return Pendulum(mass=mass, length=length, inertia=inertia,
                    damping_coefficient=damping_coefficient).checked(kind)


def _irregular_wave(hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff, record, taper,
                    units, kind="buoy"):
    """The Wave of a periodic irregular record (``sea``'s parsing and checks; the declared
    defaults of the embedded ``kind``, ``"buoy"`` or ``"hull"``) and its description."""
    from ..seas import measured_record, sea_record
    from .coupled import Wave

    if record is not None:
        bad = [n for n, v in (("hs", hs), ("tp", tp), ("seed", seed),
                              ("repeat-period", repeat_period)) if v is not None]
        if bad:
            raise ParameterError(f"{', '.join(bad)}: not used with --record; drop it")
        exc = measured_record(units, record, taper=taper, cutoff=cutoff)
    else:
        exc = sea_record(units, hs=default_of("hs", hs, kind), tp=default_of("tp", tp, kind),
                         spectrum=spectrum, gamma_peak=gamma_peak,
                         repeat_period=repeat_period, seed=default_of("seed", seed),
                         cutoff=cutoff)
    info = dict(exc.info)
    info.pop("response", None)
    tr = float(info["repeat_period"])
    # the record's own components (an FFT of samples would add round-off at every harmonic)
    wave = Wave(2 * math.pi / tr, np.asarray(exc.heave[1:], dtype=complex))
    info = {"kind": "irregular", **info}
    return wave, info
