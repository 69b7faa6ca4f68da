"""``power-matrix --controller mpc``: the causal column beside the
non-causal optimum (of the prescribed-heave pendulum and of the heaving buoy), per bin the
best of the controller's run and rest, the annual energy of each column side by side, and
the incomplete site marked in every column.

Independent sources: the receding-horizon controller run by hand on the same record
(:func:`parapend.control.mpc.mpc_run` with the arguments written out here, and
:func:`parapend.control.horizon.horizon_curve`; for the buoy
:func:`parapend.hydro.control.buoy_mpc` on the record built from ``sea_record``), the
energy identity of Eq. 14 (no motion over a window harvests more than the ``gamma -> 0``
limit plus the boundary term), and the closed form ``AEP = 8766 h sum max(P, 0) f`` for
each column.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.performance import matrix_spec
from parapend.performance.annual import HOURS_PER_YEAR
from parapend.performance.causal import solve_causal

#: a small matrix: 2 x 2 bins, one 2-wave record each, a warm-up of half a peak period, a
#: plan every 1/16 peak period (a cheap run: the tests compare computations, not settings)
KW = {"hs": "1,2", "tp": "6,8", "realizations": 1, "waves": 2, "controller": "mpc",
      "forecast": "perfect", "warm_up": 0.5, "update_interval": 0.0625}
#: a site with a sea state outside the matrix (Hm0 4 m): the annual energy is incomplete
SERIES = "hs,tp\n1,6\n1,8\n2,6\n2,8\n2,8\n4,8\n"


def _by_hand(hs, tp, seed, *, waves=2, warm_up=0.5, horizon=1.0, update_interval=0.0625,
             plan_samples=2, gamma=0.01, forecast="perfect", speed_limit=4.0):
    """The causal run of one record written out: the record as ``sea`` builds it for the
    default pendulum (1 m, 10 kg), ``mpc_run`` from the hanging rest, 64 samples a peak
    period, the rated-speed penalty at 4 sqrt(g/l), the mean over one repeat after the
    warm-up; (storage-corrected, harvested) W,
    the units and the record."""
    from parapend.control.forecast import ARForecast
    from parapend.control.mpc import mpc_run
    from parapend.seas import sea_record
    from parapend.units import Units

    units = Units(1.0, 10.0, 9.81, None)
    exc = sea_record(units, hs=hs, tp=tp, repeat_period=waves * tp, seed=seed)
    tn = tp / units.time
    res = mpc_run(exc.q, gamma=gamma, horizon=horizon * tn, update_interval=update_interval * tn,
                  dt=tn / 64, average_from=warm_up * tn, t_end=exc.period + warm_up * tn,
                  seed=seed, interval_samples=plan_samples, speed_limit=speed_limit,
                  forecast=None if forecast == "perfect" else ARForecast(tn))
    assert res.success
    return (units.to_watts(res.mean_electrical_power),
            units.to_watts(res.harvested_electrical_power), units, exc)


@pytest.mark.parametrize("forecast", ["perfect", pytest.param("ar", marks=pytest.mark.slow)])
def test_a_record_is_the_controller_run_by_hand(forecast):
    """A bin's record (Hm0 2 m, Tp 8 s, realization 0, seed 5): the column's powers are
    those of ``mpc_run`` run by hand on the same record (same seed, same heave), to
    round-off, beside the optimum of ``sea`` on it."""
    from parapend.performance.solve import solve_bin

    spec = matrix_spec(**{**KW, "forecast": forecast, "seed": 5})
    got = solve_bin(spec, 1, 1, 0)
    p, w, *_ = _by_hand(2.0, 8.0, 5, forecast=forecast)
    assert got[f"causal_{forecast}_power"] == pytest.approx(p, rel=1e-12, abs=0)
    assert got[f"causal_{forecast}_harvested_power"] == pytest.approx(w, rel=1e-12, abs=0)
    s = parapend.sea(hs=2.0, tp=8.0, repeat_period=16.0, seed=5)
    assert got["power"] == pytest.approx(s.power_w, rel=1e-12)


@pytest.mark.slow
def test_every_bin_of_the_matrix_is_the_controller_run_by_hand():
    """Through the engine (store, statistics, the Dataset): each bin's causal power and
    its causal power matrix are ``mpc_run`` by hand on the bin's record."""
    ds = parapend.power_matrix(**KW, workers=1).dataset
    for i, hs in enumerate((1.0, 2.0)):
        for j, tp in enumerate((6.0, 8.0)):
            p, w, *_ = _by_hand(hs, tp, 0)
            assert ds["causal_perfect_power"].values[i, j, 0] == pytest.approx(p, rel=1e-12)
            assert ds["causal_perfect_power_mean"].values[i, j] == pytest.approx(p, rel=1e-12)
            assert ds["causal_perfect_power_matrix"].values[i, j] == pytest.approx(
                max(p, 0.0), rel=1e-12)
            assert ds["causal_perfect_mode"].values[i, j] == (1 if p > 0 else 0)


def test_a_record_is_horizon_curve():
    """One record's causal power is that of ``parapend horizon`` on the same record (the
    same planner, 2 torque samples an interval)."""
    spec = matrix_spec(**{**KW, "seed": 3})
    got = solve_causal(spec, 0, 1, 0)
    ref = parapend.horizon(hs=1.0, tp=8.0, repeat_period=16.0, seed=3, horizons="1",
                           forecasts="perfect", baselines="none", warm_up=0.5,
                           update_interval=0.0625, speed_limit=4.0)
    assert got["causal_perfect_power"] == pytest.approx(ref.mpc_power_w[0][0][0],
                                                        rel=1e-12, abs=0)


@pytest.mark.parametrize("i, j", [(0, 0), (1, 1)])
def test_causal_never_beats_what_the_sea_allows(i, j):
    """The invariant. Eq. 14's energy balance gives, for any motion over a window of length
    ``tau``, ``W + dE = int (q sin(theta) theta' - gamma theta'^2) dt <= [-q cos(theta)] +
    int |q'| dt``: so the storage-corrected causal power is at most the record's
    ``gamma -> 0`` limit ``TV(q) / T_r`` plus ``2 max|q| / tau`` (units ``m g l``), over
    one repeat ``tau = T_r``. Against the non-causal optimum (the best periodic motion of
    the record) no exact bound holds for a motion that is not periodic: the causal power
    exceeds it by at most the storage term ``|P - P_harvested|`` (the change of stored
    energy per unit time) plus the boundary term ``2 max|q| / tau``."""
    from parapend.performance.check import _record, _units
    from parapend.performance.solve import solve_bin

    spec = matrix_spec(**KW)
    got = solve_bin(spec, i, j, 0)
    units = _units(spec)
    exc = _record(spec, units, i, j, 0)
    qmax = float(np.max(np.abs(exc.q(np.linspace(0, exc.period, 4097)))))
    boundary = units.to_watts(2 * qmax / exc.period)
    p = got["causal_perfect_power"]
    stored = abs(p - got["causal_perfect_harvested_power"])
    assert p <= got["limit_power"] + boundary
    assert p <= got["power"] + stored + boundary


def _stub(causal_power):
    """solve_bin with the optimum 1 + i + j W, the limit 10 W and the causal column
    ``causal_power[i][j]`` (harvested: the same), without a solve."""
    def solve_bin(spec, i, j, r):
        out = {"power": 1.0 + i + j, "limit_power": 10.0, "uniform_power": 0.5,
               "status": "converged"}
        for f in spec.forecasts:
            out[f"causal_{f}_power"] = out[f"causal_{f}_harvested_power"] = \
                causal_power[i][j] * (0.9 if f == "ar" else 1.0)
        return out
    return solve_bin


@pytest.fixture
def stubbed(monkeypatch, tmp_path):
    """``parapend.power_matrix`` at ``KW`` (both forecasts) with the solve stood in by
    :func:`_stub`, on the site ``SERIES`` (incomplete) or a complete scatter."""
    import parapend.performance.solve as solve

    def run(causal_power, complete=False):
        monkeypatch.setattr(solve, "solve_bin", _stub(causal_power))
        site = tmp_path / "site.csv"
        if complete:
            site.write_text("hs,tp,frequency\n1,6,0.25\n1,8,0.25\n2,6,0.25\n2,8,0.25\n")
            where = {"scatter": str(site)}
        else:
            site.write_text(SERIES)
            where = {"timeseries": str(site)}
        return parapend.power_matrix(**{**KW, "forecast": "perfect,ar"}, workers=1,
                                     rated_power=20.0, netcdf=str(tmp_path / "m.nc"),
                                     **where)
    return run


def test_aep_of_each_column_is_8766_h_sum_p_f_and_incomplete_everywhere(stubbed):
    """Each column's annual energy is ``8766 h sum max(P, 0) f`` over the bins, the
    uncounted share (the sea state outside) bounds it at 0 (and nothing bounds it above: no
    upper bound), and every column says incomplete: in the JSON, the NetCDF variables and
    the text."""
    import xarray as xr

    rec = stubbed([[0.5, 1.5], [1.9, 2.0]])
    ds, out = rec.dataset, rec.to_dict()
    f = np.array([[1, 1], [1, 2]]) / 6.0
    assert np.allclose(ds["frequency"].values, f)
    cols = {"optimum": "power_matrix", "causal_perfect": "causal_perfect_power_matrix",
            "causal_ar": "causal_ar_power_matrix"}
    with xr.open_dataset(out["netcdf"]) as nc:
        assert nc["column"].attrs["flag_meanings"].split() == list(cols)
        assert nc["column"].values.tolist() == [0, 1, 2]
        for k, (col, var) in enumerate(cols.items()):
            p = ds[var].values
            lo = HOURS_PER_YEAR * float(np.sum(p * f)) / 1e6
            e = out["causal"]["annual_energy"][col]
            assert e["complete"] is False and e["annual_energy_mwh"] is None
            assert e["annual_energy_mwh_bounds"][0] == pytest.approx(lo, rel=1e-12)
            assert e["annual_energy_mwh_bounds"][1] is None
            assert e["capacity_factor"] is None
            assert e["capacity_factor_bounds"][0] == pytest.approx(
                lo * 1e6 / (HOURS_PER_YEAR * 20.0), rel=1e-12)
            assert e["capacity_factor_bounds"][1] is None
            assert math.isnan(nc["annual_energy"].values[k])
            assert nc["annual_energy_complete"].values[k] == 0
            assert nc["annual_energy_lower"].values[k] == pytest.approx(lo, rel=1e-12)
            assert math.isnan(nc["annual_energy_upper"].values[k])
            assert math.isnan(nc["capacity_factor"].values[k])
        assert nc["annual_energy_lower"].attrs["units"] == "MWh"
        assert nc["causal_perfect_power_mean"].attrs["units"] == "W"
    assert out["annual_energy"]["causal_ar_power"]["complete"] is False
    assert out["hours_per_year"] == HOURS_PER_YEAR
    json.dumps(out["causal"])  # plain JSON
    from parapend.performance.figures import text_report

    text = text_report(ds, out, [])
    assert "annual energy side by side (8766 h/yr):" in text
    side = text.split("annual energy side by side (8766 h/yr):\n")[1].splitlines()[:3]
    assert ["(incomplete, no upper bound)" in line for line in side] == [True] * 3
    assert "causal power matrix, autoregressive forecast" in text


def test_a_losing_controller_rests_and_the_aep_is_never_negative(stubbed):
    """Where the controller's mean power is negative the bin rests: 0 W in the causal power
    matrix and the annual energy, the choice recorded; the stored per-record powers keep
    their sign. On a complete site each column is one plain number, 8766 h sum max(P, 0) f."""
    rec = stubbed([[-3.0, 1.5], [1.9, -0.1]], complete=True)
    ds, out = rec.dataset, rec.to_dict()
    assert ds["causal_perfect_power_mean"].values[0, 0] == -3.0
    assert ds["causal_perfect_power_matrix"].values.tolist() == [[0.0, 1.5], [1.9, 0.0]]
    assert out["causal"]["mode"]["perfect"] == [["rest", "controller"], ["controller", "rest"]]
    for k, (col, q) in enumerate((("optimum", "power"),
                                  ("causal_perfect", "causal_perfect_power"),
                                  ("causal_ar", "causal_ar_power"))):
        want = HOURS_PER_YEAR * 0.25 * float(np.sum(np.maximum(ds[f"{q}_mean"].values, 0)))
        assert out["annual_energy"][q]["wh"] == pytest.approx(want, rel=1e-12)
        e = out["causal"]["annual_energy"][col]
        assert e["complete"] is True
        assert e["annual_energy_mwh"] == pytest.approx(want / 1e6, rel=1e-12)
        assert e["capacity_factor"] == pytest.approx(want / (HOURS_PER_YEAR * 20.0),
                                                     rel=1e-12)
        assert ds["annual_energy"].values[k] >= 0


def test_a_bin_without_a_causal_result_makes_only_its_column_incomplete(stubbed, tmp_path):
    """A failed causal run (NaN) in the only record of a bin: that bin has no causal result,
    so the causal columns' annual energies are incomplete (bounds with the bin's share at 0
    and at the bin's own bound, its gamma -> 0 limit: 10 W) while the optimum's stays
    complete; the text says how many runs failed."""
    from parapend.performance.figures import text_report

    rec = stubbed([[1.0, 1.5], [1.9, math.nan]], complete=True)
    ds, out = rec.dataset, rec.to_dict()
    assert ds["causal_perfect_mode"].values[1, 1] == -1
    assert ds["causal_perfect_power_count"].values[1, 1] == 0
    side = out["causal"]["annual_energy"]
    assert side["optimum"]["complete"] is True
    for col in ("causal_perfect", "causal_ar"):
        p = ds[f"{col}_power_matrix"].values
        lo = HOURS_PER_YEAR * 0.25 * float(np.nansum(p))
        hi = lo + HOURS_PER_YEAR * 0.25 * 10.0
        assert side[col]["complete"] is False and side[col]["annual_energy_mwh"] is None
        assert side[col]["annual_energy_mwh_bounds"] == pytest.approx([lo / 1e6, hi / 1e6],
                                                                      rel=1e-12)
    assert ds["annual_energy_complete"].values.tolist() == [1, 0, 0]
    # the Zarr export reads back without a warning (filterwarnings = error)
    import xarray as xr

    from parapend.performance import _write_zarr

    _write_zarr(ds, tmp_path / "m.zarr")
    with xr.open_zarr(tmp_path / "m.zarr", consolidated=False) as z:
        assert z["annual_energy_complete"].values.tolist() == [1, 0, 0]
        assert z["column"].attrs["flag_meanings"] == "optimum causal_perfect causal_ar"
    text = text_report(ds, out, [])
    assert "1 of 4 causal runs failed" in text
    assert "1 bins without a causal result" in text


def test_the_store_identity_without_a_controller_is_unchanged():
    """A matrix without the controller writes the spec it wrote before (a store resumes);
    with it, the settings are part of the identity and read back."""
    from parapend.performance.spec import MatrixSpec

    plain = matrix_spec(hs="1,2", tp="6,8")
    assert "controller" not in json.loads(plain.to_json())
    assert "causal_perfect_power" not in plain.variables
    spec = matrix_spec(hs="1,2", tp="6,8", controller="mpc", forecast="ar,perfect",
                       horizon=1.5)
    assert MatrixSpec.from_json(spec.to_json()) == spec
    assert spec.speed_limit == 4.0
    assert matrix_spec(hs="1,2", tp="6,8", controller="mpc",
                       speed_limit=math.inf).speed_limit is None
    assert spec.forecasts == ("perfect", "ar") and spec.horizon == 1.5
    assert matrix_spec(hs="1,2", tp="6,8", controller="mpc").horizon == 1.0
    assert spec.update_interval == 0.03125 and spec.warm_up == 4.0 and spec.plan_samples == 2


def test_the_work_is_capped_in_one_line():
    """The causal runs count in the cap on the solves: 400 bins x 1000 records fit the
    optimum alone, not with the causal column (a record's runs count as 3.5 solves)."""
    from parapend.performance.check import MAX_SOLVES, check_size

    kw = {"hs": "1:3:20", "te": "6:10:20", "realizations": 1000}
    assert check_size(matrix_spec(**kw), workers=1, available=1 << 40)["solves"] < MAX_SOLVES
    with pytest.raises(ParameterError, match=r"^realizations: at most 1000000 solves' work"):
        check_size(matrix_spec(**kw, controller="mpc"), workers=1, available=1 << 40)


@pytest.mark.parametrize("extra, needle", [
    (["--controller", "mpc", "--device", "buoy", "--plan-samples", "4"],
     "plan-samples: an option of the prescribed-heave pendulum's planner"),
    (["--controller", "mpc", "--device", "buoy", "--speed-limit", "4"],
     "speed-limit: an option of the prescribed-heave pendulum's planner"),
    (["--controller", "mpc", "--device", "buoy", "--update-interval", "0.01"],
     "update-interval: expected at least one torque sample"),
    (["--controller", "mpc", "--device", "buoy", "--horizon", "0.1"],
     "update-interval: expected at most the horizon 0.1"),
    (["--forecast", "ar"], "forecast: an option of the causal column; needs --controller"),
    (["--controller", "mpc", "--forecast", "oracle"], "forecast: expected perfect, ar"),
    (["--controller", "mpc", "--forecast", "ar,ar"], "forecast: expected perfect, ar"),
    (["--controller", "mpc", "--horizon", "0.01"], "horizon: expected"),
    (["--controller", "mpc", "--update-interval", "2"], "update-interval: expected"),
    (["--controller", "mpc", "--warm-up", "-1"], "warm-up: expected"),
    (["--controller", "mpc", "--plan-samples", "0"], "plan-samples: expected"),
    (["--warm-up", "2"], "warm-up: an option of the causal column"),
    (["--speed-limit", "4"], "speed-limit: an option of the causal column"),
    (["--controller", "mpc", "--speed-limit", "0"], "speed-limit: expected"),
])
def test_bad_causal_options_one_line_exit_2(extra, needle, capsys):
    code = main(["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "1",
                 "--waves", "3", "--workers", "1", *extra])
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert needle in err, err


class _PeekingForecast:
    """A tampered forecast: the record's own future at the leads asked for, plus a trace of
    it one horizon further on (a controller that looks further ahead than it says)."""

    reach = None

    def __init__(self, q, horizon):
        self.q, self.horizon = q, horizon

    def predict(self, t_now, past_t, past_q, leads):
        t = t_now + np.asarray(leads, dtype=float)
        return self.q(t) + 1e-3 * self.q(t + self.horizon)


def _torques(q, t0_periods, forecast, *, horizon=0.5, tamper_after=None):
    """The held torques before ``t0`` of a short causal run (4 peak periods of the README's
    sea state) driven by ``q``, or by ``q`` altered from ``tamper_after`` on (peak
    periods); ``forecast``: "perfect", "ar" or "peek" (:class:`_PeekingForecast`)."""
    from parapend.control.forecast import ARForecast
    from parapend.control.mpc import mpc_run
    from parapend.units import Units

    tn = 8.0 / Units(1.0, 10.0, 9.81, None).time
    qq = q
    if tamper_after is not None:
        def qq(t):
            t = np.asarray(t, dtype=float)
            return q(t) + np.where(t > tamper_after * tn, 0.05 * np.cos(3.0 * t), 0.0)
    fo = {"perfect": None, "ar": ARForecast(tn) if forecast == "ar" else None,
          "peek": _PeekingForecast(qq, horizon * tn)}[forecast]
    res = mpc_run(qq, gamma=0.01, horizon=horizon * tn, update_interval=tn / 16,
                  dt=tn / 64, t_end=4 * tn, forecast=fo)
    return res.torque[: int(round(t0_periods * 64))]


@pytest.mark.parametrize("forecast, after, causal", [
    ("perfect", 2.5, True),   # altered after t0 + H: nothing before t0 changes
    ("ar", 2.0, True),        # the AR forecast reads the past only: altered after t0
    ("peek", 2.5, False),     # a controller that looks further ahead fails the test
])
def test_torques_before_t0_ignore_the_sea_after_t0_plus_h(forecast, after, causal):
    """Causality (the acceptance, on the pendulum's controller that the causal
    column runs): altering the sea only after ``t0 + H`` (perfect forecast; after ``t0``
    with the AR one) leaves every torque held before ``t0`` bit-identical; a tampered
    forecast that peeks one horizon further fails the same check. t0 = 2 peak periods,
    H = 0.5."""
    from parapend.seas import sea_record
    from parapend.units import Units

    exc = sea_record(Units(1.0, 10.0, 9.81, None), hs=2.0, tp=8.0, repeat_period=80.0,
                     seed=1)
    a = _torques(exc.q, 2.0, forecast)
    b = _torques(exc.q, 2.0, forecast, tamper_after=after)
    assert a.size == 128 and np.any(a != 0)
    assert np.array_equal(a, b) is causal


# --- the buoy (--device buoy): parapend.hydro.control.buoy_mpc on the optimum's record -------

#: the buoy's small matrix (the sphere of tests/test_performance_buoy.py): 2 x 2 bins, one
#: 4-wave record each, a warm-up of one peak period
BUOY_KW = {"device": "buoy", "hs": "0.1,0.2", "tp": "2.6,3.0", "realizations": 1,
           "waves": 4, "seed": 7, "mass": 20.0, "length": 0.3, "damping_coefficient": 0.5,
           "harmonics": 24, "controller": "mpc", "warm_up": 1.0}


@pytest.fixture(scope="module")
def buoy_bin(sphere_nc):
    """The bin Hs 0.2 m, Tp 3 s of the buoy's matrix, solved as the matrix solves it."""
    from parapend.performance.solve import solve_bin

    spec = matrix_spec(**BUOY_KW, forecast="perfect,ar", hydro=sphere_nc)
    return spec, solve_bin(spec, 1, 1, 0)


@pytest.mark.slow  # the sphere's BEM (10 s, once a module), then solves
def test_a_buoy_bin_is_buoy_mpc_by_hand(buoy_bin, sphere_nc):
    """A buoy bin's causal powers are :func:`parapend.hydro.control.buoy_mpc` run by hand on
    the record the buoy's optimum solves (built here from ``sea_record``, as
    tests/test_performance_buoy.py builds it), with the column's settings written out: the
    default controller (``plan``, one solve an update), horizon 2 and a plan every 1/8 peak
    period (as ``parapend buoy --controller mpc``), the warm-up, one repeat, the perfect and
    the AR forecast; to round-off."""
    from parapend.hydro.bem import load
    from parapend.hydro.control import buoy_mpc
    from parapend.hydro.coupled import Pendulum, Wave
    from parapend.seas import sea_record
    from parapend.units import Units

    spec, got = buoy_bin
    assert spec.buoy_controller == "plan" and spec.horizon == 2.0
    assert spec.update_interval == 0.125 and spec.forecasts == ("perfect", "ar")
    pend = Pendulum(mass=20.0, length=0.3, inertia=20.0 * 0.3**2, damping_coefficient=0.5)
    exc = sea_record(Units(0.3, 20.0, 9.81, pend.inertia), hs=0.2, tp=3.0,
                     repeat_period=4 * 3.0, seed=7)
    wave = Wave(2 * math.pi / (4 * 3.0), np.asarray(exc.heave[1:], dtype=complex))
    for forecast in ("perfect", "ar"):
        r = buoy_mpc(load(sphere_nc), pend, wave, peak_period=3.0, horizon=2.0,
                     update_interval=0.125, warmup=1.0, repeats=1, forecast=forecast,
                     controller="plan", iterations=1)
        # a loss is a measurement the matrix keeps (the bin then rests)
        assert r.status in ("ok", "loses_energy") and r.forecast == forecast
        assert r.t_end_s - r.average_from_s == pytest.approx(12.0, rel=1e-9)  # one repeat
        assert got[f"causal_{forecast}_power"] == pytest.approx(r.mean_power_w, rel=1e-12,
                                                                abs=0)
        assert got[f"causal_{forecast}_harvested_power"] == pytest.approx(
            r.harvested_power_w, rel=1e-12, abs=0)
        # storage-corrected: the stored energy of buoy and pendulum counted
        assert r.mean_power_w == pytest.approx(r.harvested_power_w + r.stored_w, rel=1e-12)
    # the AR forecast knows less: it harvests differently (not the perfect run again)
    assert got["causal_ar_power"] != got["causal_perfect_power"]


def _buoy_stub(causal_power):
    """The buoy's solve_bin with the optimum 1 + i + j W and the causal column
    ``causal_power[i][j]`` (harvested: the same), without a solve."""
    def solve_bin(spec, i, j, r):
        return {"power": 1.0 + i + j, "radiation_bound_power": 10.0, "one_way_power": 0.5,
                "causal_perfect_power": causal_power[i][j],
                "causal_perfect_harvested_power": causal_power[i][j], "status": "converged"}
    return solve_bin


@pytest.mark.slow  # the sphere's BEM (10 s, once a module), then solves
def test_the_buoy_column_rests_its_aep_is_8766_h_sum_p_f(monkeypatch, sphere_nc, tmp_path):
    """The buoy's causal column: a bin where the controller loses rests (0 W, the choice
    recorded), each column's annual energy is ``8766 h sum max(P, 0) f`` and never negative,
    and the controller that ran is named in the JSON, the text and the NetCDF."""
    import xarray as xr

    import parapend.performance.solve as solve
    from parapend.performance.figures import text_report

    monkeypatch.setattr(solve, "solve_bin", _buoy_stub([[-3.0, 1.5], [1.9, -0.1]]))
    site = tmp_path / "site.csv"
    site.write_text("hs,tp,frequency\n0.1,2.6,0.25\n0.1,3.0,0.25\n0.2,2.6,0.25\n"
                    "0.2,3.0,0.25\n")
    rec = parapend.power_matrix(**BUOY_KW, hydro=sphere_nc, workers=1, scatter=str(site),
                                netcdf=str(tmp_path / "m.nc"))
    ds, out = rec.dataset, rec.to_dict()
    assert ds["causal_perfect_power_matrix"].values.tolist() == [[0.0, 1.5], [1.9, 0.0]]
    assert out["causal"]["mode"]["perfect"] == [["rest", "controller"],
                                                ["controller", "rest"]]
    assert out["causal"]["buoy_controller"] == "plan"
    assert out["causal"]["plan_samples"] is None and out["causal"]["speed_limit"] is None
    for col, q in (("optimum", "power"), ("causal_perfect", "causal_perfect_power")):
        want = HOURS_PER_YEAR * 0.25 * float(np.sum(np.maximum(ds[f"{q}_mean"].values, 0)))
        assert out["annual_energy"][q]["wh"] == pytest.approx(want, rel=1e-12)
        e = out["causal"]["annual_energy"][col]
        assert e["complete"] is True and e["annual_energy_mwh"] >= 0
        assert e["annual_energy_mwh"] == pytest.approx(want / 1e6, rel=1e-12)
    with xr.open_dataset(out["netcdf"]) as nc:
        assert nc.attrs["causal_buoy_controller"] == "plan"
        assert "causal_plan_samples" not in nc.attrs
        assert nc["annual_energy"].values.tolist() == pytest.approx(
            [out["causal"]["annual_energy"][c]["annual_energy_mwh"]
             for c in ("optimum", "causal_perfect")], rel=1e-12)
    report = text_report(ds, out, [])
    assert "the buoy's plan controller)" in report
    assert "causal power matrix, perfect forecast" in report


@pytest.mark.slow  # the sphere's BEM (10 s, once a module), then solves
def test_the_buoy_column_runs_coupled_with_an_efficiency(sphere_nc, monkeypatch):
    """The plan controller prices no losses: with an efficiency the column runs the coupled
    one (which does), whichever is the column's default, and says so."""
    from parapend.performance import causal

    for default in ("coupled", "plan"):
        monkeypatch.setattr(causal, "BUOY_CONTROLLER", default)
        spec = matrix_spec(**BUOY_KW, hydro=sphere_nc, efficiency=0.8)
        assert spec.buoy_controller == "coupled" and spec.horizon == 1.0
        plain = matrix_spec(**BUOY_KW, hydro=sphere_nc)
        assert plain.buoy_controller == default
        assert plain.horizon == {"plan": 2.0, "coupled": 1.0}[default]


@pytest.mark.slow  # the sphere's BEM (10 s, once a module), then solves
def test_the_buoy_column_is_estimated_and_a_tiny_time_limit_marks_a_partial(buoy_bin,
                                                                            sphere_nc):
    """Untimed work estimated past two minutes is refused in one line naming the largest
    size that fits (the causal runs counted); a tiny ``time_limit`` finishes one bin, the
    same as the full computation's, and marks the matrix partial."""
    from parapend.performance.check import check_size, record_seconds

    big = {**BUOY_KW, "waves": 400, "hydro": sphere_nc}
    est = check_size(matrix_spec(**big), workers=1)
    assert est["causal_seconds"] == pytest.approx(record_seconds(matrix_spec(**big)))
    assert est["seconds"] > 120
    # not even the fewest bins fit: the advice is fewer --waves (it said "at most 1 bins",
    # which the command refuses)
    with pytest.raises(ParameterError, match=r"^waves: a power matrix of 4 bins .* not even 4 "
                                             r"bins .* or give --time-limit SECONDS"):
        parapend.power_matrix(**big, workers=1)
    spec, got = buoy_bin
    rec = parapend.power_matrix(**BUOY_KW, hydro=sphere_nc, workers=1, time_limit=1e-9)
    ds = rec.dataset
    assert ds.attrs["status"] == "time_limit" and ds.attrs["bins_finished"] == 1
    p = ds["causal_perfect_power_mean"].values
    # the dearest bin goes first (the higher sea: Hs 0.2 m; the records are all 4 waves)
    i, j = divmod(spec.block_order()[0], len(spec.period))
    assert (i, j) == (1, 0)
    assert np.isfinite(p).sum() == 1 and np.isfinite(p[i, j])
    from parapend.performance.solve import solve_bin

    assert p[i, j] == solve_bin(spec, i, j, 0)["causal_perfect_power"]


def test_the_shifted_q_is_the_records_q_to_round_off():
    """The perfect forecast's cheaper ``q`` (:class:`parapend.performance.causal.ShiftedQ`:
    the leads' exponentials kept, one matrix-vector product an update) against the record's
    own ``q`` (the direct sum) along a 50-wave record: equal to the round-off of the phase
    ``k w t`` (``k w t`` reaches 1e3 rad here: 1e-13 of ``q``'s scale); scalars, short and
    long arrays and offset sets beyond the kept ones are the direct sum itself."""
    from parapend.performance.causal import ShiftedQ
    from parapend.seas import sea_record
    from parapend.units import Units

    units = Units(1.0, 10.0, 9.81, None)
    exc = sea_record(units, hs=2.0, tp=8.0, repeat_period=400.0, seed=2)
    tn = 8.0 / units.time
    sq = ShiftedQ(exc, tn)
    leads = np.sort(np.random.default_rng(0).uniform(0.0, tn, 300))
    scale = float(np.max(np.abs(exc.q(np.linspace(0, exc.period, 4001)))))
    for tj in np.linspace(0.0, exc.period, 37):
        got, ref = sq(tj + leads), exc.q(tj + leads)
        assert np.max(np.abs(got - ref)) < 1e-12 * scale
    assert len(sq.cache) == 1  # one offset set, built once
    assert sq(1.5) == exc.q(1.5)
    assert np.array_equal(sq(np.linspace(0, 3, 7)), exc.q(np.linspace(0, 3, 7)))
    long = np.linspace(0, 30, 9000)
    assert np.array_equal(sq(long), exc.q(long))
    for k in range(ShiftedQ.KEEP + 2):
        t = 10.0 + leads * (1.0 + 0.01 * k)
        assert np.max(np.abs(sq(t) - exc.q(t))) < 1e-12 * scale
    assert len(sq.cache) == ShiftedQ.KEEP
