"""Forecasts, causal baselines and the horizon curve (docs/control.md, "Forecasts, baselines
and the horizon curve")."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.control import baselines as bl
from parapend.control import forecast as fc
from parapend.control import horizon as hz
from parapend.errors import ParameterError
from parapend.seas import sea_record
from parapend.units import Units

UNITS = Units(1.0, 10.0)
TP = 8.0 / UNITS.time  # the README's peak period in pendulum time


def _record(seed=0, waves=100, gamma_peak=3.3):
    return sea_record(UNITS, hs=2.0, tp=8.0, gamma_peak=gamma_peak,
                      repeat_period=8.0 * waves, seed=seed)


# --- forecasts -----------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["ls", "yw"])
def test_ar_fit_recovers_the_coefficients_of_a_synthetic_ar_process(method):
    """x_k = 1.6 x_{k-1} - 0.8 x_{k-2} + 0.3 x_{k-3} ... (stable, seeded): the fit on 20000
    samples recovers the coefficients to the sampling error (~ 1/sqrt(n))."""
    a_true = np.array([1.5, -0.9, 0.2])
    rng = np.random.default_rng(7)
    n = 20000
    x = np.zeros(n + 200)
    e = rng.standard_normal(x.size)
    for k in range(3, x.size):
        x[k] = a_true @ x[k - 3:k][::-1] + e[k]
    a = fc.fit_ar(x[200:], 3, method)
    assert np.max(np.abs(a - a_true)) < 0.03
    assert fc._stable(a_true) and fc._stable(a)


def test_ar_fit_refuses_too_short_a_series():
    with pytest.raises(ParameterError, match="order"):
        fc.fit_ar(np.ones(10), 8)


def test_perfect_forecast_is_the_record_itself():
    exc = _record(waves=10)
    f = fc.PerfectForecast(exc.q)
    lead = np.linspace(0, 3 * TP, 11)
    assert np.array_equal(f.predict(40.0, None, None, lead), exc.q(40.0 + lead))


def test_ar_forecast_error_is_zero_at_lead_zero_grows_and_beats_persistence():
    """On a narrow-banded JONSWAP record (peak enhancement 7): the normalized rms error is
    0 at lead 0, grows with the lead over the first quarter period, stays below 1 there,
    and is below that of persistence (q(t + L) = q(t), computed directly)."""
    exc = _record(seed=3, gamma_peak=7.0, waves=100)
    leads = TP * np.array([0.0, 0.05, 0.1, 0.25])
    dt = TP / 64
    err = fc.prediction_error(fc.ARForecast(TP), exc.q, t_start=45 * TP,
                              t_end=exc.period, dt=dt, leads=leads, origins=25)
    assert err[0] < 1e-12
    assert np.all(np.diff(err) > 0)
    assert np.all(err < 1.0)
    t = np.arange(45 * TP, exc.period - TP, dt)
    q = exc.q(t)
    rms = math.sqrt(float(np.mean(exc.q(np.arange(0, exc.period, dt)) ** 2)))
    for lead, e in zip(leads[1:], err[1:]):
        pers = math.sqrt(float(np.mean((exc.q(t + lead) - q) ** 2))) / rms
        assert e < pers


def test_ar_forecast_is_causal_and_persists_before_its_window_fills():
    exc = _record(waves=100)
    dt = TP / 64
    t = np.arange(0, 60 * TP, dt)
    q = exc.q(t)
    f = fc.ARForecast(TP)
    k = int(50 * TP / dt)
    lead = np.linspace(0, TP, 9)
    p1 = f.predict(t[k], t[:k + 1], q[:k + 1], lead)
    q2 = q.copy()
    q2[k + 1:] = 0.0  # the future changed: same forecast
    p2 = f.predict(t[k], t[:k + 1], q2[:k + 1], lead)
    assert np.array_equal(p1, p2)
    assert p1[0] == pytest.approx(q[k], abs=1e-12)
    early = f.predict(t[10], t[:11], q[:11], lead)  # too short a past: persistence
    assert np.allclose(early, q[10] * np.exp(-lead / (fc.PERSISTENCE * TP)))


@pytest.mark.parametrize("kw, match", [({"order": 0}, "order"), ({"window": 0.5}, "window"),
                                       ({"order": 200, "window": 2}, "window")])
def test_ar_forecast_bad_options(kw, match):
    with pytest.raises(ParameterError, match=match):
        fc.ARForecast(TP, **kw)


# --- baselines -----------------------------------------------------------------------------
def test_extremum_rule_on_a_sinusoid_is_positive_below_the_limit():
    """q = d sin(w t): two half-turns per period (plus the first), power positive and below
    the limit w TV(q) / 2 pi = 2 |d| w / pi (docs/limit.md), and at least 0.6 of it."""
    w, d = 0.25, 0.2
    r = bl.extremum_baseline(lambda t: d * np.sin(w * np.asarray(t)), peak_omega=w,
                             gamma=0.01, t_end=20 * 2 * math.pi / w)
    lim = 2 * d * w / math.pi
    assert r.success and r.info["half_turns"] == 41
    assert 0.6 * lim < r.mean_power < lim
    assert r.mean_power == pytest.approx(-np.sum(r.torque[:-1] * np.diff(r.theta)) / r.t[-1],
                                         rel=1e-12)


def test_extremum_rule_series_reintegrates_and_is_causal():
    """The saved series, each interval integrated again from its saved state with its
    saved torque held by SciPy's DOP853, reproduces the next saved state; a run on a record
    changed after t1 is the same up to t1 (causal)."""
    from scipy.integrate import solve_ivp

    exc = _record(waves=6)
    r = bl.extremum_baseline(exc.q, peak_omega=2 * math.pi / TP, gamma=0.01,
                             t_end=exc.period, torque_limit=2.0)
    assert np.max(np.abs(r.torque)) <= 2.0
    worst = 0.0
    for k in range(0, r.t.size - 1, 7):
        sol = solve_ivp(lambda t, y, u=r.torque[k]: [y[1], (1 + exc.q(t)) * math.sin(y[0])
                                                      - 0.01 * y[1] + u],
                        (r.t[k], r.t[k + 1]), [r.theta[k], r.theta_dot[k]], method="DOP853",
                        rtol=1e-11, atol=1e-12)
        worst = max(worst, abs(sol.y[0, -1] - r.theta[k + 1]))
    assert worst < 1e-7
    t1 = exc.period / 2

    def changed(t):
        t = np.asarray(t, dtype=float)
        return np.where(t <= t1 + 1e-9, exc.q(t), 0.0)

    r2 = bl.extremum_baseline(changed, peak_omega=2 * math.pi / TP, gamma=0.01,
                              t_end=exc.period, torque_limit=2.0)
    k1 = int(np.searchsorted(r.t, t1))
    assert np.array_equal(r.theta[:k1], r2.theta[:k1])
    assert np.array_equal(r.torque[:k1], r2.torque[:k1])


def test_electrical_work_applies_the_efficiency_both_ways():
    w = bl.electrical_work(np.array([-1.0, 1.0, 0.0, 0.0]), np.array([0.0, 2.0, 3.0, 3.0]),
                           (0.8, 0.5))
    assert np.allclose(w, [1.6, -2.0, 0.0])  # generating 2 * 0.8; motoring -1 / 0.5


def test_tracker_baseline_on_a_short_record():
    exc = _record(waves=6)
    r = bl.tracker_baseline(exc.q, peak_omega=2 * math.pi / TP, gamma=0.01,
                            t_end=exc.period)
    assert r.success and r.info["periods"] == 6
    assert r.info["design_status"] == "converged"
    rms = math.sqrt(0.5 * float(np.sum(np.abs(exc.spec) ** 2)))
    assert r.info["design_delta"] == pytest.approx(-math.sqrt(2) * rms, rel=2e-2)
    assert math.isfinite(r.mean_power)


# --- the horizon curve ---------------------------------------------------------------------
def test_horizon_baselines_only_cli_json_save_plot(tmp_path, capsys):
    import xarray as xr

    from tests.figure_checks import all_problems

    nc, png = tmp_path / "h.nc", tmp_path / "h.png"
    argv = ["horizon", "--repeat-period", "48", "--forecasts", "none", "--baselines",
            "extremum", "--records", "2", "--save", str(nc), "--plot", str(png), "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["seeds"] == [0, 1] and out["forecasts"] == []
    api = parapend.horizon(repeat_period=48.0, forecasts="none", baselines="extremum",
                           records=2)
    assert api.baseline_power == out["baseline_power"]
    opt = api.optimum_power
    assert opt[1] == pytest.approx(parapend.sea(repeat_period=48.0, seed=1).power, rel=1e-12)
    for r in range(2):
        run = bl.extremum_baseline(_record(seed=r, waves=6).q, peak_omega=2 * math.pi / TP,
                                   gamma=0.01, t_end=_record(seed=r, waves=6).period)
        # storage-corrected: the harvested energy plus the change of the stored energy
        # E = theta'^2/2 + cos(theta) over the record, per unit time
        de = (0.5 * run.theta_dot[-1] ** 2 + math.cos(run.theta[-1])
              - 0.5 * run.theta_dot[0] ** 2 - math.cos(run.theta[0]))
        corrected = (np.sum(run.work) + de) / run.t[-1]
        assert out["baseline_harvested_power"][0][r] == pytest.approx(run.mean_power,
                                                                       rel=1e-12)
        assert out["baseline_stored_energy_change"][0][r] == pytest.approx(de, abs=1e-12)
        assert out["baseline_power"][0][r] == pytest.approx(corrected, rel=1e-12)
        assert out["baseline_fraction"][0][r] == pytest.approx(corrected / opt[r],
                                                               rel=1e-12)
        assert corrected < out["limit_power"][r]
    ds = xr.open_dataset(nc)
    assert np.allclose(ds["baseline_power"].values, out["baseline_power"], rtol=1e-15)
    ds.close()
    assert all_problems(hz.plot_horizon(api)) == []
    assert png.stat().st_size > 1000


def test_horizon_fractions_and_wiring_with_a_stub_controller(monkeypatch):
    """The horizon loop passes the horizon in pendulum time and each forecast through, and
    divides by the record's optimum: checked with a stub in place of mpc_run."""
    from parapend.control import mpc

    seen = []

    class Res:
        success, status = True, "ok"

    def stub(q, *, horizon, forecast, t_end, **kw):
        seen.append((horizon, None if forecast is None else forecast.name))
        r = Res()
        r.mean_electrical_power = horizon / 1000.0
        r.harvested_electrical_power = horizon / 1000.0 - 1e-4
        r.stored_energy_change = 0.5
        r.failed_solves = 1
        r.update_times = np.array([9.0, 1e-3, 2e-3, 3e-3])
        reach = getattr(forecast, "reach", None)  # as mpc_run: plans over at most the reach
        r.horizon = horizon if reach is None else min(horizon, reach)
        return r

    monkeypatch.setattr(mpc, "mpc_run", stub)
    r = parapend.horizon(repeat_period=48.0, horizons="0.5,2", baselines="none")
    assert seen == [(0.5 * TP, None), (2 * TP, None), (0.5 * TP, "ar"), (2 * TP, "ar")]
    assert r.mpc_fraction[1][1][0] == pytest.approx(2 * TP / 1000 / r.optimum_power[0],
                                                    rel=1e-12)
    assert r.ar_leads[0] == 0 and r.ar_error[0] < 1e-12
    assert np.allclose(r.mpc_horizon_used, [[0.5, 2.0], [0.5, 2.0]], rtol=1e-12)
    # the storage account and the timing of every run are passed through; the first update
    # of the first record is reported apart, the others pooled
    assert r.mpc_stored_energy_change[0][1] == [0.5]
    assert r.mpc_harvested_power[0][1][0] == pytest.approx(2 * TP / 1000 - 1e-4)
    assert r.mpc_failed_solves == [[[1], [1]], [[1], [1]]]
    assert r.mpc_update_time_first[0][0] == 9.0 and r.mpc_update_time_max[0][0] == 3e-3
    assert r.mpc_update_time_median[0][0] == 2e-3
    assert r.update_interval_s == pytest.approx(0.03125 * 8.0) and r.realtime_fits is True


@pytest.mark.parametrize("argv, match", [
    (["--horizons", "0.5,x"], "horizons"), (["--horizons", "0"], "horizons"),
    (["--forecasts", "oracle"], "forecasts"), (["--baselines", "lqr"], "baselines"),
    (["--forecasts", "none", "--baselines", "none"], "forecasts"),
    (["--records", "0"], "records"), (["--update-interval", "2"], "update-interval"),
    (["--torque-limit", "0"], "torque-limit"), (["--save", "h.csv"], "save"),
    (["--gamma", "0.1", "--damping-coefficient", "1"], "gamma")])
def test_horizon_bad_input_is_one_line_exit_2(argv, match, capsys):
    assert main(["horizon", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and match in err


@pytest.mark.slow
def test_horizon_with_the_controller_on_a_short_record():
    """End to end with the receding-horizon controller: perfect forecast at 1 and 2 peak
    periods on a 6-wave record; finite powers below the limit, every run finished."""
    r = parapend.horizon(repeat_period=48.0, horizons="1,2", forecasts="perfect",
                         baselines="extremum")
    assert r.success
    p = np.asarray(r.mpc_power)
    assert np.all(np.isfinite(p)) and np.all(p < r.limit_power[0])
