"""``parapend power-matrix --device buoy --dofs surge,heave,pitch``: each bin's record solved
as ``parapend buoy --dofs surge,heave,pitch --hs --tp --repeat-period --seed`` solves it
(checked against ``parapend.buoy`` run by hand, slow), the store's layout and the annual
energy's invariant (fast: the hull's solve replaced by a stand-in, everything else real),
every refusal in one line before any bin runs, and ``--dofs heave`` unchanged.

The hull is the synthetic one of tests/test_hull_cli.py, as a ``--hydro`` dataset."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from hull_timedomain import RHO_V, synthetic_hull

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro import api as hull_api
from parapend.hydro.bem import HullHydro
from parapend.performance import HOURS_PER_YEAR, matrix_spec, power_matrix
from parapend.performance.resource import repeat_period
from parapend.performance.spec import MatrixSpec

PEND = {"mass": 4000.0, "length": 1.0, "inertia": 5000.0, "damping_coefficient": 50.0,
        "pivot_height": 1.5, "pivot_offset": 1.0}
HULL = {"device": "buoy", "dofs": "surge,heave,pitch", **PEND}
BINS = {"hs": "1,2", "tp": "5,6", "waves": 2.0, "seed": 3}


def _save(path, **kw):
    from capytaine.io.xarray import save_dataset_as_netcdf

    h = synthetic_hull(**kw)
    hull = HullHydro(omega=h["omega_data"], added_mass=h["A"], radiation_damping=h["B"],
                     excitation=h["F"], hydrostatic_stiffness=h["C"], mass=RHO_V,
                     pitch_inertia=float(h["Mh"][2, 2]), description="synthetic hull")
    save_dataset_as_netcdf(path, hull.to_dataset())
    return str(path)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return _save(tmp_path_factory.mktemp("hull") / "hull.nc")


@pytest.fixture(scope="module")
def scatter(tmp_path_factory):
    """A site over the 2 x 2 bins (shares summing to 1)."""
    path = tmp_path_factory.mktemp("site") / "scatter.csv"
    rows = [(1, 5, 0.4), (1, 6, 0.3), (2, 5, 0.2), (2, 6, 0.1)]
    path.write_text("hs,tp,frequency\n" + "".join(f"{h},{t},{f}\n" for h, t, f in rows))
    return str(path), {(h, t): f for h, t, f in rows}


# -- the stand-in for the hull's solve (fast tests) --------------------------------------------

def _stand_in(real):
    """``solve_record`` with the checks real and the solve replaced: the power a function
    of the record (its sum |a_k|^2, so bins and seeds differ), rest below a threshold,
    swinging for the longer records, the rotation reversed on odd seeds."""

    def fake(problem, wave, info, *, check_only=False):
        if check_only:
            return real(problem, wave, info, check_only=True)
        e = float(np.sum(np.abs(np.asarray(wave.amplitudes)) ** 2))
        long = 2 * math.pi / wave.omega > 11.0
        mode = "rest" if e < 0.5 else "swinging" if long else "rotation"
        p = 0.0 if mode == "rest" else 1e4 * e
        loss = 0.9 if problem["pto"].copper_loss else 1.0
        winding = 0 if mode != "rotation" else -1 if info["seed"] % 2 else 1
        return SimpleNamespace(power_w=loss * p, mechanical_power_w=p, mode=mode,
                               winding=winding,
                               success=True, modes=[], radiation_bound_w=1e5 * e,
                               one_way_power_w=None if mode == "rest" else 2e4 * e)
    return fake


@pytest.fixture
def stand_in(monkeypatch):
    monkeypatch.setattr(hull_api, "solve_record", _stand_in(hull_api.solve_record))


def _energy(spec, i, j, r):
    from parapend.performance.buoy_device import wave_of

    wave, _ = wave_of(spec, i, j, r)
    return float(np.sum(np.abs(np.asarray(wave.amplitudes)) ** 2))


def test_the_store_holds_each_records_answer_and_the_aep_invariant(dataset, scatter,
                                                                   stand_in):
    """Per realization: the best mode's power (0 at rest), its mode, the bound, the one-way
    power (NaN at rest); the power matrix max(mean, 0); the annual energy is 8766 h x
    sum(P f) over the site's bins, summed here independently."""
    path, freq = scatter
    # (the size estimate is the embedded barge's, 100 s a record: a time limit lets this
    # small hull's matrix run; it finishes well inside it, not partial)
    ds, annual, _, _ = power_matrix(**BINS, realizations=2, hydro=dataset, scatter=path,
                                    workers=1, time_limit=3600, **HULL)
    assert ds.attrs.get("status", "ok") == "ok"
    spec = MatrixSpec.from_json(ds.attrs["sweep"])
    assert spec.dofs == "surge,heave,pitch" and spec.pivot_height == 1.5
    modes = {"rest": 0, "rotation": 1, "swinging": 2, "rotation, reversed": 3}
    seen = set()
    for i in range(2):
        for j in range(2):
            for r in range(2):
                e = _energy(spec, i, j, r)
                mode = "rest" if e < 0.5 else "swinging" if j == 1 else (
                    "rotation, reversed" if (3 + r) % 2 else "rotation")
                seen.add(mode)
                p = 0.0 if mode == "rest" else 1e4 * e
                assert ds["power"].values[i, j, r] == p
                assert ds["mode"].values[i, j, r] == modes[mode]
                assert ds["radiation_bound_power"].values[i, j, r] == 1e5 * e
                ow = ds["one_way_power"].values[i, j, r]
                assert (math.isnan(ow) if mode == "rest" else ow == 2e4 * e)
                assert ds["status"].values[i, j, r] == (1 if mode == "rest" else 0)
    assert seen == {"rest", "rotation", "swinging", "rotation, reversed"}
    pm = ds["power_matrix"].values
    assert np.array_equal(pm, np.maximum(ds["power"].values.mean(axis=-1), 0.0))
    # the rotating bin's two records turn one each way: a tie, given to the forward sense
    assert (ds["operating_mode"].values == np.where(pm > 0, [[1, 2], [1, 2]], 0)).all()
    want = HOURS_PER_YEAR * sum(pm[i, j] * freq[(h, t)] for i, h in enumerate((1, 2))
                                for j, t in enumerate((5, 6)))
    assert annual["power"]["wh"] == pytest.approx(want, rel=1e-12)
    assert annual["power"]["complete"]


def test_a_lossy_take_off_shows_the_electrical_power(dataset, stand_in, tmp_path):
    """With a copper loss (or an efficiency) the Dataset's power is the hull's power_w (the
    electrical one) and mechanical_power its motion's, as for the heave buoy; the store
    resumes to the same numbers and modes."""
    store = str(tmp_path / "m.zarr")
    ds, _, run, _ = power_matrix(**BINS, realizations=1, hydro=dataset, workers=1,
                                 copper_loss=1e-6, store=store, **HULL)
    p, m = ds["power"].values, ds["mechanical_power"].values
    assert np.array_equal(p, 0.9 * m) and (m > 0).any()
    assert ds["mode"].dtype == np.int8
    again, _, run2, _ = power_matrix(**BINS, realizations=1, hydro=dataset, workers=1,
                                     copper_loss=1e-6, store=store, **HULL)
    assert run.computed_points == 4 and run2.resumed_points == 4
    for v in ("power", "mechanical_power", "mode", "status", "radiation_bound_power"):
        assert np.array_equal(again[v].values, ds[v].values, equal_nan=True), v


def test_a_bin_names_the_sense_most_of_its_records_turn(dataset, capsys, stand_in):
    """Seeds 3, 4 and 5: two records turn against a positive pitch, one with it; the bin's
    mode is the reversed rotation in the JSON and the text."""
    pend = [x for k, v in PEND.items() for x in (f"--{k.replace('_', '-')}", repr(v))]
    args = ["power-matrix", "--device", "buoy", "--dofs", "surge,heave,pitch", "--hydro",
            dataset, "--hs", "1,2", "--tp", "5,6", "--waves", "2", "--realizations", "3",
            "--seed", "3", "--workers", "1", "--time-limit", "3600", *pend]
    assert main([*args, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["operating_mode"] == [["rest", "rest"], ["rotation, reversed", "swinging"]]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "operating mode of the bins: 1 rotation, reversed; 1 swinging; 2 rest" in text


def test_the_command_line_reports_the_modes(dataset, capsys, stand_in):
    """The command line's JSON names each bin's mode (swinging included) and each period
    bin's record length (``record_s``: 2 peak periods here), and its text report names the
    hull and counts them."""
    args = ["power-matrix", "--device", "buoy", "--dofs", "surge,heave,pitch", "--hydro",
            dataset, "--hs", "1,2", "--tp", "5,6", "--waves", "2", "--realizations", "1",
            "--workers", "1", *(x for k, v in PEND.items()
                                for x in (f"--{k.replace('_', '-')}", repr(v)))]
    assert main([*args, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["operating_mode"] == [["rest", "rest"], ["rotation", "swinging"]]
    assert out["waves"] == 2.0 and out["record_s"] == [10.0, 12.0]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "1 rotation; 1 swinging; 2 rest" in text
    assert text.startswith("power matrix, hull (surge, heave, pitch): 2 Hm0 x 2 tp bins")


def test_dofs_heave_keeps_the_store_identity():
    """The new fields at their defaults are left out of the store's identity, so a store
    written before them still resumes; a hull's spec round-trips through the JSON."""
    spec = matrix_spec(hs="1,2", te="6,7", realizations=1)
    d = json.loads(spec.to_json())
    for k in ("dofs", "pivot_height", "pivot_offset", "hull_pitch_inertia", "barge_length",
              "barge_beam", "barge_draft", "copper_loss", "torque_limit"):
        assert k not in d
    assert spec == matrix_spec(hs="1,2", te="6,7", realizations=1, dofs="heave")
    assert MatrixSpec.from_json(spec.to_json()) == spec
    assert spec.variables == ("power", "limit_power", "uniform_power", "status")


def test_the_hull_spec_round_trips(dataset):
    spec = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL)
    assert MatrixSpec.from_json(spec.to_json()) == spec
    assert spec.variables == ("power", "radiation_bound_power", "one_way_power",
                              "peak_torque", "peak_pivot_force", "mode", "failure", "status")


def test_the_take_off_reaches_the_hull(dataset):
    """--efficiency, --torque-limit and --copper-loss reach the hull's take-off (HullPTO) as
    parapend.buoy builds it, and enter the store's identity."""
    from parapend.hydro.api import _hull_pto as _pto
    from parapend.performance.hull_device import problem

    kw = {"efficiency": 0.9, "torque_limit": 2e4, "copper_loss": 1e-6}
    spec = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, **kw)
    assert problem(spec)["pto"] == _pto(kw)
    d = json.loads(spec.to_json())
    assert (d["efficiency"], d["torque_limit"], d["copper_loss"]) == (0.9, 2e4, 1e-6)
    assert spec.variables[3] == "electrical_power"


@pytest.mark.parametrize("pto, waves, cap", [
    ({}, 400, "HULL_MAX_RECORD_HARMONICS"),  # an ideal take-off: matrix-free records
    ({"efficiency": 0.9}, 50, "HULL_MAX_HARMONICS"),  # an efficiency's
    ({"torque_limit": 2e4}, 80, "HULL_MAX_PTO_RECORD_HARMONICS"),  # a limit's
])
def test_the_longest_record_is_the_hulls_limit(dataset, pto, waves, cap):
    """Too long a record is refused naming --waves and the largest that fits; that largest
    fits the hull's own size check (12 harmonics per wave, at most the limit of `buoy` alone
    for that take-off), 0.01 more does not. The hull's default record is its declared one
    for that take-off (``defaults.HULL["matrix_waves"]``, 200 peak periods, for an ideal
    one; ``"matrix_waves_lossy"`` for a lossy one), and it fits."""
    from parapend import limits
    from parapend.defaults import HULL as HULL_DEFAULTS
    from parapend.hydro.hull import HARMONICS_PER_TURN, waves_in
    from parapend.performance.buoy_device import wave_of

    with pytest.raises(ParameterError, match=r"^waves: .*at most ([0-9.]+) peak periods "
                                             rf"fit, got {waves}$") as err:
        matrix_spec(hs="1,2", tp="5,6", realizations=1, hydro=dataset, waves=waves, **pto,
                    **HULL)
    default = matrix_spec(hs="1,2", tp="5,6", realizations=1, hydro=dataset, **HULL)
    assert default.waves == HULL_DEFAULTS["matrix_waves"]  # no take-off given: ideal
    assert HULL_DEFAULTS["matrix_waves"] == 200.0
    lossy = matrix_spec(hs="1,2", tp="5,6", realizations=1, hydro=dataset, **pto, **HULL)
    assert lossy.waves == HULL_DEFAULTS["matrix_waves_lossy" if pto else "matrix_waves"]
    most = float(str(err.value).split("at most ")[-1].split(" peak")[0])
    spec = matrix_spec(**{**BINS, "waves": most}, realizations=1, hydro=dataset, **pto,
                       **HULL)

    def size(waves):
        import dataclasses

        s = dataclasses.replace(spec, waves=waves)
        return max(HARMONICS_PER_TURN * waves_in(wave_of(s, 0, j, 0)[0]) for j in range(2))
    assert size(most) <= getattr(limits, cap) < size(most + 0.01)


def test_the_dearest_bins_are_handed_out_first(dataset):
    """The engine hands a matrix's bins out dearest first: the higher seas, then the longer
    records (at Tp 5 s 240 waves, at 6 and 7 s 200), so no worker ends alone on a dear
    bin; a resume keeps that order over the bins left."""
    from parapend.maps.run import _ordered

    spec = matrix_spec(hs="1,2", tp="5,6,7", realizations=1, hydro=dataset, **HULL)
    assert spec.bin_waves == (240.0, 200.0, 200.0)
    # block b is (Hs index b // 3, Tp index b % 3); equal costs keep the index order
    assert spec.block_order() == [3, 4, 5, 0, 1, 2]
    assert _ordered(spec, [0, 2, 4]) == [4, 0, 2]
    assert sorted(spec.block_order()) == list(range(spec.blocks))
    # a product without an order keeps the blocks as given
    assert _ordered(SimpleNamespace(), [2, 0, 1]) == [2, 0, 1]


def test_the_default_records_last_twenty_minutes(dataset):
    """The hull's default records (an ideal take-off) are 200 peak periods or 20 minutes,
    the longer, as far as the hull's solver takes them: at Tp 5 s 240 peak periods (1200 s),
    at Tp 6 s 200 (1200 s too); at Tp 2 and 4 s the longest record that fits (its
    size check passes, 0.01 peak period more fails), shorter than 20 minutes. An explicit
    --waves and a lossy take-off's records are as given in every bin. The lengths are in
    the store's identity (the JSON round-trips) and a spec without them reads ``waves``."""
    import dataclasses

    from parapend.hydro.api import solve_record
    from parapend.performance.buoy_device import wave_of
    from parapend.performance.hull_device import problem

    spec = matrix_spec(hs="1,2", tp="5,6", realizations=1, hydro=dataset, **HULL)
    assert spec.bin_waves == (240.0, 200.0)
    for j in range(2):  # 240 x 5 s and 200 x 6 s
        wave, _ = wave_of(spec, 0, j, 0)
        assert 2 * math.pi / wave.omega == pytest.approx(1200.0, rel=1e-12)
    assert MatrixSpec.from_json(spec.to_json()) == spec
    d = json.loads(spec.to_json())
    d.pop("bin_waves")
    assert MatrixSpec.from_json(json.dumps(d)).record_waves(0) == 200.0
    short = matrix_spec(hs="1,2", tp="2,4", realizations=1, hydro=dataset, **HULL)
    p = problem(short)

    def fits(j, waves):
        s = dataclasses.replace(short, waves=waves, bin_waves=None)
        try:
            solve_record(p, wave_of(s, 0, j, 0)[0], None, check_only=True)
        except ParameterError:
            return False
        return True
    for j, tp in enumerate(short.tp):
        w = short.record_waves(j)
        assert 200.0 < w < 1200.0 / tp
        assert fits(j, w) and not fits(j, w + 0.01)
    for kw in ({"waves": 200.0}, {"efficiency": 0.9}):
        given = matrix_spec(hs="1,2", tp="5,6", realizations=1, hydro=dataset, **kw, **HULL)
        assert given.bin_waves is None
        assert [given.record_waves(j) for j in range(2)] == [given.waves] * 2


@pytest.mark.parametrize("kw, match", [
    ({"device": "prescribed-heave", "dofs": "surge,heave,pitch"}, r"^dofs: .*--device buoy"),
    ({"device": "buoy", "pivot_height": 1.0}, r"^pivot-height: a hull's option"),
    ({"device": "buoy", "copper_loss": 1.0}, r"^copper-loss: a hull's option"),
    ({"device": "buoy", "barge_length": 9.0}, r"^barge-length: a hull's option"),
    ({"device": "buoy", "torque_limit": 1.0}, r"^torque-limit: not supported"),
    ({**HULL, "winding": 2}, r"^winding: "),
    ({**HULL, "density": 1000.0, "hydro": None}, r"^density: the hull's BEM"),
    ({**HULL, "depth": 50.0, "hydro": None}, r"^depth: the hull's BEM"),
    ({**HULL, "response": "x.csv"}, r"^response: "),
    ({**HULL, "pivot_offset": 50.0, "hydro": None}, r"^pivot-offset: the pivot must lie"),
    ({**HULL, "body": "barge", "radius": 1.0, "hydro": None}, r"^radius: "),
    ({**HULL, "harmonics": 4000}, r"^harmonics: "),
    ({**HULL, "harmonics": 500, "efficiency": 0.9}, r"^harmonics: "),
    ({**HULL, "dofs": "surge,heave"}, r"^dofs: "),
    ({"device": "buoy", "body": "barge"}, r"^body: the barge is a hull that pitches"),
    # the hull's controller's ranges, before any bin (the heaving buoy's are wider)
    ({**HULL, "controller": "mpc", "horizon": 12.0},
     r"^horizon: expected a number in \[0.05, 10\]"),
    ({**HULL, "controller": "mpc", "update_interval": 0.02}, r"^update-interval: expected a "
     r"number in \[0.041"),
    ({**HULL, "controller": "mpc", "horizon": 0.1, "update_interval": 0.125},
     r"^update-interval: expected at most the horizon"),
])
def test_refusals_in_one_line(kw, match, dataset):
    kw = {"hydro": dataset, **kw}
    if kw.get("device") != "buoy" or "dofs" not in kw:
        kw.pop("hydro")
    with pytest.raises(ParameterError, match=match) as err:
        matrix_spec(**BINS, realizations=1, **kw)
    assert "\n" not in str(err.value)


def test_a_bin_outside_the_hulls_data_is_refused(tmp_path):
    """Every period bin's record checked before any bin runs: the longest lies below the
    dataset's lowest frequency, refused naming tp and the bin."""
    path = _save(tmp_path / "narrow.nc", n=60, w_min=1.2)
    with pytest.raises(ParameterError, match=r"^tp: the record of the bin 6 s: "):
        matrix_spec(**BINS, realizations=1, hydro=path, **HULL)


def test_the_command_line_refuses_in_one_line(dataset, capsys):
    assert main(["power-matrix", "--dofs", "surge,heave,pitch", "--hs", "1,2", "--tp",
                 "5,6"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "dofs" in err and "Traceback" not in err
    assert main(["power-matrix", "--device", "buoy", "--dofs", "surge,heave,pitch", "--hydro",
                 dataset, "--hs", "1,2", "--tp", "5,6", "--waves", "400"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "waves" in err


@pytest.mark.slow
def test_each_bin_is_parapend_buoy_by_hand(dataset, scatter, capsys, tmp_path):
    """The command line's matrix (2 x 2 bins, one realization of 2-wave records): each bin's
    power, mode and radiation bound equal ``parapend.buoy(dofs="surge,heave,pitch", ...)``
    on that bin's record, run by hand, to 1e-9; the annual energy 8766 h x sum(P f)."""
    path, freq = scatter
    nc = str(tmp_path / "m.nc")
    args = ["power-matrix", "--device", "buoy", "--dofs", "surge,heave,pitch", "--hydro",
            dataset, "--hs", "1,2", "--tp", "5,6", "--waves", "2", "--seed", "3",
            "--realizations", "1", "--workers", "1", "--scatter", path, "--netcdf", nc,
            "--json", *(x for k, v in PEND.items()
                        for x in (f"--{k.replace('_', '-')}", repr(v)))]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    import xarray as xr

    ds = xr.load_dataset(nc)
    pm = np.array(out["power_matrix"])
    for i, h in enumerate((1.0, 2.0)):
        for j, t in enumerate((5.0, 6.0)):
            r = parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, hs=h, tp=t,
                              repeat_period=repeat_period(2.0, t), seed=3, **PEND)
            assert r.success
            assert ds["power"].values[i, j, 0] == pytest.approx(r.power_w, rel=1e-9)
            assert pm[i, j] == pytest.approx(max(r.power_w, 0.0), rel=1e-9)
            assert ds["radiation_bound_power"].values[i, j, 0] == pytest.approx(
                r.radiation_bound_w, rel=1e-9)
            want = ("rotation, reversed" if r.mode == "rotation" and r.winding < 0
                    else r.mode)
            assert ds["mode"].values[i, j, 0] == ("rest", "rotation", "swinging",
                                                  "rotation, reversed").index(want)
    want = HOURS_PER_YEAR * sum(pm[i, j] * freq[(h, t)] for i, h in enumerate((1, 2))
                                for j, t in enumerate((5, 6)))
    assert out["annual_energy"]["power"]["wh"] == pytest.approx(want, rel=1e-12)


def test_the_hulls_causal_column_is_in_the_spec(dataset):
    """``--controller mpc`` with the hull: the spec carries the causal column (the hull's
    controller, a horizon of 2 peak periods by default, the forecasts asked for), round
    trips, and stores each forecast's causal power beside the optimum's."""
    spec = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, controller="mpc",
                       forecast="perfect,ar")
    assert (spec.controller, spec.buoy_controller, spec.horizon) == (
        "mpc", "hull-collocation", 2.0)  # the hull's default planner
    assert spec.forecasts == ("perfect", "ar")
    assert MatrixSpec.from_json(spec.to_json()) == spec
    assert "causal_perfect_power" in spec.variables and "causal_ar_power" in spec.variables
    # the work estimate before any bin runs prices the hull's controller: the runs' length
    # (warm-up and record) times its cost a peak period, per forecast
    from parapend.performance.check import BUOY_CAUSAL_SECONDS, record_seconds

    want = (BUOY_CAUSAL_SECONDS["hull-collocation"] * (spec.waves + spec.warm_up) * spec.horizon
            * (0.125 / spec.update_interval) * 2)
    assert record_seconds(spec) == pytest.approx(want, rel=1e-12)


@pytest.mark.slow
def test_a_hull_bins_causal_run_stays_below_its_optimum(dataset):
    """One bin's record solved and run causally (perfect forecast) in its optimum's mode: a
    causal controller cannot beat the omniscient optimum of the same record."""
    from parapend.performance.solve import solve_bin

    spec = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, controller="mpc")
    out = solve_bin(spec, 0, 0, 0)
    p, c = out["power"], out["causal_perfect_power"]
    assert math.isfinite(p) and p > 0
    assert math.isnan(c) or c <= p * (1 + 1e-3)


def test_the_hulls_causal_column_takes_the_buoys_planners(dataset):
    """``--planner`` in the causal column, as ``parapend buoy --controller mpc --planner``:
    the hull's collocation planner (the default) is its own controller in the spec
    (another store than L-BFGS-B's), priced by its own cost a peak period; the heaving
    buoy's planners name its controller; every misuse refused in one line naming the
    option."""
    from parapend.performance.check import BUOY_CAUSAL_SECONDS, record_seconds

    lb = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, controller="mpc",
                     planner="lbfgsb")
    col = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, controller="mpc",
                      planner="collocation")
    assert col == matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, controller="mpc")
    assert (col.buoy_controller, col.horizon) == ("hull-collocation", 2.0)
    assert lb.buoy_controller == "hull"  # the stores' name for it from before
    assert col != lb and MatrixSpec.from_json(col.to_json()) == col
    assert record_seconds(col) / record_seconds(lb) == pytest.approx(
        BUOY_CAUSAL_SECONDS["hull-collocation"] / BUOY_CAUSAL_SECONDS["hull"], rel=1e-12)
    # the matrix's estimate counts each record's solve and its causal runs
    from parapend.performance.check import check_size, hull_record_seconds

    for spec in (lb, col):
        est = check_size(spec, workers=1)
        assert est["seconds"] == pytest.approx(
            4 * (hull_record_seconds(spec.waves) + record_seconds(spec)), rel=1e-12)
    # an efficiency's records are priced by their own cost a peak period
    from parapend.performance.check import EFFICIENCY_SECONDS

    lossy = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, efficiency=0.9)
    assert check_size(lossy, workers=1)["seconds"] == pytest.approx(
        4 * EFFICIENCY_SECONDS * lossy.waves, rel=1e-12)
    # ... and their workers' memory by the dense problems' (1.97 GB measured): 3 GB holds
    # one (the default then starts one), not two (refused, naming --workers)
    from parapend.performance.check import HULL_DENSE_WORKER_BYTES, WORKER_BYTES

    assert HULL_DENSE_WORKER_BYTES > 2 * 10**9 > 3 * WORKER_BYTES
    assert check_size(lossy, available=3 << 30)["processes"] == 1
    with pytest.raises(ParameterError, match=r"^workers: 2 processes need about 5 GB"):
        check_size(lossy, workers=2, available=3 << 30)
    assert check_size(col, workers=2, available=3 << 30)["processes"] == 2
    # a copper loss alone is smooth (matrix-free past 100 harmonics): priced as before
    copper = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, copper_loss=1e-5)
    est = check_size(copper, workers=2, available=3 << 30)
    assert est["processes"] == 2
    assert est["seconds"] == pytest.approx(2 * hull_record_seconds(copper.waves, False),
                                           rel=1e-12)
    for kw, match in (({"planner": "plan"}, r"^planner: with --dofs surge,heave,pitch "),
                      ({"planner": "coupled"}, r"^planner: with --dofs surge,heave,pitch "),
                      ({"planner": "collocation", "controller": None},
                       r"^planner: an option of the causal column; needs --controller mpc")):
        args = {**BINS, "realizations": 1, "hydro": dataset, **HULL, "controller": "mpc",
                **kw}
        with pytest.raises(ParameterError, match=match):
            matrix_spec(**args)
    with pytest.raises(ParameterError, match=r"^planner: an option of --device buoy"):
        matrix_spec(hs="1,2", te="6,8", controller="mpc", planner="plan")


def test_the_heaving_buoys_causal_column_takes_its_planner():
    """The heaving buoy: ``--planner coupled`` runs the coupled controller where the default
    is ``plan``; ``plan`` with an efficiency and the hull's planners are refused."""
    base = {"hs": "0.5,1", "tp": "2.5,3", "device": "buoy", "controller": "mpc"}
    assert matrix_spec(**base).buoy_controller == "plan"
    spec = matrix_spec(**base, planner="coupled")
    assert (spec.buoy_controller, spec.horizon) == ("coupled", 1.0)
    with pytest.raises(ParameterError, match=r"^planner: with --dofs heave expected plan "):
        matrix_spec(**base, planner="collocation")
    with pytest.raises(ParameterError, match=r"^efficiency: not with --planner plan"):
        matrix_spec(**base, planner="plan", efficiency=0.9)


def test_the_command_line_takes_the_planner(dataset, capsys):
    """``power-matrix --planner``: a name outside the four refused by the parser, the
    hull's planner on the heaving buoy in one line."""
    args = ["power-matrix", "--device", "buoy", "--hs", "0.5,1", "--tp", "2.5,3",
            "--controller", "mpc", "--planner"]
    assert main([*args, "ipopt"]) == 2
    assert "--planner: invalid choice: 'ipopt'" in capsys.readouterr().err
    assert main([*args, "lbfgsb"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "error: planner: with --dofs heave expected plan" in err


@pytest.mark.slow
def test_a_hull_bins_collocation_run_is_parapend_buoys(dataset):
    """One bin's causal run with ``planner="collocation"`` (perfect forecast) is the run
    ``parapend.buoy(dofs="surge,heave,pitch", controller="mpc", planner="collocation")``
    makes of the same record by hand (the same warm-up, horizon and update interval), to
    1e-9, and stays below the record's optimum."""
    pytest.importorskip("casadi")
    from threadpoolctl import threadpool_limits

    from parapend.performance.solve import solve_bin

    spec = matrix_spec(**BINS, realizations=1, hydro=dataset, **HULL, controller="mpc",
                       planner="collocation")
    out = solve_bin(spec, 0, 1, 0)
    p, c = out["power"], out["causal_perfect_power"]
    assert math.isfinite(p) and p > 0 and math.isfinite(c)
    assert c <= p * (1 + 1e-3)
    with threadpool_limits(1, user_api="blas"):
        r = parapend.buoy(dofs="surge,heave,pitch", hydro=dataset, hs=1.0, tp=6.0,
                          repeat_period=repeat_period(2.0, 6.0), seed=3, controller="mpc",
                          planner="collocation", horizon=spec.horizon,
                          update_interval=spec.update_interval, **PEND)
    assert r.planner.startswith("hull-collocation")
    assert r.optimum_power_w == pytest.approx(p, rel=1e-9)
    assert max(r.electrical_power_w, 0.0) == pytest.approx(c, rel=1e-9)


@pytest.mark.slow
@pytest.mark.skipif(__import__("sys").platform == "win32", reason="kill -9")
def test_a_hull_causal_matrix_killed_resumes_to_the_same_store(dataset, tmp_path):
    """The hull's causal column in a ``--store``: a run killed with SIGKILL after its first
    bin, resumed on two processes, leaves the store byte for byte as one uninterrupted run
    on one process (each bin is solved whole, on its own)."""
    import zarr
    from killed import kill_after, store_files

    grid = {**BINS, "realizations": 1, "hydro": dataset, **HULL, "controller": "mpc"}
    ref = tmp_path / "ref.zarr"
    power_matrix(**grid, workers=1, store=str(ref), command="test")
    store = tmp_path / "killed.zarr"
    kill_after("from parapend.performance import power_matrix",  # 1 of the 4 bins stored
               f"power_matrix(**{grid!r}, workers=1, store=sys.argv[1], command='test', "
               "progress=slow)", store, 1)
    done = np.asarray(zarr.open_group(store, mode="r")["done"][...])
    assert 0 < done.sum() < done.size
    ds, _, run, _ = power_matrix(**grid, workers=2, store=str(store), command="test")
    assert run.resumed_points >= 1 and 0 < run.computed_points < done.size
    assert store_files(store) == store_files(ref)
    assert np.isfinite(ds["causal_perfect_power_mean"].values).any()


def test_a_lengthened_record_is_never_shorter_than_waves(dataset, monkeypatch):
    """Where the hull's solver takes less than the 20 minutes, the record is the longest
    that fits, floored to 0.01 peak period: never below the spec's own ``waves``, round or
    not, and always one that fits (the solver's size check stubbed by a threshold)."""
    import dataclasses

    from parapend.performance import hull_device

    spec = matrix_spec(hs="1,2", tp="5,6", realizations=1, hydro=dataset, **HULL)
    for waves in (200.0, 200.001, 200.005, 200.0099, 150.3, 150.0037):
        for extra in (0.0, 0.003, 0.0049, 0.0093, 0.012, 0.031, 7.77):
            top = waves + extra
            monkeypatch.setattr(hull_device, "_fits_bin", lambda s, j, w, top=top: w <= top)
            got = hull_device.lengthen(dataclasses.replace(spec, waves=waves, bin_waves=None),
                                       1200.0)
            for j, tp in enumerate(spec.tp):
                want = max(waves, 1200.0 / tp)
                if top >= want:
                    assert got.record_waves(j) == pytest.approx(want, rel=1e-12)
                else:
                    assert waves <= got.record_waves(j) <= top
                    assert got.record_waves(j) > min(top - 0.02, waves)
