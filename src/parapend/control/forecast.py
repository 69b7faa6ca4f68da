r"""Wave forecasts for the receding-horizon controller: perfect and autoregressive.

A forecast answers ``predict(t_now, past_t, past_q, lead_times)``: the excitation ``q`` at
``t_now + lead_times`` (non-dimensional time), knowing only the samples ``past_q`` of ``q``
at the times ``past_t <= t_now``.

- :class:`PerfectForecast`: the record's own future (non-causal; the upper bound of every
  forecast).
- :class:`ARForecast`: an autoregressive model of ``q`` fitted on the past only, the standard
  predictor of wave-energy control (Fusco and Ringwood, *Short-term wave forecasting for
  real-time control of wave energy converters*, IEEE Trans. Sustain. Energy 1(2), 2010).
  The past is resampled at the spacing ``Delta = Tp / samples_per_period`` over a sliding
  window of ``window`` peak periods; the model

      q_k = a_1 q_{k-1} + ... + a_p q_{k-p} + e_k

  is fitted by least squares on that window (every call: the sea may change), iterated
  ``ceil(lead / Delta)`` steps ahead, and the predicted samples are joined to the past by
  a cubic spline through the last past samples and the predicted ones, so that the
  forecast at lead 0 is the measured ``q(t_now)``. A least-squares fit whose companion
  matrix has a root outside the unit circle (a prediction that would grow without bound)
  is replaced by the Yule-Walker fit, which is stable by construction.

The defaults (``samples_per_period = 12``, ``order = 24``, ``window = 40`` peak periods)
come from the error scan of :func:`prediction_error` on the JONSWAP record of ``sea``
(docs/control.md): a twelfth of a period puts the record's cutoff of 3 fp below the
Nyquist frequency (6 fp) and keeps the spline's error at short leads small (an eighth
gave 0.08 at a lead of 0.05 Tp against 0.03); an order of two peak periods was the best
of 8 to 36 coefficients at a quarter and half a period; 40 periods of window (480
samples for 24 coefficients) beat 10, 20 and 30 at every lead, and stay well below the
record's repeat, so the model cannot memorize the record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_int, check_range

__all__ = ["ARForecast", "PerfectForecast", "fit_ar", "make_forecast", "prediction_error",
           "FORECASTS"]

#: forecasts by name (``--forecast``)
FORECASTS = ("perfect", "ar")


@dataclass(frozen=True)
class PerfectForecast:
    """The record's own future: ``q(t_now + lead)`` read off the record ``q`` (a vectorized
    callable of non-dimensional time). Non-causal: what a perfect forecast gives."""

    q: object
    name: str = "perfect"

    def predict(self, t_now, past_t, past_q, lead_times) -> np.ndarray:
        return np.asarray(self.q(float(t_now) + np.asarray(lead_times, dtype=float)),
                          dtype=float)


def fit_ar(x, order: int, method: str = "ls") -> np.ndarray:
    """Coefficients ``a_1, ..., a_p`` of ``x_k = sum_i a_i x_{k-i} + e_k`` fitted to ``x``.

    ``method``: "ls" (least squares on every complete lag vector in ``x``) or "yw"
    (Yule-Walker: the biased autocovariance, a Toeplitz solve; the model is stable).
    """
    from scipy.linalg import solve_toeplitz

    x = np.asarray(x, dtype=float)
    p = int(order)
    if x.size < 2 * p + 1:
        raise ParameterError(f"order: expected at least {2 * p + 1} samples for an AR({p}) "
                             f"fit, got {x.size}")
    if method == "ls":
        # rows: x_{k-1} .. x_{k-p} for k = p .. n-1
        lags = np.lib.stride_tricks.sliding_window_view(x[:-1], p)[:, ::-1]
        a, *_ = np.linalg.lstsq(lags, x[p:], rcond=None)
        return a
    if method == "yw":
        n = x.size
        r = np.array([np.dot(x[: n - j], x[j:]) / n for j in range(p + 1)])
        if r[0] <= 0:
            return np.zeros(p)
        return solve_toeplitz(r[:p], r[1:])
    raise ParameterError(f"method: expected 'ls' or 'yw', got {method!r}")


def _stable(a) -> bool:
    """All roots of ``z^p - a_1 z^(p-1) - ... - a_p`` strictly inside the unit circle."""
    roots = np.roots(np.concatenate(([1.0], -np.asarray(a))))
    return bool(np.all(np.abs(roots) < 1.0))


def _iterate(a, history, steps: int) -> np.ndarray:
    """``steps`` predicted samples after ``history`` (oldest first) with AR coefficients."""
    p = a.size
    buf = list(history[-p:])
    out = np.empty(steps)
    for s in range(steps):
        v = float(np.dot(a, buf[::-1][:p]))
        out[s] = v
        buf.append(v)
        buf.pop(0)
    return out


@dataclass(frozen=True)
class ARForecast:
    """Autoregressive forecast of ``q`` fitted on a sliding window of the past (module
    docstring).

    Parameters
    ----------
    peak_period : float
        ``Tp`` in non-dimensional time (``2 pi / omega_p``).
    order : int
        ``p``, the number of AR coefficients.
    window : float
        Length of the fitting window, in peak periods.
    samples_per_period : int
        Samples of the model per peak period (``Delta = Tp / samples_per_period``).
    """

    peak_period: float
    order: int = 24
    window: float = 40.0
    samples_per_period: int = 12
    name: str = "ar"

    def __post_init__(self):
        check_range("peak-period", self.peak_period, 1e-6, 1e6)
        check_int("order", self.order, 1, 256)
        check_range("window", self.window, 1.0, 400.0)
        check_int("samples-per-period", self.samples_per_period, 2, 256)
        if self.window * self.samples_per_period < 2 * self.order + 1:
            raise ParameterError(
                f"window: expected at least {2 * self.order + 1} samples "
                f"(window x samples-per-period) for an AR({self.order}) fit, got "
                f"{self.window * self.samples_per_period:g}")

    @property
    def spacing(self) -> float:
        return self.peak_period / self.samples_per_period

    def coefficients(self, t_now, past_t, past_q):
        """``(a, history)``: the coefficients fitted on the window ending at ``t_now`` and
        the resampled past (oldest first, the last sample at ``t_now``); ``a`` is None when
        the past is too short for a fit."""
        past_t = np.asarray(past_t, dtype=float)
        past_q = np.asarray(past_q, dtype=float)
        d = self.spacing
        n_max = int(round(self.window * self.samples_per_period))
        span = float(t_now) - float(past_t[0]) if past_t.size else 0.0
        n = min(n_max, int(math.floor(span / d + 1e-9)) + 1)
        if n < 1 or past_t.size < 2:
            return None, np.array([float(past_q[-1])] if past_q.size else [0.0])
        grid = float(t_now) - d * np.arange(n - 1, -1, -1)
        hist = np.interp(grid, past_t, past_q)
        if n < 2 * self.order + 1 + self.order:
            return None, hist
        a = fit_ar(hist, self.order, "ls")
        if not _stable(a):
            a = fit_ar(hist, self.order, "yw")
        return a, hist

    def predict(self, t_now, past_t, past_q, lead_times) -> np.ndarray:
        """``q`` at ``t_now + lead_times`` (leads >= 0) from the past samples alone. Before
        the window holds enough samples for a fit, the forecast is ``q(t_now)`` decaying
        to the record's mean 0 over a peak period (a persistence forecast)."""
        from scipy.interpolate import CubicSpline

        lead = np.asarray(lead_times, dtype=float)
        if np.any(lead < -1e-12):
            raise ParameterError("lead_times: expected leads >= 0")
        a, hist = self.coefficients(t_now, past_t, past_q)
        q_now = float(hist[-1])
        if a is None:
            return q_now * np.exp(-np.clip(lead, 0.0, None) / self.peak_period)
        d = self.spacing
        steps = max(1, int(math.ceil(float(np.max(lead, initial=0.0)) / d - 1e-9)))
        pred = _iterate(a, hist, steps)
        back = min(hist.size, 4)
        knots = d * np.arange(-back + 1, steps + 1)
        vals = np.concatenate((hist[-back:], pred))
        return CubicSpline(knots, vals)(np.clip(lead, 0.0, None))


def make_forecast(name: str, q, peak_period: float, **ar_options):
    """The forecast called ``name`` ("perfect" or "ar") for the record ``q`` (callable)."""
    if name == "perfect":
        return PerfectForecast(q)
    if name == "ar":
        return ARForecast(peak_period, **ar_options)
    raise ParameterError(f"forecast: expected one of {', '.join(FORECASTS)}, got {name!r}")


def prediction_error(forecast, q, *, t_start: float, t_end: float, dt: float, leads,
                     origins: int = 200) -> np.ndarray:
    """Normalized rms prediction error of ``forecast`` at each lead time.

    ``q`` (vectorized callable) is sampled every ``dt`` from 0; at ``origins`` forecast
    times evenly spread over ``[t_start, t_end - max(leads)]`` the forecast sees the samples
    up to that time and predicts ``q`` at every lead. Returns
    ``sqrt(mean (q_hat - q)^2) / rms(q)`` per lead (``rms`` over the whole sampled span).
    """
    leads = np.asarray(leads, dtype=float)
    t_all = np.arange(0.0, t_end + dt / 2, dt)
    q_all = np.asarray(q(t_all), dtype=float)
    rms = math.sqrt(float(np.mean(q_all**2)))
    last = t_end - float(np.max(leads))
    if last <= t_start:
        raise ParameterError("leads: the longest lead leaves no forecast origin in "
                             f"[{t_start:g}, {t_end:g}]")
    t0s = np.linspace(t_start, last, int(origins))
    sq = np.zeros(leads.size)
    for t0 in t0s:
        k = int(math.floor(t0 / dt + 1e-9))
        t_now = t_all[k]
        pred = forecast.predict(t_now, t_all[: k + 1], q_all[: k + 1], leads)
        sq += (pred - np.asarray(q(t_now + leads), dtype=float)) ** 2
    return np.sqrt(sq / t0s.size) / rms
