"""The autoregressive forecast shrunk by its out-of-sample skill (docs/control.md,
"Forecasts")."""

from __future__ import annotations

import numpy as np
import pytest

from parapend.control import forecast as fc
from parapend.seas import sea_record
from parapend.units import Units

UNITS = Units(1.0, 10.0)
TP = 8.0 / UNITS.time  # the README's peak period in pendulum time
DELTA = TP / 12  # the forecast's default spacing


def _ar_process(a, n, seed, burn=500):
    """A seeded AR process ``x_k = sum a_i x_{k-i} + e_k`` (unit white noise ``e``)."""
    a = np.asarray(a, dtype=float)
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(n + burn)
    x = np.zeros(n + burn)
    for k in range(a.size, x.size):
        x[k] = a @ x[k - a.size:k][::-1] + e[k]
    return x[burn:]


def test_kstep_matrix_is_the_iterated_model():
    """Row k of the k-step map applied to the last p samples equals the model iterated k
    steps (a second implementation: the sample-by-sample recursion)."""
    a = np.array([1.5, -0.9, 0.2])
    x = _ar_process(a, 50, seed=1)
    c = fc.kstep_matrix(a, 12)
    assert np.allclose(c @ x[::-1][:3], fc._iterate(a, x, 12), rtol=0, atol=1e-12)
    assert np.array_equal(c[0], a)


def test_synthetic_ar_process_is_recovered_and_predicted_with_full_gain():
    """On a stable AR(2) oscillation with known coefficients the forecast's fit recovers
    them, the skill gains at the first steps are ~1 (the model is right, nothing to
    shrink), and the one-step forecast is the true conditional mean ``a . x`` to the fit's
    sampling error."""
    a_true = np.array([1.6, -0.8])
    n = 480  # the default window: 40 peak periods of 12 samples
    x = _ar_process(a_true, n, seed=11)
    t = DELTA * np.arange(n)
    f = fc.ARForecast(TP, order=2)
    a, hist = f.coefficients(t[-1], t, x)
    assert np.allclose(hist, x, atol=1e-12)
    assert np.max(np.abs(a - a_true)) < 0.08
    g = fc.skill_gains(hist, 2, 6)
    assert np.all(g[:2] > 0.85) and np.all(g <= 1.0)
    one = f.predict(t[-1], t, x, [DELTA])[0]
    assert one == pytest.approx(a_true @ x[::-1][:2], abs=0.15 * np.std(x))


def test_white_noise_has_no_skill_and_the_forecast_is_zero_beyond_lead_zero():
    """Unit white noise: nothing is predictable, every gain is 0, the forecast is the
    measured value at lead 0 and exactly 0 from one sample on."""
    rng = np.random.default_rng(5)
    x = rng.standard_normal(480)
    t = DELTA * np.arange(x.size)
    f = fc.ARForecast(TP)
    assert np.all(fc.skill_gains(x, 24, 24) == 0.0)
    lead = DELTA * np.arange(0, 25)
    p = f.predict(t[-1], t, x, lead)
    assert p[0] == pytest.approx(x[-1], abs=1e-12)
    assert np.all(np.abs(p[1:]) < 1e-12)
    # the plain iterated AR model does predict something (chance structure of the fit)
    plain = fc.ARForecast(TP, shrink=False).predict(t[-1], t, x, lead)
    assert np.max(np.abs(plain[1:])) > 0.01


def test_skill_gains_are_out_of_sample():
    """A window whose first half is a predictable AR(2) oscillation and whose second half
    is white noise: a model fitted on either half has no skill on the other, so every gain
    is 0 (an in-sample fit on the first half would claim skill), while the same
    oscillation throughout gives gains near 1, non-increasing with the lead."""
    osc = _ar_process([1.6, -0.8], 480, seed=2)
    noise = np.random.default_rng(3).standard_normal(240) * np.std(osc)
    mixed = np.concatenate((osc[:240], noise))
    assert np.all(fc.skill_gains(mixed, 2, 6) == 0.0)
    g = fc.skill_gains(osc, 2, 6)
    assert g[0] > 0.9
    assert np.all(np.diff(g) <= 0)  # non-increasing with the lead


def test_forecast_ignores_samples_after_t_now():
    """Causal: given samples beyond ``t_now`` (two different futures), the forecast is the
    one from the past alone, to the last bit."""
    exc = sea_record(UNITS, hs=2.0, tp=8.0, repeat_period=8.0 * 100, seed=0)
    other = sea_record(UNITS, hs=2.0, tp=8.0, repeat_period=8.0 * 100, seed=1)
    dt = TP / 64
    t = np.arange(0, 60 * TP, dt)
    q = exc.q(t)
    k = int(50 * TP / dt)
    q2 = q.copy()
    q2[k + 1:] = other.q(t[k + 1:])
    f = fc.ARForecast(TP)
    lead = np.linspace(0, 2 * TP, 17)
    past = f.predict(t[k], t[:k + 1], q[:k + 1], lead)
    assert np.array_equal(f.predict(t[k], t, q, lead), past)
    assert np.array_equal(f.predict(t[k], t, q2, lead), past)


def test_error_is_not_above_predicting_zero_and_below_the_plain_ar_at_long_leads():
    """README sea state, 100-wave record (seed 0), 40 origins from 45 peak periods on: the
    shrunk forecast's error (1 = predicting zero) stays within sampling of 1 at every lead
    and below it up to half a period, while the plain iterated AR model exceeds 1 beyond a
    period; at short leads the two agree."""
    exc = sea_record(UNITS, hs=2.0, tp=8.0, repeat_period=8.0 * 100, seed=0)
    leads = TP * np.array([0.1, 0.25, 0.5, 1.0, 2.0])
    kw = dict(t_start=45 * TP, t_end=exc.period, dt=TP / 64, leads=leads, origins=40)
    new = fc.prediction_error(fc.ARForecast(TP), exc.q, **kw)
    old = fc.prediction_error(fc.ARForecast(TP, shrink=False), exc.q, **kw)
    assert np.all(new[:3] < 0.8)
    assert np.all(new <= 1.02)
    assert np.all(old[3:] > 1.0)
    assert np.all(new[3:] < old[3:])
    assert np.allclose(new[:2], old[:2], rtol=0.1)


def test_prediction_error_of_zero_is_one():
    """The normalization: predicting 0 scores exactly 1 at every lead > 0."""

    class Zero:
        def predict(self, t_now, past_t, past_q, lead):
            return np.zeros(np.size(lead))

    exc = sea_record(UNITS, hs=2.0, tp=8.0, repeat_period=8.0 * 20, seed=0)
    err = fc.prediction_error(Zero(), exc.q, t_start=2 * TP, t_end=exc.period,
                              dt=TP / 64, leads=TP * np.array([0.3, 1.0]), origins=20)
    assert np.allclose(err, 1.0, rtol=0, atol=1e-12)


def test_the_controller_plans_no_further_than_the_forecast_reach():
    """mpc_run caps its horizon at a forecast's ``reach`` (ARForecast: ``reach_periods``
    peak periods); a forecast without one, or with None, keeps the horizon asked for."""
    from parapend.control.mpc import mpc_run

    class Calm:
        def __init__(self, reach):
            self.reach = reach

        def predict(self, t_now, past_t, past_q, lead):
            return np.zeros(np.size(lead))

    dt = 0.5
    kw = dict(gamma=0.01, horizon=20 * dt, update_interval=2 * dt, dt=dt, t_end=12 * dt,
              theta0=0.0, theta_dot0=1.0)  # rotating: the controller runs from the start
    q = lambda t: np.zeros(np.shape(t))  # noqa: E731
    assert mpc_run(q, forecast=Calm(5 * dt), **kw).horizon == pytest.approx(5 * dt)
    assert mpc_run(q, forecast=Calm(None), **kw).horizon == pytest.approx(20 * dt)
    assert fc.ARForecast(TP, reach_periods=0.5).reach == pytest.approx(0.5 * TP)
    assert fc.ARForecast(TP).reach is None


@pytest.mark.slow
def test_closed_loop_with_the_ar_forecast_is_positive_and_flat_beyond_its_reach():
    """The README's sea state on a 20-wave record (seed 0): the receding-horizon controller
    with the AR forecast extracts positive power at half a period and at two, and the two
    agree: beyond its skill the shrunk forecast is 0, and planning on a calm future the
    controller applies the same torque (the horizon is not capped, docs/control.md)."""
    import parapend

    r = parapend.horizon(repeat_period=160.0, horizons="0.5,2", forecasts="ar",
                         baselines="none")
    assert r.success
    assert r.mpc_horizon_used == [[0.5, 2.0]]
    p = np.asarray(r.mpc_power)[0, :, 0]
    assert np.all(p > 0.5 * r.optimum_power[0])
    assert abs(p[0] - p[1]) < 0.01 * p[0]


@pytest.mark.parametrize("kw, match", [({"reach_periods": 0.0}, "reach-periods"),
                                       ({"order": 24, "window": 10}, "window")])
def test_bad_options_are_one_line_errors(kw, match):
    from parapend.errors import ParameterError

    with pytest.raises(ParameterError, match=match):
        fc.ARForecast(TP, **kw)
