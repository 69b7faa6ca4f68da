r"""Irregular seas: sea-state spectra, periodic random records, measured heave records.

Spectra (IEC TS 62600-2, as in MHKiT's ``resource`` module; ``f`` in Hz, ``S`` in m^2/Hz)::

    Pierson-Moskowitz  S_PM(f) = A f^-5 exp(-B f^-4),   B = (5/4) Tp^-4,  A = B Hs^2 / 4
    JONSWAP            S_J(f)  = (1 - 0.287 ln gamma_p) S_PM(f) gamma_p^exp(-(f/fp - 1)^2 / (2 s^2))
                       s = 0.07 for f <= fp, 0.09 above

``4 sqrt(m0) = Hs`` exactly for Pierson-Moskowitz and to about 1 % for JONSWAP (the factor
``1 - 0.287 ln gamma_p`` is the standard's approximate normalization).

A record is made periodic with a repeat period ``T_r`` (as WecOptTool does): components at
the multiples ``f_k = k / T_r`` up to a cutoff, amplitudes ``a_k = sqrt(2 S(f_k) / T_r)``,
phases drawn from ``numpy.random.default_rng(seed)``, uniform in [0, 2 pi)::

    eta(t) = sum_k a_k cos(2 pi f_k t + phi_k)

The base of the pendulum heaves as ``z = eta`` (a buoy small against the wavelengths, which
follows the surface), or as ``z = sum |H(f_k)| a_k cos(2 pi f_k t + phi_k + arg H(f_k))``
with a heave response ``H`` given as a table (``f,gain,phase``; Hz, m/m, radians; linear
interpolation, gain 0 outside the table). Then ``q = z_tt / g`` (base acceleration over
``g``, as in :mod:`parapend.units`), an excitation with fundamental ``omega_r = 2 pi t0 /
T_r`` (non-dimensional) whose ``k``-th harmonic is ``Q_k = -(2 pi f_k)^2 a_k e^{i phi_k} /
g``: a :class:`SeaExcitation`.

The cutoff matters: the acceleration spectrum ``f^4 S(f)`` falls only like ``1/f``, so the
total variation of ``q`` (and the gamma -> 0 limit of power) grows slowly with the cutoff.
It is stated in units of the peak frequency (``cutoff = 3``: components up to ``3 fp``) and
reported; a heave response table that falls off at high frequency removes the dependence.

Measured records: CSV ``t,z`` (seconds, metres), resampled on a uniform grid by linear
interpolation at the median spacing, the mean removed, and made periodic by a Tukey
(cosine) taper over ``taper`` of its length (half at each end; default 0.1), so that ``z``
and its slope are continuous across the repeat; ``T_r`` is the record's length. The
acceleration is the spectral second derivative, cut at the same ``cutoff`` (in units of the
record's spectral peak) so that the measurement noise, amplified by ``f^2``, stays out.
"""

from __future__ import annotations

import contextlib
import contextvars
import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import limits
from .errors import ParameterError, check_int, check_positive, check_range
from .excitation import Excitation, _read_bounded, check_excitation

__all__ = ["SPECTRA", "SeaExcitation", "jonswap", "measured_record", "pierson_moskowitz",
           "read_response", "sea_record", "spectral_moments"]

SPECTRA = ("jonswap", "pierson-moskowitz")


def pierson_moskowitz(f, hs: float, tp: float) -> np.ndarray:
    """Pierson-Moskowitz spectrum (IEC TS 62600-2), m^2/Hz, at frequencies ``f`` (Hz, > 0)."""
    f = np.asarray(f, dtype=float)
    b = 1.25 / tp**4
    a = b * hs**2 / 4.0
    fs = np.where(f > 0, f, 1.0)
    return np.where(f > 0, a * fs**-5.0 * np.exp(-b * fs**-4.0), 0.0)


def jonswap(f, hs: float, tp: float, gamma_peak: float = 3.3) -> np.ndarray:
    """JONSWAP spectrum (IEC TS 62600-2, MHKiT's normalization), m^2/Hz, at ``f`` (Hz)."""
    f = np.asarray(f, dtype=float)
    fp = 1.0 / tp
    sigma = np.where(f <= fp, 0.07, 0.09)
    peak = np.exp(-((f / fp - 1.0) ** 2) / (2.0 * sigma**2))
    return (1.0 - 0.287 * math.log(gamma_peak)) * pierson_moskowitz(f, hs, tp) * gamma_peak**peak


def spectral_moments(f, s, orders=(0, 1, 2)) -> tuple:
    """``m_n = int f^n S(f) df`` by the trapezoidal rule on the given frequencies."""
    f = np.asarray(f, dtype=float)
    s = np.asarray(s, dtype=float)
    from scipy.integrate import trapezoid

    return tuple(float(trapezoid(f**n * s, f)) for n in orders)


@dataclass(frozen=True, eq=False)
class SeaExcitation(Excitation):
    """Periodic ``q = z_tt / g`` of a sea record: harmonic ``k`` at ``k omega`` (rad per unit
    of non-dimensional time), ``omega = 2 pi t0 / T_r``.

    Attributes
    ----------
    omega : float
        Fundamental ``omega_r``, non-dimensional.
    spec : ndarray, complex, shape (K + 1,)
        One-sided spectrum of ``q`` (``Q_0 = 0``).
    heave : ndarray, complex, shape (K + 1,)
        One-sided spectrum of the heave ``z`` (m).
    info : dict
        What defines the record (JSON-ready): sea state or file, cutoff, repeat period...
    """

    omega: float
    spec: np.ndarray = field(repr=False)
    heave: np.ndarray = field(repr=False)
    info: dict = field(default_factory=dict)
    name: str = "sea"

    @property
    def spectrum(self) -> np.ndarray:
        return self.spec

    def describe(self) -> dict:
        return {"excitation": "sea", "omega": self.omega, **self.info}

    def z(self, t) -> np.ndarray:
        """Heave (m) at non-dimensional times ``t``."""
        from .excitation import _evaluate

        return _evaluate(self.heave, self.omega * np.asarray(t, dtype=float))

    @property
    def mean_frequency_harmonic(self) -> float:
        """``m1 / m0`` of the heave spectrum, in harmonics of the repeat period."""
        k = np.arange(self.heave.size)
        e = np.abs(self.heave) ** 2
        return float(np.sum(k * e) / np.sum(e)) if np.sum(e) > 0 else 0.0


def _heave_to_q(heave: np.ndarray, repeat_period: float, gravity: float) -> np.ndarray:
    k = np.arange(heave.size)
    return -((2 * math.pi * k / repeat_period) ** 2) * heave / gravity


def read_response(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Heave response table, CSV ``f,gain,phase`` (Hz, m of heave per m of wave, radians)."""
    rows = _csv_rows(path, ["f", "gain", "phase"], "response")
    a = np.array(rows)
    return check_response(a[:, 0], a[:, 1], a[:, 2], f" in {path}")


def check_response(f, gain, phase, where: str = "") -> tuple:
    """A heave response table (from a file or given as arrays): three equal-length 1-D
    arrays of finite numbers, at least 2 rows, ``f >= 0`` strictly increasing (Hz), gains in
    ``[0, 1e3]`` (m/m), phases finite (rad)."""
    try:
        f, gain, phase = (np.array(v, dtype=float) for v in (f, gain, phase))
    except (TypeError, ValueError):
        raise ParameterError(f"response: expected three arrays of numbers (f, gain, "
                             f"phase){where}") from None
    if not (f.ndim == gain.ndim == phase.ndim == 1 and f.shape == gain.shape == phase.shape):
        raise ParameterError(f"response: expected three 1-D arrays of equal length (f, gain, "
                             f"phase){where}")
    if f.size > limits.MAX_FILE_ROWS:
        raise ParameterError(f"response: expected at most {limits.MAX_FILE_ROWS} rows{where}, "
                             f"got {f.size}")
    if not all(np.all(np.isfinite(v)) for v in (f, gain, phase)):
        raise ParameterError(f"response: expected finite numbers{where}")
    if f.size < 2 or np.any(np.diff(f) <= 0) or f[0] < 0:
        raise ParameterError(f"response: expected at least 2 rows with f >= 0 strictly "
                             f"increasing{where}")
    if np.any(gain < 0) or np.max(gain) > 1e3:
        raise ParameterError(f"response: expected gains in [0, 1e3]{where}, got "
                             f"{float(np.min(gain)):.4g} to {float(np.max(gain)):.4g}")
    return f, gain, phase


def _csv_rows(path, header: list, name: str, max_rows: int = None) -> list:
    if not isinstance(path, (str, Path)) or not str(path):
        raise ParameterError(f"{name}: expected a CSV path, got {path!r:.60}")
    path = Path(path)
    try:
        rows = max_rows or limits.MAX_FILE_ROWS
        # 64 bytes a row: two numbers at full precision (about 45) and room to spare
        text = _read_bounded(path, f"a CSV of at most {rows} rows '{','.join(header)}'",
                             max_bytes=max(limits.MAX_BYTES_FILE, 64 * rows))
    except ParameterError as exc:  # name the parameter the user gave, not "file"
        msg = str(exc)
        raise ParameterError(f"{name}:{msg[5:]}" if msg.startswith("file:") else msg) from None
    try:
        rows = [r for r in csv.reader(text.splitlines()) if r and any(c.strip() for c in r)]
    except csv.Error as exc:  # a field over the csv module's limit (131072 characters)
        raise ParameterError(f"{name}: not a CSV of numbers '{','.join(header)}' in {path} "
                             f"({exc})") from None
    if not rows or [c.strip().lower() for c in rows[0]] != header:
        raise ParameterError(f"{name}: expected a CSV header '{','.join(header)}' in {path}")
    max_rows = max_rows or limits.MAX_FILE_ROWS
    if len(rows) - 1 > max_rows:
        raise ParameterError(f"{name}: expected at most {max_rows} rows in {path}, "
                             f"got {len(rows) - 1}")
    out = []
    for i, r in enumerate(rows[1:], start=2):
        try:
            if len(r) != len(header):
                raise ValueError
            vals = [float(c) for c in r]
            if not all(math.isfinite(v) for v in vals):
                raise ValueError
        except ValueError:
            raise ParameterError(f"{name}: expected {len(header)} finite numbers on line {i} "
                                 f"of {path}, got {','.join(r)!r:.60}") from None
        out.append(vals)
    return out


def check_spectrum(spectrum, gamma_peak, cutoff) -> tuple[float, float]:
    """The spectrum's shape, its JONSWAP peak enhancement and its cutoff (in units of the
    peak frequency), checked in one line each; returns ``(gamma_peak, cutoff)``."""
    if not isinstance(spectrum, str) or spectrum not in SPECTRA:
        raise ParameterError(f"spectrum: expected one of {', '.join(SPECTRA)}, "
                             f"got {spectrum!r:.60}")
    gamma_peak = check_range("gamma-peak", gamma_peak, 1.0, 20.0,
                             why="JONSWAP peak enhancement")
    if spectrum != "jonswap" and gamma_peak != 3.3:
        raise ParameterError("gamma-peak: only used by spectrum 'jonswap'")
    cutoff = check_range("cutoff", cutoff, 1.5, 10.0,
                         why="highest component frequency, in units of the peak frequency")
    return gamma_peak, cutoff


#: A regular wave steeper than this breaks (Michell's limit, H / lambda ~ 0.142); a sea
#: state's significant steepness ``Hs / lambda_p`` is held to the same limit
BREAKING_STEEPNESS = 1 / 7
#: a wave (``H / lambda``) or a sea state (``Hs / lambda_p``) steeper than this is warned
#: about (linear theory stretched)
STEEP_WARNING = 1 / 20


def sea_steepness(hs: float, tp: float, g: float = 9.81) -> float:
    """The significant steepness ``Hs / lambda_p`` of a sea state: ``lambda_p = g Tp^2 /
    (2 pi)``, the deep-water wavelength of the peak period (the longest it has: a finite
    depth's waves are shorter and steeper)."""
    return hs / (g * tp * tp / (2 * math.pi))


#: False within :func:`steepness_unchecked`
_REFUSE_BREAKING = contextvars.ContextVar("parapend_refuse_breaking", default=True)


@contextlib.contextmanager
def steepness_unchecked():
    """Within it, :func:`check_sea_steepness` refuses nothing: a power matrix's rectangle of
    bins holds corners no sea reaches (Hm0 5 m at Te 4 s), which a site's scatter gives no
    hours, and the matrix solves its bins as before; a record drawn only as a scaled base
    excitation (``track``'s irregular sea, set by the rms of ``q``) is no sea state."""
    token = _REFUSE_BREAKING.set(False)
    try:
        yield
    finally:
        _REFUSE_BREAKING.reset(token)


def check_sea_steepness(hs: float, tp: float) -> None:
    """Refuse, before any work, a sea state whose significant wave alone would break:
    ``Hs / lambda_p > 1/7`` (:data:`BREAKING_STEEPNESS`, the regular wave's limit); not
    within :func:`steepness_unchecked`."""
    steep = sea_steepness(hs, tp)
    if steep > BREAKING_STEEPNESS and _REFUSE_BREAKING.get():
        raise ParameterError(f"hs: Hs = {hs:g} m at Tp = {tp:g} s (peak wavelength "
                             f"{hs / steep:.4g} m) is steepness Hs / lambda_p = {steep:.3g}, "
                             f"past breaking (1/7); expected at most "
                             f"{tp * tp * 9.81 / (14 * math.pi):.4g} m")


def sea_steepness_warning(hs: float, tp: float) -> str | None:
    """The validity warning of a sea state steeper than :data:`STEEP_WARNING` (the regular
    wave's ``H / lambda`` warning, on ``Hs / lambda_p``), or None."""
    steep = sea_steepness(hs, tp)
    if steep <= STEEP_WARNING:
        return None
    return (f"linear theory: the sea's steepness Hs / lambda_p = {steep:.3g} exceeds "
            f"{STEEP_WARNING:.3g} (1/20; breaking at 1/7): its steepest waves' nonlinearity "
            "is left out")


def check_sea_state(hs, tp) -> tuple[float, float]:
    """``(hs, tp)`` checked: each in its range, and the sea not past breaking
    (:func:`check_sea_steepness`)."""
    hs = check_range("hs", hs, limits.SEA_MIN_HS, limits.SEA_MAX_HS,
                     why="significant wave height, m")
    tp = check_range("tp", tp, *limits.SEA_TP_RANGE, why="peak period, s")
    check_sea_steepness(hs, tp)
    return hs, tp


def _check_sea(hs, tp, spectrum, gamma_peak, repeat_period, cutoff):
    hs, tp = check_sea_state(hs, tp)
    gamma_peak, cutoff = check_spectrum(spectrum, gamma_peak, cutoff)
    if repeat_period is not None:
        repeat_period = check_positive("repeat-period", repeat_period)
        waves = repeat_period / tp
        if not limits.SEA_WAVES_RANGE[0] <= waves <= limits.SEA_WAVES_RANGE[1]:
            raise ParameterError(
                f"repeat-period: expected {limits.SEA_WAVES_RANGE[0]:g} to "
                f"{limits.SEA_WAVES_RANGE[1]:g} peak periods ({tp:g} s each), got "
                f"{repeat_period:g} s = {waves:.3g} periods")
    return hs, tp, gamma_peak, repeat_period, cutoff


def sea_record(units, *, hs: float = 2.0, tp: float = 8.0, spectrum: str = "jonswap",
               gamma_peak: float = 3.3, repeat_period: float | None = None, seed: int = 0,
               cutoff: float = 3.0, response=None) -> SeaExcitation:
    """Periodic random record of a sea state, as an excitation of the pendulum ``units``.

    Parameters
    ----------
    units : parapend.units.Units
        The pendulum (sets the time unit ``t0`` and ``g``).
    hs, tp : float
        Significant wave height (m) and peak period (s).
    spectrum : {"jonswap", "pierson-moskowitz"}
    gamma_peak : float
        JONSWAP peak enhancement factor (default 3.3).
    repeat_period : float or None
        ``T_r`` in s (default ``100 tp``: a record of about 100 waves).
    seed : int
        Seed of the random phases (``numpy.random.default_rng``).
    cutoff : float
        Highest component frequency, in units of ``fp = 1/tp`` (default 3).
    response : path or (f, gain, phase) arrays or None
        Heave response of the buoy; None: the base follows the surface (``z = eta``).
    """
    hs, tp, gamma_peak, repeat_period, cutoff = _check_sea(hs, tp, spectrum, gamma_peak,
                                                           repeat_period, cutoff)
    seed = check_int("seed", seed, 0, 2**63 - 1)
    tr = 100.0 * tp if repeat_period is None else repeat_period
    kmax = int(math.floor(cutoff * tr / tp))
    k = np.arange(kmax + 1)
    f = k / tr
    s = (jonswap(f, hs, tp, gamma_peak) if spectrum == "jonswap"
         else pierson_moskowitz(f, hs, tp))
    s[0] = 0.0
    amp = np.sqrt(2.0 * s / tr)
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0.0, 2 * math.pi, kmax + 1)
    eta = amp * np.exp(1j * phase)
    eta[0] = 0.0
    info = {"spectrum": spectrum, "hs": hs, "tp": tp, "repeat_period": tr, "seed": seed,
            "cutoff": cutoff, "components": kmax}
    if spectrum == "jonswap":
        info["gamma_peak"] = gamma_peak
    heave = eta
    if response is not None:
        if isinstance(response, (str, Path)):
            rf, rg, rp = read_response(response)
        else:
            try:
                rf, rg, rp = response
            except (TypeError, ValueError):
                raise ParameterError("response: expected a CSV path or three arrays (f, gain, "
                                     "phase)") from None
            rf, rg, rp = check_response(rf, rg, rp)
        gain = np.interp(f, rf, rg, left=0.0, right=0.0)
        ph = np.interp(f, rf, rp)
        heave = eta * gain * np.exp(1j * ph)
        info["response"] = str(response) if isinstance(response, (str, Path)) else "table"
    else:
        info["response"] = "none (base heave = surface elevation: a small buoy)"
    return _excitation(units, heave, tr, info)


def _excitation(units, heave: np.ndarray, tr: float, info: dict) -> SeaExcitation:
    omega = 2 * math.pi * units.time / tr
    if not limits.OMEGA_RANGE[0] / 10 <= omega:
        raise ParameterError(f"repeat-period: the record's fundamental omega_r = 2 pi t0 / T_r "
                             f"= {omega:.3g} is below {limits.OMEGA_RANGE[0] / 10:g} for this "
                             "pendulum; shorten the repeat period")
    q = _heave_to_q(heave, tr, units.gravity)
    if q.size - 1 > limits.SEA_MAX_COMPONENTS:
        raise ParameterError(f"repeat-period: {q.size - 1} components (at most "
                             f"{limits.SEA_MAX_COMPONENTS}); shorten the record or the cutoff")
    measured = "record" in info
    if not np.any(q[1:] != 0):
        if measured:
            raise ParameterError(f"record: the heave in {info['record']} has no variation "
                                 "below the cutoff; no motion of the base")
        raise ParameterError("response: the heave response is zero over the sea's "
                             "frequencies; no motion of the base")
    # the cap on q applies to q = z''/g as evaluated, whatever sets it (hs, the cutoff, the
    # response, g: sea --gravity 1e-3 gave max |q| = 2146)
    return check_excitation(
        SeaExcitation(omega, q, heave, info), "record" if measured else "sea",
        f" (q = z''/g of the {'record' if measured else 'sea record'} with g = "
        f"{units.gravity:g} m/s^2: {'a smaller cutoff' if measured else 'a smaller hs or cutoff'}"
        f", or a larger gravity)")


def measured_record(units, path, *, taper: float = 0.1, cutoff: float = 3.0) -> SeaExcitation:
    """A measured heave record, CSV ``t,z`` (s, m), made periodic (see the module docstring)."""
    taper = check_range("taper", taper, 0.0, 1.0, why="fraction of the record tapered")
    cutoff = check_range("cutoff", cutoff, 1.5, 10.0,
                         why="highest frequency kept, in units of the record's peak")
    rows = np.array(_csv_rows(path, ["t", "z"], "record", limits.SEA_MAX_RECORD_ROWS))
    if rows.shape[0] < 16:
        raise ParameterError(f"record: expected at least 16 rows 't,z' in {path}")
    t, z = rows[:, 0], rows[:, 1]
    if np.any(np.diff(t) <= 0):
        raise ParameterError(f"record: expected strictly increasing t in {path}")
    if np.max(np.abs(z)) > limits.SEA_MAX_HS:
        raise ParameterError(f"record: expected |z| <= {limits.SEA_MAX_HS:g} m in {path}")
    dt = float(np.median(np.diff(t)))
    span = (t[-1] - t[0]) / dt
    if not span < limits.SEA_MAX_RESAMPLED:  # before any allocation
        raise ParameterError(
            f"record: resampling {t[-1] - t[0]:.6g} s at the median spacing {dt:.4g} s needs "
            f"{span:.4g} points, more than {limits.SEA_MAX_RESAMPLED} (SEA_MAX_RESAMPLED) in "
            f"{path}; the record has gaps or uneven sampling: resample it uniformly")
    n = int(round(span)) + 1
    tu = t[0] + dt * np.arange(n)
    zu = np.interp(tu, t, z)
    zu = zu - zu.mean()
    if taper > 0:
        from scipy.signal.windows import tukey

        zu = zu * tukey(n, taper)
        zu = zu - zu.mean()
    tr = n * dt
    spec = np.fft.rfft(zu) / n
    heave = 2 * spec
    heave[0] = 0.0
    if n % 2 == 0:
        heave[-1] = spec[-1].real
    power = np.convolve(np.abs(heave) ** 2, np.ones(9) / 9, mode="same")
    kp = max(int(np.argmax(power[1:])) + 1, 1)
    kmax = min(heave.size - 1, int(math.floor(cutoff * kp)))
    heave = heave[:kmax + 1] * np.exp(-2j * math.pi * np.arange(kmax + 1) * t[0] / tr)
    info = {"record": str(path), "rows": int(rows.shape[0]), "sample_interval": dt,
            "repeat_period": tr, "taper": taper, "cutoff": cutoff,
            "peak_period": tr / kp, "components": kmax,
            "response": "none (the record is the base heave)"}
    return _excitation(units, heave, tr, info)
