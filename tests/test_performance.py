"""Power matrix, wave resource and annual energy (docs/performance.md).

Independent sources: MHKiT's ``wave.performance`` and ``wave.resource`` on the same inputs
(1e-10 relative), closed forms (the Pierson-Moskowitz Te/Tp, deep-water J from m_-1), a
hand-made 3 x 3 annual energy written out in the docs, and ``sea`` run by hand on the
seeds of a bin.
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from killed import kill_after

import parapend
from parapend.cli import main
from parapend.performance import bin_edges, power_matrix
from parapend.performance.annual import (
    HOURS_PER_YEAR,
    annual_energy,
    bin_series,
    read_scatter,
)
from parapend.performance.resource import (
    energy_flux,
    record_spectrum,
    te_over_tp,
    wave_number,
)

TINY = {"hs": "1,2", "te": "6,7", "realizations": 2, "waves": 4, "workers": 1}


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    store = tmp_path_factory.mktemp("pm") / "tiny.zarr"
    ds, annual, run, _ = power_matrix(**TINY, store=str(store))
    return ds, store


def _rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))


# -- the resource -------------------------------------------------------------------------

def test_te_over_tp_closed_form_and_ittc():
    pm = math.gamma(1.25) * 1.25 ** -0.25
    assert te_over_tp("pierson-moskowitz") == pytest.approx(0.857222537, abs=1e-9)
    # JONSWAP at gamma_p = 1 is Pierson-Moskowitz: the quadrature against the closed form
    assert te_over_tp("jonswap", 1.0) == pytest.approx(pm, rel=1e-9)
    # the ITTC fit MHKiT uses (energy_period_to_peak_period), within its stated accuracy
    for g in (2.0, 3.3, 7.0):
        ittc = 0.8255 + 0.03852 * g - 0.005537 * g**2 + 0.0003154 * g**3
        assert te_over_tp("jonswap", g) == pytest.approx(ittc, rel=5e-3)


def test_energy_flux_deep_closed_form_and_mhkit():
    pd = pytest.importorskip("pandas")
    resource = pytest.importorskip("mhkit.wave.resource")
    f, s = record_spectrum(2.0, 8.0, 400.0)
    rho, g = 1025.0, 9.81
    j = energy_flux(f, s, density=rho, gravity=g)
    m_1 = np.sum(s / f) / 400.0
    assert j == pytest.approx(rho * g**2 * m_1 / (4 * math.pi), rel=1e-13)
    spec = pd.Series(s, index=pd.Index(f, name="Frequency"))
    assert _rel(j, resource.energy_flux(spec, 100.0, deep=True, rho=rho, g=g)) < 1e-10
    for depth in (5.0, 20.0, 60.0, 500.0):
        mine = energy_flux(f, s, depth=depth, density=rho, gravity=g)
        theirs = float(resource.energy_flux(spec, depth, deep=False, rho=rho, g=g))
        assert _rel(mine, theirs) < 1e-10, depth
    # shallow water carries less flux than deep at these periods' group velocity peak? no:
    # the limit of great depth is the deep-water flux
    assert energy_flux(f, s, depth=5000.0, density=rho, gravity=g) == pytest.approx(j,
                                                                                   rel=1e-9)


def test_wave_number_solves_the_dispersion_relation():
    f = np.linspace(0.02, 1.0, 50)
    for h in (1.0, 10.0, 1000.0):
        k = wave_number(f, h, 9.81)
        w2 = (2 * math.pi * f) ** 2
        assert np.max(np.abs(9.81 * k * np.tanh(k * h) - w2) / w2) < 1e-14


def test_bin_edges_are_mhkits():
    perf = pytest.importorskip("mhkit.wave.performance")
    xr = pytest.importorskip("xarray")
    c = np.array([0.5, 1.0, 1.5, 2.5])
    e = bin_edges(c)
    assert e.tolist() == [0.0, 0.75, 1.25, 2.0, 3.0]
    # MHKiT's counts of a series binned on these centres = ours
    rng = np.random.default_rng(3)
    hs = rng.uniform(0.0, 3.2, 400)
    te = rng.uniform(0.0, 9.5, 400)
    tc = np.array([4.0, 6.0, 8.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = perf.capture_width_matrix(xr.DataArray(hs), xr.DataArray(te),
                                           xr.DataArray(np.ones(400)), "count", c, tc,
                                           to_pandas=False).values
    mine, outside = bin_series(hs, te, e, bin_edges(tc))
    assert np.array_equal(np.nan_to_num(theirs), mine)
    assert outside == 400 - int(mine.sum())


# -- MHKiT on the same matrix -------------------------------------------------------------

def test_matrix_equals_mhkit(tiny):
    xr = pytest.importorskip("xarray")
    perf = pytest.importorskip("mhkit.wave.performance")
    resource = pytest.importorskip("mhkit.wave.resource")
    pd = pytest.importorskip("pandas")
    ds, _ = tiny
    hm0, te = ds["hm0"].values, ds["te"].values
    j = ds["wave_energy_flux_matrix"].values
    p = ds["power"].values  # (hm0, te, realization)
    # one "sea state" per realization, as MHKiT's series
    ii, kk, rr = np.meshgrid(range(hm0.size), range(te.size), range(p.shape[2]),
                             indexing="ij")
    h_s = xr.DataArray(hm0[ii].ravel())
    t_s = xr.DataArray(te[kk].ravel())
    j_s = xr.DataArray(j[ii, kk].ravel())
    cw = xr.DataArray(p.ravel() / j[ii, kk].ravel())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # MHKiT warns of bins wider than IEC's 0.5 m, 1 s
        cwm = {s: perf.capture_width_matrix(h_s, t_s, cw, s, hm0, te, to_pandas=False)
               for s in ("mean", "std", "min", "max", "count")}
        old = perf.capture_length_maxtrix(h_s, t_s, cw, "mean", hm0, te, to_pandas=False)
        jm = perf.wave_energy_flux_matrix(h_s, t_s, j_s, "mean", hm0, te, to_pandas=False)
        pm = perf.power_matrix(cwm["mean"], jm)
        cw1 = perf.capture_width(xr.DataArray(p[0, 0]), xr.DataArray(j[0, 0]),
                                 to_pandas=False)
    assert _rel(ds["capture_width_matrix"], cwm["mean"]) < 1e-10
    assert _rel(ds["capture_width_matrix"], old) < 1e-10
    for s in ("std", "min", "max"):
        assert _rel(ds[f"capture_width_{s}"], cwm[s]) < 1e-10 or np.allclose(
            ds[f"capture_width_{s}"], cwm[s], rtol=1e-10, atol=1e-10 * float(
                ds["capture_width_matrix"].max())), s
    assert np.array_equal(ds["power_count"].values, cwm["count"].values)
    assert _rel(ds["wave_energy_flux_matrix"], jm) < 1e-10
    assert _rel(ds["power_matrix"], pm) < 1e-10
    assert _rel(ds["power_mean"], pm) < 1e-10
    assert _rel(cw1 * j[0, 0], p[0, 0]) < 1e-13
    # the annual energy of a site (a frequency matrix summing to 1)
    freq = np.array([[0.1, 0.2], [0.3, 0.4]])
    ours = annual_energy(ds["power_mean"].values, freq)["wh"]
    theirs = perf.mean_annual_energy_production_matrix(
        parapend.performance.to_mhkit(ds["capture_width_matrix"]),
        parapend.performance.to_mhkit(ds["wave_energy_flux_matrix"]),
        xr.DataArray(freq, dims=("x_centers", "y_centers")))
    assert _rel(ours, theirs) < 1e-10
    # J of each bin: MHKiT's energy_flux of the bin's record spectrum
    ratio = ds.attrs["te_over_tp"]
    for a, h in enumerate(hm0):
        for b, t in enumerate(te):
            tp = t / ratio
            f, s = record_spectrum(h, tp, 4 * tp)
            spec = pd.Series(s, index=pd.Index(f, name="Frequency"))
            ref = float(resource.energy_flux(spec, 100.0, deep=True, rho=1025.0, g=9.81))
            assert _rel(j[a, b], ref) < 1e-10


def test_statistics_and_timeseries_energy_equal_mhkit(tiny):
    xr = pytest.importorskip("xarray")
    perf = pytest.importorskip("mhkit.wave.performance")
    ds, _ = tiny
    for a, b in ((0, 0), (1, 1)):
        st = perf.statistics(xr.DataArray(ds["power"].values[a, b]), to_pandas=False)
        for s in ("mean", "std", "min", "max"):
            assert _rel(ds[f"power_{s}"].values[a, b], float(st.sel(index=s))) < 1e-10, s
        assert int(st.sel(index="count")) == ds["power_count"].values[a, b]
    # a time series of sea states: MHKiT's mean_annual_energy_production_timeseries with each
    # state's bin (capture width, flux) equals the AEP of the binned frequencies
    hs = np.array([1.1, 1.9, 2.2, 0.9, 1.3, 2.4, 6.0])
    te = np.array([6.2, 6.8, 7.1, 5.5, 6.9, 6.1, 6.0])
    counts, outside = bin_series(hs, te, ds["hm0_edges"].values, ds["te_edges"].values)
    assert outside == 1  # Hs = 6 m lies above the last edge (2.5 m)
    ours = annual_energy(ds["power_mean"].values, counts / hs.size)["wh"]
    i = np.searchsorted(ds["hm0_edges"].values, hs[:-1], side="right") - 1
    k = np.searchsorted(ds["te_edges"].values, te[:-1], side="right") - 1
    cw = np.append(ds["capture_width_matrix"].values[i, k], 0.0)  # outside: nothing
    j = np.append(ds["wave_energy_flux_matrix"].values[i, k], 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = perf.mean_annual_energy_production_timeseries(xr.DataArray(cw),
                                                               xr.DataArray(j))
        old = perf.capture_length(xr.DataArray(ds["power"].values[0, 0]),
                                  xr.DataArray(j[0]), to_pandas=False)
    assert _rel(ours, theirs) < 1e-10
    assert old.size == ds.sizes["realization"]


def test_std_is_ddof0_and_dims_follow_mhkit(tiny):
    ds, _ = tiny
    p = ds["power"].values
    assert np.allclose(ds["power_std"].values, p.std(axis=-1, ddof=0), rtol=0, atol=1e-15)
    assert ds["power_matrix"].dims == ("hm0", "te")
    assert ds["hm0_edges"].values.tolist() == [0.0, 1.5, 2.5]
    assert ds["te_edges"].values.tolist() == [0.0, 6.5, 7.5]


def test_each_bin_mean_is_sea_by_hand(tiny):
    ds, _ = tiny
    ratio = te_over_tp("jonswap", 3.3)
    for a, b in ((0, 1), (1, 0)):
        hs, te = float(ds["hm0"][a]), float(ds["te"][b])
        tp = te / ratio
        runs = [parapend.sea(hs=hs, tp=tp, repeat_period=4 * tp, seed=r) for r in (0, 1)]
        got = [r.power_w for r in runs]
        assert ds["power_mean"].values[a, b] == pytest.approx(np.mean(got), rel=1e-12)
        assert ds["power_min"].values[a, b] == pytest.approx(min(got), rel=1e-12)
        lim = [r.limit_power_w for r in runs]
        assert ds["limit_power_mean"].values[a, b] == pytest.approx(np.mean(lim), rel=1e-12)
        # no motion beats the limit
        assert np.all(ds["power"].values <= ds["limit_power"].values)


# -- the annual energy --------------------------------------------------------------------

#: the hand-made 3 x 3 example of docs/performance.md
HAND_P = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
HAND_F = np.array([[0.1, 0.1, 0.0], [0.2, 0.2, 0.1], [0.0, 0.2, 0.1]])


def test_hand_made_annual_energy(tmp_path):
    # 0.1 + 0.2 + 0.8 + 1.0 + 0.6 + 1.6 + 0.9 = 5.2 W on average; x 8766 h = 45583.2 Wh
    a = annual_energy(HAND_P, HAND_F)
    assert a["wh"] == pytest.approx(45583.2, rel=1e-14)
    assert a["mwh"] == pytest.approx(0.0455832, rel=1e-14)
    assert a["mean_power_w"] == pytest.approx(5.2, rel=1e-14)
    # the same through a scatter CSV, in frequencies and in hours
    hs, te = (1.0, 2.0, 3.0), (6.0, 7.0, 8.0)
    lines = ["hs,te,frequency"] + [f"{hs[i]},{te[k]},{HAND_F[i, k]}" for i in range(3)
                                   for k in range(3) if HAND_F[i, k] > 0]
    (tmp_path / "s.csv").write_text("\n".join(lines) + "\n")
    assert np.allclose(read_scatter(tmp_path / "s.csv", hs, te, "te"), HAND_F, atol=0)
    hours = ["hs,te,count"] + [f"{hs[i]},{te[k]},{HAND_F[i, k] * 8766}" for i in range(3)
                               for k in range(3)]
    (tmp_path / "h.csv").write_text("\n".join(hours) + "\n")
    assert np.allclose(read_scatter(tmp_path / "h.csv", hs, te, "te"), HAND_F, rtol=1e-14,
                       atol=1e-17)
    # a bin of the site without power is listed, and left out of the sum
    p = HAND_P.copy()
    p[2, 1] = np.nan
    b = annual_energy(p, HAND_F)
    assert b["missing"] == [[2, 1]] and not b["complete"]
    assert b["wh"] == pytest.approx((5.2 - 1.6) * HOURS_PER_YEAR, rel=1e-14)
    assert b["missing_frequency"] == pytest.approx(0.2)


def test_site_through_the_command(tiny, tmp_path, capsys):
    ds, _ = tiny
    (tmp_path / "s.csv").write_text("hs,te,frequency\n1,6,0.5\n2,7,0.5\n")
    (tmp_path / "t.csv").write_text("hs,te\n1.2,6.1\n2.1,6.9\n9,6\n1.4,5.9\n")
    # the fixture's store: the command resumes it (nothing to compute)
    argv = ["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "2", "--waves",
            "4", "--workers", "1", "--json", "--store", str(tiny[1])]
    import json

    assert main(argv + ["--scatter", str(tmp_path / "s.csv"), "--rated-power", "10"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["computed_bins"] == 0 and out["resumed_bins"] == 4
    want = 8766 * (0.5 * ds["power_mean"].values[0, 0] + 0.5 * ds["power_mean"].values[1, 1])
    assert out["annual_energy"]["power"]["wh"] == pytest.approx(want, rel=1e-12)
    assert out["capacity_factor"] == pytest.approx(want / 8766 / 10, rel=1e-12)
    # a sea state outside the bins: the annual energy is incomplete, no resolved answer (3)
    assert main(argv + ["--timeseries", str(tmp_path / "t.csv")]) == 3
    out = json.loads(capsys.readouterr().out)
    a = out["annual_energy"]["power"]
    assert a["outside_frequency"] == {"sea_states": 1, "frequency": 0.25}
    want = 8766 * (0.5 * ds["power_mean"].values[0, 0] + 0.25 * ds["power_mean"].values[1, 1])
    assert a["wh"] == pytest.approx(want, rel=1e-12)
    # the text report and the three figures
    plot = tmp_path / "pm"
    assert main([x for x in argv if x != "--json"]
                + ["--scatter", str(tmp_path / "s.csv"), "--plot", str(plot)]) == 0
    text = capsys.readouterr().out
    assert "mean annual energy (8766 h/yr): optimum" in text
    for name in ("matrix", "capture-width", "scatter"):
        assert (tmp_path / f"pm-{name}.png").stat().st_size > 1000


_SCATTER = {"SUM": "hs,te,frequency\n1,6,0.5\n2,7,0.4\n",
            "EDGES": "hs,te,frequency\n1.25,6,0.5\n2,7,0.5\n",
            "TP": "hs,tp,frequency\n1,6,1\n",
            "NEG": "hs,te,frequency\n-1,6,0.5\n2,7,0.5\n",
            "EMPTY": "hs,te,frequency\n"}


@pytest.mark.parametrize("extra, needle", [
    (["--hs", "1:2:0"], "hs: expected at least 2 bins"),
    (["--hs", "1"], "hs: expected at least 2 bin centres"),
    (["--hs", "-1,2"], "hs: expected positive"),
    (["--te", "7,6"], "te: expected increasing"),
    (["--tp", "7,8"], "te, tp:"),
    (["--torque-limit", "2"], "torque-limit: not supported"),
    (["--horizon", "10"], "horizon: an option of the causal column; needs --controller mpc"),
    (["--waves", "1"], "waves:"),
    (["--gamma-peak", "0"], "gamma-peak:"),
    (["--te", "0.5,40"], "te: expected peak periods from 1 to 30 s"),
    (["--hs", "1,31"], "hs: expected bin centres up to 30 m"),
    (["--device", "buoy", "--response", "x.csv"], "response:"),
    (["--rated-power", "5"], "rated-power: the capacity factor needs a site"),
    (["--scatter", "SUM"], "scatter: expected frequencies summing to 1"),
    (["--scatter", "EDGES"], "scatter: hs = 1.25 is not a bin centre"),
    (["--scatter", "TP"], "scatter: its periods are tp"),
    (["--scatter", "NEG"], "scatter: expected positive heights"),
    (["--scatter", "EMPTY"], "scatter: expected at least one bin"),
])
def test_bad_input_one_line_exit_2(extra, needle, tmp_path, capsys):
    if extra[0] == "--scatter":
        (tmp_path / "s.csv").write_text(_SCATTER[extra[1]])
        extra = ["--scatter", str(tmp_path / "s.csv")]
    opts = {"--hs": "1,2", "--te": "6,7", "--realizations": "1", "--waves": "3",
            "--workers": "1"}
    opts.update(zip(extra[::2], extra[1::2]))
    code = main(["power-matrix", *(x for kv in opts.items() for x in kv)])
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert needle in err, err


# -- figures, electrical power -------------------------------------------------------------

def test_figures_pass_the_house_checks(tiny):
    sys.path.insert(0, str(Path(__file__).parent))
    import figure_checks as fc

    from parapend.performance import figures

    ds, _ = tiny
    ds = ds.copy()
    ds["frequency"] = (("hm0", "te"), np.array([[0.5, 0.2], [0.3, 0.0]]))
    ds.attrs["annual_energy_mwh"] = 0.01
    for draw in (figures.plot_matrix, figures.plot_capture_width, figures.plot_scatter):
        fig = draw(ds)
        problems = fc.all_problems(fig, si=True)
        assert not problems, (draw.__name__, problems)
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_matrix_title_counts_records_in_the_singular_and_plural(tiny):
    import matplotlib.pyplot as plt

    from parapend.performance import figures

    ds, _ = tiny
    for n, words in ((2, "mean over 2 records of 4"), (1, "mean over 1 record of 4")):
        fig = figures.plot_matrix(ds.isel(realization=slice(0, n)))
        assert words in fig.axes[0].get_title(), fig.axes[0].get_title()
        plt.close(fig)


def test_electrical_power_at_efficiency_one_is_the_power():
    from parapend.performance.solve import electrical_power

    r = parapend.sea(hs=2.0, tp=8.0, repeat_period=32.0, seed=1)
    # the instantaneous -T theta' on the grid, averaged: the optimizer's integrated-by-parts
    # power to the accuracy docs/seas.md states (1e-7)
    assert electrical_power(r, 1.0) == pytest.approx(r.power_w, rel=1e-6)
    e = electrical_power(r, 0.8)
    assert e < 0.8 * r.power_w  # motoring costs 1/eta: below eta P


# -- the engine: Dask, kill -9 ---------------------------------------------------------------

SMALL = {"hs": "1,2", "te": "6,7", "realizations": 1, "waves": 3}


def _files(store: Path) -> dict:
    import hashlib

    return {str(p.relative_to(store)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(store.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_dask_local_cluster_writes_the_same_store(tmp_path):
    distributed = pytest.importorskip("distributed")
    ref = tmp_path / "ref.zarr"
    power_matrix(**SMALL, workers=1, store=str(ref), command="test")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  protocol="tcp", host="127.0.0.1",
                                  dashboard_address="127.0.0.1:0", silence_logs=50) as c:
        store = tmp_path / "dask.zarr"
        ds, _, run, _ = power_matrix(**SMALL, store=str(store), command="test",
                                     scheduler=c.scheduler_address)
    assert run.executor.startswith("Dask cluster at tcp://127.0.0.1")
    assert _files(store) == _files(ref)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="kill -9")
def test_kill_9_then_resume_equals_uninterrupted(tmp_path):
    grid = {"hs": "1,1.5,2", "te": "6,7", "realizations": 2, "waves": 8}
    ref = tmp_path / "ref.zarr"
    power_matrix(**grid, workers=1, store=str(ref), command="test")
    store = tmp_path / "killed.zarr"
    kill_after("from parapend.performance import power_matrix",  # 2 of the 6 bins stored
               f"power_matrix(**{grid!r}, workers=1, store=sys.argv[1], command='test', "
               "progress=slow)", store, 4)
    import zarr

    done = np.asarray(zarr.open_group(store, mode="r")["done"][...])
    assert 0 < done.sum() < done.size
    t = time.monotonic()
    _, _, run, _ = power_matrix(**grid, workers=2, store=str(store), command="test")
    assert 0 < run.computed_points < 12 and run.resumed_points >= 4, time.monotonic() - t
    assert _files(store) == _files(ref)


def test_outputs_read_back(tiny, tmp_path):
    import xarray as xr

    ds, store = tiny
    nc, zr, csv = tmp_path / "m.nc", tmp_path / "m.zarr", tmp_path / "m.csv"
    out, _, run, _ = power_matrix(**TINY, store=str(store), netcdf=str(nc), zarr=str(zr),
                                  csv=str(csv), width=0.5)
    assert run.computed_points == 0  # resumed: nothing computed
    back = xr.open_dataset(nc)
    assert np.array_equal(back["power_matrix"].values, ds["power_matrix"].values)
    back.close()
    z = xr.open_zarr(zr, consolidated=False).load()
    assert np.array_equal(z["capture_width_matrix"].values, ds["capture_width_matrix"].values)
    rows = csv.read_text().splitlines()
    head = rows[0].split(",")
    assert len(rows) == 1 + 4 and head[:3] == ["hm0", "te", "tp"]
    row = dict(zip(head, rows[2].split(",")))  # hm0 = 1, te = 7
    assert float(row["power_mean"]) == ds["power_mean"].values[0, 1]
    assert float(row["capture_width_ratio_matrix"]) == pytest.approx(
        ds["capture_width_matrix"].values[0, 1] / 0.5, rel=1e-15)
    assert int(row["power_count"]) == 2
    # an export is replaced; the store (or any other directory) never is
    power_matrix(**TINY, store=str(store), zarr=str(zr))
    with pytest.raises(parapend.ParameterError, match="not an export of a power matrix"):
        power_matrix(**TINY, store=str(store), zarr=str(store))
    assert (store / "power").is_dir()


def test_map_refuses_a_power_matrix_store(tiny, capsys):
    _, store = tiny
    assert main(["map", "--store", str(store), "--plot", "x.png"]) == 2
    err = capsys.readouterr().err
    assert "holds a power matrix" in err and len(err.strip().splitlines()) == 1


def test_bins_past_breaking_are_marked_with_their_share_of_the_year(tmp_path, capsys):
    """A rectangle of bins holds a corner past breaking (Hm0 6 m at Te 3 s): solved, and
    marked by the closed-form steepness ``Hs / (g Tp^2 / (2 pi)) > 1/7``, with the share of
    the year and the annual energy the site gives it."""
    import json

    (tmp_path / "s.csv").write_text("hs,te,frequency\n1,3,0.25\n6,3,0.25\n1,7,0.25\n6,7,0.25\n")
    argv = ["power-matrix", "--hs", "1,6", "--te", "3,7", "--realizations", "1", "--waves",
            "4", "--workers", "1", "--scatter", str(tmp_path / "s.csv")]
    assert main(argv + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    tp = np.array([3.0, 7.0]) / te_over_tp("jonswap", 3.3)
    steep = np.array([[h / (9.81 * t * t / (2 * math.pi)) for t in tp] for h in (1.0, 6.0)])
    assert steep[1, 0] > 1 / 7 and (np.delete(steep.ravel(), 2) < 1 / 7).all()
    assert [(b["hm0"], b["te"]) for b in out["bins_past_breaking"]] == [(6.0, 3.0)]
    assert out["bins_past_breaking"][0]["steepness"] == pytest.approx(steep[1, 0], rel=1e-12)
    assert out["past_breaking_frequency"] == 0.25
    pm = out["power_matrix"][1][0]
    assert out["past_breaking_mwh"] == pytest.approx(HOURS_PER_YEAR * 0.25 * pm / 1e6,
                                                     rel=1e-12)
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "1 bin past breaking (Hs / lambda_p > 1/7" in text and "(Hm0 6 m, te 3 s)" in text
