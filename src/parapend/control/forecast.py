r"""Wave forecasts for the receding-horizon controller: perfect and autoregressive.

A forecast answers ``predict(t_now, past_t, past_q, lead_times)``: the excitation ``q`` at
``t_now + lead_times`` (non-dimensional time), knowing only the samples ``past_q`` of ``q``
at the times ``past_t <= t_now``.

- :class:`PerfectForecast`: the record's own future (non-causal; the upper bound of every
  forecast).
- :class:`ARForecast`: an autoregressive model of ``q`` fitted on the past only, the standard
  predictor of wave-energy control (Fusco and Ringwood, *Short-term wave forecasting for
  real-time control of wave energy converters*, IEEE Trans. Sustain. Energy 1(2), 2010),
  shrunk toward 0 at the leads where it has no skill.
  The past is resampled at the spacing ``Delta = Tp / samples_per_period`` over a sliding
  window of ``window`` peak periods; the model

      q_k = a_1 q_{k-1} + ... + a_p q_{k-p} + e_k

  is fitted by least squares on that window (every call: the sea may change), and its
  ``k``-step prediction (the model iterated ``k`` steps, :func:`kstep_matrix`) is
  multiplied by a gain ``g_k`` in [0, 1] estimated out of sample on the same window
  (:func:`skill_gains`: a model fitted on one half of the window predicts the other half;
  ``g_k`` is the least-squares gain of those predictions, 0 from the first lead where
  they improve on predicting 0 by less than ``MIN_SKILL = 0.1``, so non-increasing). So
  the forecast is the AR prediction where the past shows it has skill and decays to the
  mean 0 where it has none, instead of predicting waves that are not there. The predicted
  samples are joined to the past by a cubic spline through the last past samples and the
  predicted ones, so that the forecast at lead 0 is the measured ``q(t_now)``. A
  least-squares fit whose companion matrix has a root outside the unit circle (a
  prediction that would grow without bound) is replaced by the Yule-Walker fit, which is
  stable by construction. On a window shorter than ``6 order`` samples the order is a
  sixth of the window (three samples per coefficient in each half), and below
  ``MIN_ORDER`` coefficients (3 peak periods at the defaults) the forecast is persistence
  decaying over ``PERSISTENCE`` peak periods.
  A finite ``reach_periods`` caps the horizon the receding-horizon controller plans over
  (default none: with the gains the forecast is 0 where it has no skill, and the controller
  gets the same power at every horizon, docs/control.md).

The defaults (``samples_per_period = 12``, ``order = 24``, ``window = 40`` peak periods)
come from the error scan of :func:`prediction_error` on the JONSWAP record of ``sea``
(docs/control.md): a twelfth of a period puts the record's cutoff of 3 fp below the
Nyquist frequency (6 fp) and keeps the spline's error at short leads small (an eighth
gave 0.08 at a lead of 0.05 Tp against 0.03); an order of two peak periods was the best
of 8 to 36 coefficients at a quarter and half a period; 40 periods of window (480
samples for 24 coefficients) beat 10, 20 and 30 at every lead, and stay well below the
record's repeat, so the model cannot memorize the record. ``shrink=False`` gives the
plain iterated AR prediction (no gains), for comparison.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_int, check_range

__all__ = ["ARForecast", "PerfectForecast", "fit_ar", "kstep_matrix", "make_forecast",
           "prediction_error", "skill_gains", "FORECASTS"]

#: smallest AR order fitted (below it, on a short window, the forecast is persistence)
MIN_ORDER = 6
#: decay time of the persistence forecast (before the first fit), in peak periods: of 1,
#: 1/4, 1/8, 1/16 and 1/32 on the README's records, the longest whose error is within 1 %
#: of predicting 0 at every lead (1/8: 1.07 at a quarter period; 1: 1.53)
PERSISTENCE = 1.0 / 16

#: smallest out-of-sample skill ``1 - sum (p - y)^2 / sum y^2`` of a lead kept in the forecast
MIN_SKILL = 0.1
#: score the skill on both halves of the window (False: the second half only)
TWO_FOLDS = True

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


def kstep_matrix(a, steps: int) -> np.ndarray:
    """The ``k``-step predictors of the AR model ``a`` as rows ``c_k`` (``k`` from 1 to ``steps``).

    ``x_{t+k}`` is predicted as ``c_k`` times ``(x_t, x_{t-1}, ..., x_{t-p+1})`` by iterating
    the model: the ``k``-step predictor as a linear
    map of the last ``p`` samples (the first row of the companion matrix to the power k)."""
    a = np.asarray(a, dtype=float)
    p = a.size
    # rows[i]: the coefficients of x_{t-p+1+i} in terms of the last p samples
    rows = list(np.eye(p)[::-1])
    out = np.empty((int(steps), p))
    for k in range(int(steps)):
        new = np.zeros(p)
        for i in range(p):
            new += a[i] * rows[-1 - i]
        out[k] = new
        rows.append(new)
    return out


def _lags(x, p: int) -> np.ndarray:
    """Rows ``(x_t, x_{t-1}, ..., x_{t-p+1})`` for ``t = p-1 .. n-1``."""
    return np.lib.stride_tricks.sliding_window_view(np.asarray(x, dtype=float), p)[:, ::-1]


def _fit_stable(x, order: int) -> np.ndarray:
    a = fit_ar(x, order, "ls")
    return a if _stable(a) else fit_ar(x, order, "yw")


def skill_gains(history, order: int, steps: int) -> np.ndarray:
    """Gain ``g_k`` in [0, 1] of the ``k``-step AR prediction (``k`` from 1 to ``steps``),
    estimated out of sample on ``history`` (oldest first) alone.

    Two folds: an AR(``order``) model fitted on the first half of ``history`` predicts,
    from every origin in the second half, each sample up to ``steps`` ahead that the history
    holds; one fitted on the second half predicts the first half backward in time (a
    stationary process has the same AR model forward and backward). Per step, over the
    pooled predictions ``p`` and samples ``y``: the least-squares gain ``g_k = sum(p y) /
    sum(p^2)``, clipped to [0, 1]; 0 from the first step where the predictions improve on
    predicting zero by less than ``MIN_SKILL`` (``sum (p - y)^2 > (1 - MIN_SKILL) sum
    y^2``) or fewer than ``order`` origins reach it. So the gains are non-increasing with
    the lead, and a chance correlation at a long lead does not bring the forecast back.
    """
    x = np.asarray(history, dtype=float)
    n = x.size
    h = n // 2
    steps = int(steps)
    g = np.zeros(steps)
    if h < 2 * order + 1:
        return g
    folds = [(x[:h], x)]  # fitted on the first half, scored forward on the second
    if TWO_FOLDS:
        # and fitted on the second half, scored on the first half backward in time (a
        # stationary process has the same AR model forward and backward)
        folds.append((x[n - h:][::-1], x[::-1]))
    pairs = []
    for train, seq in folds:
        a = _fit_stable(train, order)
        lag = _lags(seq, order)[h - order:]  # origins t = h - 1 .. n - 1 of seq
        pairs.append((lag @ kstep_matrix(a, steps).T, seq))
    for k in range(steps):
        pk, yk = [], []
        for pred, seq in pairs:
            m = pred.shape[0] - (k + 1)  # origins whose k+1-step target is in seq
            if m >= order:
                pk.append(pred[:m, k])
                yk.append(seq[h + k: h + k + m])
        if not pk:
            break
        pk, yk = np.concatenate(pk), np.concatenate(yk)
        den = float(pk @ pk)
        if den <= 0.0 or float((pk - yk) @ (pk - yk)) >= (1.0 - MIN_SKILL) * float(yk @ yk):
            break
        g[k] = min(1.0, max(0.0, float(pk @ yk) / den))
    return np.minimum.accumulate(g)


@dataclass(frozen=True)
class ARForecast:
    """Autoregressive forecast of ``q`` fitted on a sliding window of the past (module
    docstring).

    Parameters
    ----------
    peak_period : float
        ``Tp`` in non-dimensional time (``2 pi / omega_p``).
    order : int
        ``p``, the number of AR coefficients (fewer on a short window, :meth:`order_for`).
    window : float
        Length of the fitting window, in peak periods.
    samples_per_period : int
        Samples of the model per peak period (``Delta = Tp / samples_per_period``).
    shrink : bool
        Multiply each lead's prediction by its out-of-sample skill gain
        (:func:`skill_gains`); False: the plain iterated AR prediction.
    reach_periods : float or None
        The forecast's reach in peak periods: the receding-horizon controller
        (:func:`parapend.control.mpc.mpc_run`) plans over at most this long (``reach``).
        None (default): no cap.
    """

    peak_period: float
    order: int = 24
    window: float = 40.0
    samples_per_period: int = 12
    shrink: bool = True
    reach_periods: float | None = None
    name: str = "ar"

    def __post_init__(self):
        check_range("peak-period", self.peak_period, 1e-6, 1e6)
        check_int("order", self.order, 1, 256)
        check_range("window", self.window, 1.0, 400.0)
        check_int("samples-per-period", self.samples_per_period, 2, 256)
        if self.reach_periods is not None:
            check_range("reach-periods", self.reach_periods, 0.01, 100.0)
        if self.window * self.samples_per_period < 6 * self.order:
            raise ParameterError(
                f"window: expected at least {6 * self.order} samples "
                f"(window x samples-per-period) for an AR({self.order}) fit, got "
                f"{self.window * self.samples_per_period:g}")

    @property
    def reach(self):
        """The reach in non-dimensional time (``reach_periods * peak_period``), or None."""
        return None if self.reach_periods is None else self.reach_periods * self.peak_period

    @property
    def spacing(self) -> float:
        return self.peak_period / self.samples_per_period

    def order_for(self, samples: int) -> int:
        """The AR order used on a window of ``samples`` samples: ``order``, or a sixth of
        the window while it is shorter than ``6 order`` (so that each half of the window,
        :func:`skill_gains`, holds three samples per coefficient); 0 (no fit, persistence)
        below ``MIN_ORDER``."""
        p = min(self.order, int(samples) // 6)
        return p if p >= min(MIN_ORDER, self.order) else 0

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
        p = self.order_for(n)
        if p == 0:
            return None, hist
        return _fit_stable(hist, p), hist

    def predict(self, t_now, past_t, past_q, lead_times) -> np.ndarray:
        """``q`` at ``t_now + lead_times`` (leads >= 0) from the past samples alone. Before
        the window holds enough samples for a fit, the forecast is ``q(t_now)`` decaying
        to the record's mean 0 over ``PERSISTENCE`` peak periods (a persistence forecast)."""
        from scipy.interpolate import CubicSpline

        lead = np.asarray(lead_times, dtype=float)
        if np.any(lead < -1e-12):
            raise ParameterError("lead_times: expected leads >= 0")
        a, hist = self.coefficients(t_now, past_t, past_q)
        q_now = float(hist[-1])
        if a is None:
            return q_now * np.exp(-np.clip(lead, 0.0, None) / (PERSISTENCE * self.peak_period))
        d = self.spacing
        steps = max(1, int(math.ceil(float(np.max(lead, initial=0.0)) / d - 1e-9)))
        pred = kstep_matrix(a, steps) @ hist[::-1][:a.size]
        if self.shrink:
            pred = pred * skill_gains(hist, a.size, steps)
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
    times ``t_i`` evenly spread over ``[t_start, t_end - max(leads)]`` the forecast sees the
    samples up to that time and predicts ``q`` at every lead ``L``. Returns, per lead,
    ``sqrt(sum_i (q_hat_i - q(t_i + L))^2 / sum_i q(t_i + L)^2)``: the rms error over the
    rms of the predicted values, so that predicting 0 scores exactly 1 at every lead > 0
    (at lead 0 the forecasts here return the measured ``q``: error 0).
    """
    leads = np.asarray(leads, dtype=float)
    t_all = np.arange(0.0, t_end + dt / 2, dt)
    q_all = np.asarray(q(t_all), dtype=float)
    last = t_end - float(np.max(leads))
    if last <= t_start:
        raise ParameterError("leads: the longest lead leaves no forecast origin in "
                             f"[{t_start:g}, {t_end:g}]")
    t0s = np.linspace(t_start, last, int(origins))
    sq = np.zeros(leads.size)
    ref = np.zeros(leads.size)
    for t0 in t0s:
        k = int(math.floor(t0 / dt + 1e-9))
        t_now = t_all[k]
        pred = forecast.predict(t_now, t_all[: k + 1], q_all[: k + 1], leads)
        true = np.asarray(q(t_now + leads), dtype=float)
        sq += (pred - true) ** 2
        ref += true**2
    return np.sqrt(sq / np.where(ref > 0, ref, 1.0))
