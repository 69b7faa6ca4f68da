"""The public surface: one function per command, same options, same defaults, same results.

Walks every subcommand of the parser: each option (but the presentation ones,
``parapend.commands.PRESENTATION``) is a parameter of the package-level function of the
same name with the same default, and a cheap case run through the command line with
``--json`` and through the function gives a result carrying every JSON key, with equal
values where the case is deterministic. Also: the threshold in N m s/rad against the
closed-form conversion, and the uniform rotation through a power take-off against an
independent quadrature.
"""

from __future__ import annotations

import inspect
import json
import math

import numpy as np
import pytest

import parapend
from parapend import commands
from parapend.cli import COMMANDS, build_parser, main
from parapend.results import to_jsonable


def _subparsers():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return sub.choices


def _options(p, command):
    skip = commands.presentation(command)
    return {a.dest: a.default for a in p._actions
            if a.dest not in ("help",) and a.dest not in skip}


def test_every_command_has_its_function():
    names = set(_subparsers())
    assert names == set(COMMANDS)
    for name in names:
        fn = getattr(parapend, name.replace("-", "_"))
        assert callable(fn), name
        assert fn is getattr(commands, name.replace("-", "_")) or name == "sweep"


@pytest.mark.parametrize("command", sorted(_subparsers()))
def test_every_option_is_a_parameter_with_the_same_default(command):
    p = _subparsers()[command]
    fn = getattr(commands, command.replace("-", "_"))
    params = inspect.signature(fn).parameters
    for dest, default in _options(p, command).items():
        assert dest in params, f"{command}: option {dest} is not a parameter of {fn.__name__}"
        api = params[dest].default
        if isinstance(default, (list, tuple)) or isinstance(api, (list, tuple)):
            assert tuple(default) == tuple(api), (command, dest)
        elif api is inspect.Parameter.empty:
            assert default is None, (command, dest)  # a positional (figure's number)
        else:
            assert default == api and (default is None) == (api is None), \
                (command, dest, default, api)


def test_presentation_exclusions_are_listed_once():
    assert set(commands.PRESENTATION) == {"json", "plot", "save"}
    assert "plot" not in commands.presentation("figure")
    assert "plot" not in commands.presentation("map")


def _cli_json(argv, capsys):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def _fields(result) -> dict:
    if hasattr(result, "data_vars"):  # a Dataset: coordinates, variables, attributes
        out = {k: result[k].values for k in result.coords}
        out.update({k: result[k].values for k in result.data_vars})
        return to_jsonable({**out, **result.attrs})
    return to_jsonable(result.to_dict())


def _same(a, b, key):
    if isinstance(a, float) and isinstance(b, float):
        assert math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-15), key
    elif isinstance(a, dict) and isinstance(b, dict):
        assert a.keys() == b.keys(), key
        for k in a:
            _same(a[k], b[k], f"{key}.{k}")
    elif isinstance(a, list) and isinstance(b, list):
        assert len(a) == len(b), key
        for x, y in zip(a, b):
            _same(x, y, key)
    else:
        assert a == b, key


# (argv, keyword arguments, keys that vary run to run)
CASES = [
    (["optimize", "--harmonics", "4"], {"harmonics": 4}, set()),
    (["optimize", "--harmonics", "6", "--gamma", "0.05", "--efficiency", "0.9"],
     {"harmonics": 6, "gamma": 0.05, "efficiency": 0.9}, set()),
    (["threshold", "--harmonics", "8", "--length", "1", "--mass", "10"],
     {"harmonics": 8, "length": 1.0, "mass": 10.0}, set()),
    (["damping-sweep", "--harmonics", "4", "--points", "3"], {"harmonics": 4, "points": 3},
     set()),
    (["harmonics", "--from", "2", "--to", "3", "--length", "2", "--mass", "5"],
     {"n_from": 2, "n_to": 3, "length": 2.0, "mass": 5.0}, set()),
    (["pto-curve", "--vary", "efficiency", "--points", "2", "--harmonics", "8"],
     {"vary": "efficiency", "points": 2, "harmonics": 8}, set()),
    (["simulate", "--periods", "2"], {"periods": 2}, set()),
    (["simulate", "--periods", "2", "--length", "2", "--mass", "3"],
     {"periods": 2, "length": 2.0, "mass": 3.0}, set()),
    (["basins", "--resolution", "4", "--periods", "2", "--accuracy-sample", "100",
      "--engine", "numpy"],
     {"resolution": 4, "periods": 2, "accuracy_sample": 100, "engine": "numpy"},
     {"elapsed_s", "workers", "stats"}),
    (["rotations", "--p-max", "0.5"], {"p_max": 0.5}, set()),
    (["track", "--periods", "20", "--harmonics", "8"], {"periods": 20, "harmonics": 8},
     set()),
    (["track", "--periods", "20", "--harmonics", "8", "--length", "1", "--mass", "10"],
     {"periods": 20, "harmonics": 8, "length": 1.0, "mass": 10.0}, set()),
    (["sea", "--repeat-period", "80", "--harmonics", "32"],
     {"repeat_period": 80.0, "harmonics": 32}, set()),
    (["power-matrix", "--hs", "1,2", "--te", "6,7", "--realizations", "1", "--waves", "3",
      "--workers", "1"],
     {"hs": "1,2", "te": "6,7", "realizations": 1, "waves": 3.0, "workers": 1},
     {"seconds"}),
    (["horizon", "--repeat-period", "48", "--forecasts", "none", "--baselines", "extremum"],
     {"repeat_period": 48.0, "forecasts": "none", "baselines": "extremum"}, set()),
]


@pytest.mark.parametrize("argv, kwargs, varying", CASES, ids=[c[0][0] + str(i)
                                                               for i, c in enumerate(CASES)])
def test_cli_json_equals_the_function(argv, kwargs, varying, capsys):
    cli = _cli_json(argv + ["--json"], capsys)
    fn = getattr(parapend, argv[0].replace("-", "_"))
    got = _fields(fn(**kwargs))
    missing = set(cli) - set(got)
    assert not missing, f"{argv[0]}: JSON keys not in the result: {missing}"
    for key in set(cli) - varying:
        _same(cli[key], got[key], key)


def test_sweep_and_map_through_both(tmp_path, capsys):
    store = str(tmp_path / "m.zarr")
    argv = ["sweep", "--omega", "1.7:1.8:2", "--delta", "-0.3,-0.2", "--harmonics", "4",
            "--store", store, "--workers", "1"]
    cli = _cli_json(argv + ["--json"], capsys)
    rec = parapend.sweep(omega="1.7:1.8:2", delta="-0.3,-0.2", harmonics=4, store=store,
                         workers=1)  # resumed: every point found finished
    got = rec.to_dict()
    assert set(cli) <= set(got)
    for key in ("store", "dims", "points", "blocks", "status_counts", "largest_power"):
        _same(cli[key], got[key], key)
    png = str(tmp_path / "m.png")
    cli = _cli_json(["map", "--store", store, "--plot", png, "--json"], capsys)
    mapped = parapend.map(store=store, plot=png)
    got = mapped.to_dict()
    assert set(cli) <= set(got)
    for key in cli:
        _same(cli[key], got[key], key)
    # the Dataset behind the record, public: the map's power over the swept grid
    ds = mapped.to_dataset()
    assert ds["power"].equals(mapped.dataset["power"]) and ds.sizes["omega"] == 2 \
        and ds.sizes["delta"] == 2 and ds["power"].attrs["units"] == "m g l sqrt(g/l)"


@pytest.mark.slow
def test_records_without_curves_give_their_scalars(tmp_path):
    rec = parapend.figure("1", plot=str(tmp_path / "f.png"))
    ds = rec.to_dataset()
    assert not ds.dims and ds.attrs["command"] == "figure"
    assert rec.plot() is rec.matplotlib_figure


@pytest.mark.slow
def test_figure_through_both(tmp_path, capsys):
    png = str(tmp_path / "f.png")
    cli = _cli_json(["figure", "1", "--plot", png, "--json"], capsys)
    got = parapend.figure("1", plot=png).to_dict()
    assert set(cli) <= set(got)
    for key in cli:
        _same(cli[key], got[key], key)


# --- units ---------------------------------------------------------------------------------
def test_threshold_in_newton_metre_seconds(capsys):
    """c* = gamma* I / t0 = gamma* m l^2 sqrt(g/l) for a point mass (docs/units.md), with
    omega and delta from the heave (omega = 2 pi f sqrt(l/g), delta = -A (2 pi f)^2 / g)."""
    length, mass, f, amp, g = 1.0, 10.0, 0.9, 0.09, 9.81
    r = parapend.threshold(length=length, mass=mass, frequency=f, amplitude=amp)
    w = 2 * math.pi * f
    assert math.isclose(r.omega, w * math.sqrt(length / g), rel_tol=1e-14)
    plain = parapend.threshold(omega=w * math.sqrt(length / g), delta=-amp * w * w / g)
    assert math.isclose(plain.damping_threshold, r.damping_threshold, rel_tol=1e-12)
    expected = r.damping_threshold * mass * g * length * math.sqrt(length / g)
    assert math.isclose(r.damping_threshold_coefficient, expected, rel_tol=1e-13)
    # the uniform threshold |Q1| / 2 omega = |delta| / 2 omega, by hand in SI:
    # c_u = |delta| / (2 omega) * m l^2 / t0
    c_u = amp * w * w / g / (2 * w * math.sqrt(length / g)) * mass * length**2 / \
        math.sqrt(length / g)
    assert math.isclose(r.uniform_threshold_coefficient, c_u, rel_tol=1e-12)
    assert main(["threshold", "--length", "1", "--mass", "10", "--frequency", "0.9",
                 "--amplitude", "0.09"]) == 0
    out = capsys.readouterr().out
    assert f"{expected:.6g} N m s/rad" in out


def test_damping_sweep_in_si():
    ds = parapend.damping_sweep(harmonics=4, points=3, length=2.0, mass=3.0)
    t0 = math.sqrt(2.0 / 9.81)
    np.testing.assert_allclose(ds["damping_coefficient"].values,
                               ds["gamma"].values * 3.0 * 4.0 / t0, rtol=1e-14)
    np.testing.assert_allclose(ds["power_w"].values,
                               ds["power"].values * 3.0 * 9.81 * 2.0 / t0, rtol=1e-14)


# --- like for like -------------------------------------------------------------------------
def _uniform_by_quadrature(omega, delta, gamma, phi, eta, tmax=None):
    """Mean electrical power of theta = omega t + phi under q = delta sin(omega t), by
    adaptive quadrature (scipy.integrate.quad), and its peak torque on a fine grid."""
    from scipy.integrate import quad

    def torque(t):
        return gamma * omega - (1 + delta * math.sin(omega * t)) * math.sin(omega * t + phi)

    def elec(t):
        p = -torque(t) * omega
        return eta * p if p > 0 else p / eta

    period = 2 * math.pi / omega
    val = quad(elec, 0, period, limit=400, epsabs=1e-13, epsrel=1e-12)[0] / period
    t = np.linspace(0, period, 200001)
    tq = gamma * omega - (1 + delta * np.sin(omega * t)) * np.sin(omega * t + phi)
    return val, float(np.max(np.abs(tq)))


def test_uniform_rotation_through_an_efficiency_matches_quadrature():
    from parapend.excitation import harmonic
    from parapend.pto import uniform_under_pto

    exc = harmonic(-0.3, 1.8)
    u = uniform_under_pto(exc, 0.03, efficiency=(0.9, 0.9))
    val, _ = _uniform_by_quadrature(1.8, -0.3, 0.03, u["phase"], 0.9)
    assert math.isclose(u["electrical_power"], val, rel_tol=1e-7, abs_tol=1e-10)
    # no phase does better (a brute-force scan by quadrature)
    scan = [_uniform_by_quadrature(1.8, -0.3, 0.03, ph, 0.9)[0]
            for ph in np.linspace(0, 2 * math.pi, 73)]
    assert max(scan) <= u["electrical_power"] + 1e-9
    # lossless: the closed form of Eq. 17 generalized, omega |delta| / 2 - gamma omega^2
    u1 = uniform_under_pto(exc, 0.03)
    assert math.isclose(u1["power"], 1.8 * 0.3 / 2 - 0.03 * 1.8**2, rel_tol=1e-9)


@pytest.mark.slow
def test_uniform_rotation_under_a_torque_limit():
    from parapend.excitation import harmonic
    from parapend.pto import uniform_under_pto

    exc = harmonic(-0.3, 1.8)
    free = uniform_under_pto(exc, 0.03)
    # a limit below the free optimum's peak but above the smallest peak over phases
    scan = [_uniform_by_quadrature(1.8, -0.3, 0.03, ph, 1.0) for ph in
            np.linspace(0, 2 * math.pi, 721)]
    lowest = min(pk for _, pk in scan)
    tmax = 0.5 * (lowest + free["peak_torque"])
    u = uniform_under_pto(exc, 0.03, torque_limit=tmax)
    assert u["feasible"] and u["peak_torque"] <= tmax * (1 + 1e-9)
    val, peak = _uniform_by_quadrature(1.8, -0.3, 0.03, u["phase"], 1.0)
    assert math.isclose(u["power"], val, rel_tol=1e-8)
    assert peak <= tmax * (1 + 1e-6)
    best_feasible = max(v for v, pk in scan if pk <= tmax)
    assert best_feasible <= u["power"] + 1e-9 and u["power"] < free["power"]
    none = uniform_under_pto(exc, 0.03, torque_limit=0.5 * lowest)
    assert not none["feasible"] and none["power"] is None


def test_optimize_routes_to_the_take_off_and_compares_like_with_like(capsys):
    r = parapend.optimize(harmonics=6, gamma=0.03, efficiency=0.9)
    assert r.unconstrained_power is not None and r.efficiency_generating == 0.9
    assert r.uniform_pto_electrical_power < r.uniform_power  # the take-off costs it
    assert math.isclose(r.gain_over_uniform_pto,
                        r.electrical_power / r.uniform_pto_electrical_power - 1, rel_tol=1e-14)
    assert main(["optimize", "--harmonics", "6", "--gamma", "0.03", "--efficiency",
                 "0.9"]) == 0
    out = capsys.readouterr().out
    assert "same take-off" in out and f"{100 * r.gain_over_uniform_pto:+.2f} %" in out


def test_no_issue_numbers_in_help(capsys):
    for name, p in _subparsers().items():
        text = p.format_help()
        assert "issue" not in text.lower(), name


def test_plots_with_physical_options_have_si_axes(tmp_path):
    """The SI axis beside every non-dimensional torque, power and damping axis, scaled by
    the units (a tick of the SI axis is the non-dimensional value times the unit)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from parapend.units import Units, add_si_axes

    u = Units(1.0, 10.0)
    fig, (a, b) = plt.subplots(2)
    a.set_ylabel("torque (m g l)")
    b.set_ylabel("mean power (m g l / t0)")
    b.set_xlabel(r"damping $\gamma$")
    add_si_axes(fig, u)
    axes = [c for ax in fig.axes for c in ax.child_axes]  # the secondary axes
    labels = [ax.get_ylabel() for ax in axes] + [ax.get_xlabel() for ax in axes]
    assert "torque (N m)" in labels and "power (W)" in labels
    assert "damping c (N m s/rad)" in labels
    sec = [ax for ax in axes if ax.get_ylabel() == "power (W)"][0]
    assert math.isclose(sec._functions[0](1.0), u.power, rel_tol=1e-15)
    plt.close(fig)
    png = str(tmp_path / "p.png")
    assert main(["harmonics", "--from", "2", "--to", "3", "--length", "1", "--mass", "10",
                 "--plot", png]) == 0


def test_track_in_si():
    """Watts = m g l / t0 times the power, N m = m g l times the torque, the forcing period
    2 pi / omega times t0 = sqrt(l / g); a limit in N m is the same limit in m g l."""
    m, length, g = 10.0, 1.0, 9.81
    t0 = math.sqrt(length / g)
    r = parapend.track(periods=20, harmonics=8, length=length, mass=m,
                       torque_limit_nm=3.0 * m * g * length)
    assert math.isclose(r.torque_limit, 3.0, rel_tol=1e-14)
    assert math.isclose(r.mean_power_w, r.mean_power * m * g * length / t0, rel_tol=1e-14)
    assert math.isclose(r.peak_torque_nm, r.peak_torque * m * g * length, rel_tol=1e-14)
    assert math.isclose(r.period_s, 2 * math.pi / r.omega * t0, rel_tol=1e-14)


def test_simulate_in_si():
    """Eq. 1's time unit is sqrt(l/g) and its energy unit m g l."""
    r = parapend.simulate(periods=3, length=2.0, mass=3.0, gravity=9.0)
    t0 = math.sqrt(2.0 / 9.0)
    assert math.isclose(r.forcing_period_s, 2 * math.pi / 2.1 * t0, rel_tol=1e-14)
    assert math.isclose(r.duration_s, 3 * 2 * math.pi / 2.1 * t0, rel_tol=1e-12)
    assert math.isclose(r.final_energy_j, r.energy[-1] * 3.0 * 9.0 * 2.0, rel_tol=1e-14)


def test_sweep_function_is_not_shadowed_by_the_maps_package():
    """``parapend.sweep`` is the command's function however the design-map package was
    imported (a subpackage named ``sweep`` would rebind the attribute on import)."""
    import importlib

    import parapend

    importlib.import_module("parapend.maps.run")
    from parapend.commands import sweep

    assert parapend.sweep is sweep and parapend.maps.sweep is not sweep


def test_track_controller_defaults_are_in_defaults_and_its_table():
    """``track``'s receding-horizon options take their defaults from ``defaults.TRACK``
    (command line and function alike), and docs/defaults.md lists each."""
    from pathlib import Path

    from parapend.defaults import TRACK

    params = inspect.signature(commands.track).parameters
    table = (Path(__file__).resolve().parents[1] / "docs" / "defaults.md").read_text()
    row = next(line for line in table.splitlines() if line.startswith("| controller of `track`"))
    for name, value in TRACK.items():
        assert params[name].default == value
        flag = name.replace("_", "-")
        if value is None:
            assert f"no `--{flag}`" in row
        elif isinstance(value, float):
            assert f"`--{flag} {value:g}`" in row
        else:
            assert f"`--{name} {value}`" in row
