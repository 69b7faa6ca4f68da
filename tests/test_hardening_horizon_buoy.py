"""Hardening the newest surfaces: ``horizon --device buoy``, ``buoy --controller
mpc``, ``buoy --dofs surge,heave,pitch``: what benchmarks/fuzz31.py found, each refused in
one line naming the parameter before any BEM (the cases below are all refusals, fast)."""

from __future__ import annotations

import pytest

import parapend
from parapend.cli import main
from parapend.errors import ParameterError

HULL = "surge,heave,pitch"


def _one_line(capsys, argv, name):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0]
    assert name in err[0]
    return err[0]


# --- horizon --device buoy ---------------------------------------------------------------------
def test_buoy_horizon_refuses_a_progress_that_is_not_callable():
    # it was called only after the first run: a TypeError deep in the curve
    with pytest.raises(ParameterError, match=r"^progress: expected a callable"):
        parapend.horizon(device="buoy", progress=5)


@pytest.mark.parametrize("mesh", [5, 1.5, ["a.gdf"]])
def test_buoy_horizon_refuses_a_mesh_that_is_not_a_path(mesh):
    # os.fspath's TypeError, after the estimate
    with pytest.raises(ParameterError, match=r"^mesh: expected a path"):
        parapend.horizon(device="buoy", mesh=mesh)


# --- buoy --controller mpc -------------------------------------------------------------------
def test_mpc_with_a_period_sweep_and_a_sea_names_the_conflict():
    # was "controller: mpc runs in an irregular sea state: give --hs and --tp", both given
    with pytest.raises(ParameterError, match=r"^wave-period: a regular wave or an irregular"):
        parapend.buoy(controller="mpc", hs=0.5, tp=2.5, wave_period="1:3:5")


def test_mpc_with_a_period_sweep_alone_still_asks_for_a_sea():
    with pytest.raises(ParameterError, match=r"^controller: mpc runs in an irregular sea"):
        parapend.buoy(controller="mpc", wave_period="1:3:5")


def test_cli_mpc_period_sweep_conflict(capsys):
    _one_line(capsys, ["buoy", "--controller", "mpc", "--hs", "0.5", "--tp", "2.5",
                       "--wave-period", "1:3:5"], "wave-period")


# --- buoy --dofs surge,heave,pitch --------------------------------------------------------------
def test_hull_refuses_the_forecast():
    # --forecast was accepted and ignored (the hull has no causal controller)
    with pytest.raises(ParameterError, match=r"^forecast: not available with --dofs"):
        parapend.buoy(dofs=HULL, forecast="ar")


@pytest.mark.parametrize("name, value", [("spectrum", "jonswap"), ("gamma_peak", 2.0),
                                         ("cutoff", 2.0), ("taper", 0.2)])
def test_hull_refuses_a_seas_options_with_a_regular_wave(name, value):
    # ignored before (the heaving buoy refuses them)
    flag = name.replace("_", "-")
    with pytest.raises(ParameterError, match=rf"^{flag}: an irregular sea's option"):
        parapend.buoy(dofs=HULL, **{name: value})


@pytest.mark.parametrize("name", ["wave_height", "wave_period"])
def test_hull_refuses_a_regular_wave_beside_a_sea(name):
    # the regular wave's option was ignored beside --hs/--tp
    flag = name.replace("_", "-")
    with pytest.raises(ParameterError, match=rf"^{flag}: a regular wave or an irregular sea"):
        parapend.buoy(dofs=HULL, hs=1.0, tp=6.0, **{name: 1.0 if name == "wave_height"
                                                     else 6.0})


def test_hull_taper_needs_a_record():
    with pytest.raises(ParameterError, match=r"^taper: needs --record"):
        parapend.buoy(dofs=HULL, hs=1.0, tp=6.0, taper=0.2)


def test_cli_hull_forecast(capsys):
    _one_line(capsys, ["buoy", "--dofs", HULL, "--forecast", "ar"], "forecast")


def test_cli_hull_spectrum_with_a_regular_wave(capsys):
    _one_line(capsys, ["buoy", "--dofs", HULL, "--spectrum", "jonswap"], "spectrum")


@pytest.mark.slow
@pytest.mark.parametrize("name, value", [("gamma_peak", 0.0), ("cutoff", 0.0)])
def test_hull_checks_a_zero_instead_of_replacing_it(name, value):
    # `opts.get(name) or default` turned a 0 given into the default (the hull's BEM runs first)
    flag = name.replace("_", "-")
    with pytest.raises(ParameterError, match=rf"^{flag}: expected"):
        parapend.buoy(dofs=HULL, hs=1.0, tp=6.0, **{name: value})


@pytest.mark.slow
@pytest.mark.parametrize("pto", [{"efficiency": 0.9}, {"torque_limit": 50.0}])
def test_mpc_with_a_power_take_off_runs_a_record_above_the_take_offs_cap(pto):
    # the optimum's cap with a power take-off (256 harmonics, 16 waves) refused the causal
    # run's records (the default one has about 123 waves) though the run's yardstick is the
    # mechanical optimum. A record of 25 waves is above that cap (the optimum through the
    # take-off refuses it) and its mechanical optimum takes seconds, the default record's
    # minutes
    record = dict(hs=0.5, tp=2.5, repeat_period=50.0)
    with pytest.raises(ParameterError, match=r"^repeat-period: with --efficiency or "
                                             r"--torque-limit this record needs 400 harmonics"):
        parapend.buoy(**record, **pto)
    r = parapend.buoy(controller="mpc", time_limit=1.0, **record, **pto)
    assert r.status == "time_limit" and not r.success
    assert r.optimum_power_w is not None and r.optimum_power_w > 0
