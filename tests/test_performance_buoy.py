"""``parapend power-matrix --device buoy``: each bin is the coupled optimum of the buoy's
design on the prescribed device's seeded record (checked against ``coupled_optimum`` run by
hand), the radiation bound is never exceeded, the store resumes, bad combinations fail in
one line. The body is the small Capytaine sphere of tests/test_buoy_cli.py (``--hydro``)."""

import json
import math

import numpy as np
import pytest

from parapend.cli import main
from parapend.hydro.bem import load
from parapend.hydro.coupled import Pendulum, Wave
from parapend.hydro.optimum import coupled_optimum
from parapend.performance.resource import te_over_tp
from parapend.seas import sea_record
from parapend.units import Units

# 2 x 2 bins (the fewest the edges allow), one realization of 4-wave records
PEND = {"mass": 20.0, "length": 0.3, "damping_coefficient": 0.5, "harmonics": 24}
ARGS = ["--hs", "0.1,0.2", "--tp", "2.6,3.0", "--realizations", "1", "--waves", "4",
        "--seed", "7", "--mass", "20", "--length", "0.3", "--damping-coefficient", "0.5",
        "--harmonics", "24", "--workers", "1"]


@pytest.fixture(scope="module")
def run(sphere_nc, tmp_path_factory):
    """The CLI's JSON on a fresh store, then on the finished store (a resume)."""
    import contextlib
    import io

    store = str(tmp_path_factory.mktemp("pm") / "m.zarr")
    outs = []
    for _ in range(2):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(["power-matrix", "--device", "buoy", "--hydro", sphere_nc, *ARGS,
                         "--store", store, "--json"]) == 0
        outs.append(json.loads(buf.getvalue()))
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):  # the text report, from the finished store
        assert main(["power-matrix", "--device", "buoy", "--hydro", sphere_nc, *ARGS,
                     "--store", store]) == 0
    outs.append(buf.getvalue())
    return outs


def _by_hand(sphere_nc, hs, tp, seed, waves=4.0):
    """The record built from ``sea_record`` and ``coupled_optimum`` called directly."""
    pend = Pendulum(mass=PEND["mass"], length=PEND["length"],
                    inertia=PEND["mass"] * PEND["length"] ** 2,
                    damping_coefficient=PEND["damping_coefficient"])
    exc = sea_record(Units(pend.length, pend.mass, 9.81, pend.inertia), hs=hs, tp=tp,
                     repeat_period=waves * tp, seed=seed)
    wave = Wave(2 * math.pi / (waves * tp), np.asarray(exc.heave[1:], dtype=complex))
    h = load(sphere_nc)
    sol = coupled_optimum(h, pend, wave, harmonics=PEND["harmonics"])
    ow = coupled_optimum(h, pend, wave, harmonics=PEND["harmonics"], one_way=True)
    return sol.power, sol.radiation_bound, ow.power


def test_a_bin_is_the_coupled_optimum_by_hand(run, sphere_nc):
    out = run[0]
    assert out["device"] == "buoy" and out["failed_solves"] == 0
    assert out["width"] is None  # a dataset has no known width
    st = out["statistics"]
    p, bound, one_way = _by_hand(sphere_nc, 0.2, 3.0, 7)
    assert st["power"]["mean"][1][1] == pytest.approx(p, rel=1e-10)
    assert st["radiation_bound_power"]["mean"][1][1] == pytest.approx(bound, rel=1e-10)
    assert st["one_way_power"]["mean"][1][1] == pytest.approx(one_way, rel=1e-10)
    # the Te/Tp conversion is the prescribed device's
    ratio = te_over_tp("jonswap", 3.3)
    assert out["te"] == pytest.approx([2.6 * ratio, 3.0 * ratio], rel=1e-14)


def test_the_radiation_bound_is_never_exceeded(run):
    st = run[0]["statistics"]
    p = np.array(st["power"]["max"])
    b = np.array(st["radiation_bound_power"]["min"])
    assert np.all(p > 0) and np.all(p <= b)
    # the bound scales as Hs^2 on the same phases (the heights are 0.1 and 0.2 m)
    assert np.allclose(b[1] / b[0], 4.0, rtol=1e-12)


def test_the_store_resumes_to_the_same_numbers(run):
    first, again, text = run
    assert "power matrix, coupled buoy: 2 Hm0 x 2 tp bins" in text
    assert "found finished 4" in text
    assert first["computed_bins"] == 4 and again["resumed_bins"] == 4
    assert again["computed_bins"] == 0
    assert again["statistics"] == first["statistics"]


@pytest.mark.parametrize("extra, match", [
    (["--response", "x.csv"], "response:"),
    (["--gamma", "0.01"], "gamma:"),
    (["--efficiency", "1.2"], "efficiency:"),
    (["--winding", "auto"], "winding:"),
    (["--tp", "2.0,2.6"], "tp: the record of the bin 2 s spans"),
    (["--mass", "1000"], "mass:"),
])
def test_bad_combinations_fail_in_one_line(extra, match, sphere_nc, capsys, tmp_path):
    args = [a for a in ARGS]
    if extra[0] == "--tp" or extra[0] == "--mass":
        k = args.index(extra[0])
        args[k + 1] = extra[1]
        extra = []
    store = tmp_path / "s.zarr"
    assert main(["power-matrix", "--device", "buoy", "--hydro", sphere_nc, *args, *extra,
                 "--store", str(store)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    assert match in err, err
    assert not store.exists()


def test_a_body_without_the_buoy_is_refused(capsys):
    assert main(["power-matrix", "--radius", "0.5"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "radius: a body is only used with --device buoy" in err


@pytest.mark.slow
def test_default_width_is_the_bodys_diameter(tmp_path, capsys, monkeypatch):
    """A sphere meshed and solved by Capytaine (cached under tmp_path): the capture-width
    ratio is over 2 radius unless --width is given."""
    monkeypatch.setenv("PARAPEND_CACHE", str(tmp_path / "cache"))
    args = [a for a in ARGS]
    assert main(["power-matrix", "--device", "buoy", "--body", "sphere", "--radius", "0.5",
                 *args, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["width"] == 1.0
    cw = np.array(out["capture_width_matrix"])
    assert np.allclose(np.array(out["capture_width_ratio_matrix"]), cw / 1.0, rtol=1e-14)


@pytest.fixture(scope="module")
def run_eff(sphere_nc, tmp_path_factory):
    """``--efficiency 0.9``: the JSON on a fresh store, then on the finished store."""
    import contextlib
    import io

    store = str(tmp_path_factory.mktemp("pm") / "e.zarr")
    args = list(ARGS)
    args[1] = "0.4,0.6"  # higher seas than ARGS': at 0.1, 0.2 m the take-off loses
    outs = []
    for _ in range(2):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(["power-matrix", "--device", "buoy", "--hydro", sphere_nc, *args,
                         "--efficiency", "0.9", "--store", store, "--json"]) == 0
        outs.append(json.loads(buf.getvalue()))
    return outs


@pytest.mark.slow
def test_a_bin_with_an_efficiency_is_parapend_buoy_by_hand(run_eff, sphere_nc):
    """A bin's electrical power is ``parapend.buoy(..., efficiency=0.9)``'s on the same
    record and dataset; the store resumes to the same numbers."""
    import parapend

    first, again = run_eff
    assert again["resumed_bins"] == 4
    # a bin whose solve did not converge is left out (None), and it is exactly the record
    # that parapend.buoy alone does not solve either (Hs 0.4 m, Tp 3 s on this coarse
    # sphere stalls since the dataset's mass is its displacement): counted, never filled
    missing = [(i, j) for i, row in enumerate(first["power_matrix"])
               for j, v in enumerate(row) if v is None]
    assert first["failed_solves"] == len(missing) <= 1
    for i, j in missing:
        hs, tp = (0.4, 0.6)[i], (2.6, 3.0)[j]
        alone = parapend.buoy(hs=hs, tp=tp, repeat_period=4 * tp, seed=7, hydro=sphere_nc,
                              efficiency=0.9, mass=PEND["mass"], length=PEND["length"],
                              damping_coefficient=PEND["damping_coefficient"],
                              harmonics=PEND["harmonics"])
        assert not alone.success
    assert again["statistics"] == first["statistics"]
    st = first["statistics"]
    r = parapend.buoy(hs=0.6, tp=3.0, repeat_period=4 * 3.0, seed=7, hydro=sphere_nc,
                      efficiency=0.9, mass=PEND["mass"], length=PEND["length"],
                      damping_coefficient=PEND["damping_coefficient"],
                      harmonics=PEND["harmonics"])
    assert st["electrical_power"]["mean"][1][1] == pytest.approx(r.electrical_power_w,
                                                                 rel=1e-9)
    # the headline is the electrical power, as buoy's power_w (the rule)
    assert st["power"] == st["electrical_power"]
    assert st["power"]["mean"][1][1] == pytest.approx(r.power_w, rel=1e-9)
    assert first["power_matrix"][1][1] == pytest.approx(r.power_w, rel=1e-9)
    # the mechanical power of that motion: the optimum is flat in the motion, so a motion
    # within the solver's tolerance of the same electrical power moves it more
    assert st["mechanical_power"]["mean"][1][1] == pytest.approx(r.mechanical_power_w,
                                                                 rel=1e-4)
    # the take-off loses: electrical <= mechanical <= the radiation bound, in every bin
    e, p, bound = (np.array(st[k][m], dtype=float) for k, m in (
        ("electrical_power", "max"), ("mechanical_power", "max"),
        ("radiation_bound_power", "min")))
    solved = np.isfinite(e)
    assert solved.sum() == 4 - len(missing)
    assert r.success and np.all(e[solved] > 0) and np.all(e[solved] <= p[solved])
    assert np.all(p[solved] <= bound[solved])
