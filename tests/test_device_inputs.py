"""Inputs that compose (parapend.hydro.device, docs/buoy.md "Inputs that compose"): every
option of ``buoy``, ``horizon`` and ``power-matrix`` is declared once, in an input object or
as a documented run option; the objects give the keyword functions' answers; and the
documented script builds a sea, a pendulum, the barge and a take-off once and gets the
optimum, a causal run and a 2 x 2 power matrix from them."""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import math
import re
from pathlib import Path

import pytest
from hull_timedomain import synthetic_hull_netcdf

import parapend
from parapend import commands
from parapend.cli import build_parser
from parapend.hydro import device as dv

DOCS = Path(__file__).resolve().parents[1] / "docs"
COMMANDS = ("buoy", "horizon", "power-matrix")


def _options(command):
    sub = next(a for a in build_parser()._actions
               if isinstance(a, argparse._SubParsersAction)).choices[command]
    skip = commands.presentation(command) | {"help"}
    return [a for a in sub._actions if a.option_strings and a.dest not in skip]


@pytest.mark.parametrize("command", COMMANDS)
def test_every_option_is_declared_once(command):
    """Each option is a declared parameter of one input object, or a run option, never both;
    a declaration carries a unit, a default and a help, and names a keyword of
    ``parapend.buoy`` (the objects are its inputs, grouped)."""
    declared = dv.declarations()
    buoy = inspect.signature(parapend.buoy).parameters
    for action in _options(command):
        name = action.dest
        assert (name in declared) != (name in dv.RUN_OPTIONS), (command, name)
        if name in declared:
            owner, unit, default, _bounds, text = declared[name]
            assert owner in ("Sea", "Pendulum", "Body", "PowerTakeOff", "Controller")
            assert unit and default and text, name
            assert name in buoy, name


def test_each_name_is_declared_in_one_object_and_the_run_options_are_documented():
    fields = [f.name for cls in (dv.Sea, dv.Pendulum, dv.Body, dv.PowerTakeOff, dv.Controller)
              for f in dataclasses.fields(cls)]
    assert len(fields) == len(set(fields))
    assert not set(fields) & set(dv.RUN_OPTIONS)
    text = (DOCS / "buoy.md").read_text(encoding="utf-8")
    assert "RUN_OPTIONS" in text and "declarations()" in text


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return synthetic_hull_netcdf(tmp_path_factory.mktemp("hull") / "hull.nc")


def test_the_objects_give_the_keyword_functions_answers(dataset):
    """A device built once: its hull optimum is ``parapend.buoy``'s with the same keywords,
    bit for bit; its heave-only model is the heaving buoy's; a hull's causal run and horizon
    curve are refused in one line naming what is missing."""
    period = 2 * math.pi / 1.2
    sea = dv.Sea.regular(1.0, period)
    body = dv.Body(hydro=dataset, dofs="surge,heave,pitch", pivot_height=1.5,
                   pivot_offset=1.0)
    pend = dv.Pendulum(mass=4000.0, length=1.0, inertia=5000.0, damping_coefficient=50.0)
    device = dv.Device(body, pend, dv.PowerTakeOff(copper_loss=1e-4))
    got = device.optimum(sea, winding=0)
    want = parapend.buoy(hydro=dataset, dofs="surge,heave,pitch", pivot_height=1.5,
                         pivot_offset=1.0, mass=4000.0, length=1.0, inertia=5000.0,
                         damping_coefficient=50.0, wave_height=1.0, wave_period=period,
                         copper_loss=1e-4, winding=0)
    assert got.power_w == want.power_w and got.mode == want.mode == "swinging"
    heave = dv.Device(body.with_dofs("heave"), pend).optimum(sea)
    assert heave.power_w == parapend.buoy(hydro=dataset, mass=4000.0, length=1.0,
                                          inertia=5000.0, damping_coefficient=50.0,
                                          wave_height=1.0, wave_period=period).power_w
    state = dv.Sea.state(hs=1.0, tp=5.0, repeat_period=20.0)
    with pytest.raises(parapend.ParameterError, match="^dofs: .*by its keywords only"):
        device.horizon(state)


def test_the_commands_take_the_objects(dataset):
    """``parapend.buoy`` takes the objects (``sea=``, ``pendulum=``, ``body=``, ``pto=``, or a
    ``device=``) and gives its keywords' answer bit for bit; a field given twice, of the wrong
    object or not taken by the command is refused in one line naming it, before any work
    (``horizon`` and ``power_matrix`` too)."""
    period = 2 * math.pi / 1.2
    sea = dv.Sea.regular(1.0, period)
    pend = dv.Pendulum(mass=4000.0, length=1.0, inertia=5000.0, damping_coefficient=50.0)
    body = dv.Body(hydro=dataset)
    want = parapend.buoy(hydro=dataset, mass=4000.0, length=1.0, inertia=5000.0,
                         damping_coefficient=50.0, wave_height=1.0, wave_period=period)
    got = parapend.buoy(sea=sea, pendulum=pend, body=body)
    assert got.power_w == want.power_w and got.to_dict() == want.to_dict()
    assert parapend.buoy(sea=sea, device=dv.Device(body, pend)).power_w == want.power_w
    # a keyword beside the objects: the command's own
    assert parapend.buoy(sea=sea, body=body, mass=4000.0, length=1.0, inertia=5000.0,
                         damping_coefficient=50.0).power_w == want.power_w
    bad = [({"sea": sea, "wave_height": 2.0}, "^wave-height: given twice"),
           ({"pendulum": pend, "device": dv.Device(pendulum=pend)}, "^mass: given twice"),
           ({"sea": 3.0}, "^sea: expected a Sea"),
           ({"pendulum": sea}, "^pendulum: expected a Pendulum, got a Sea")]
    for kw, match in bad:
        with pytest.raises(parapend.ParameterError, match=match.replace("a Pendulum",
                                                                        "a Pendulum .*")):
            parapend.buoy(**kw)
    with pytest.raises(parapend.ParameterError, match="^wave-height: not taken by horizon"):
        parapend.horizon(sea=sea, device=dv.Device(body, pend))
    with pytest.raises(parapend.ParameterError, match="^horizon: not taken by horizon"):
        parapend.horizon(device=dv.Device(body, pend),
                         controller=dv.Controller.receding_horizon(2.0))
    with pytest.raises(parapend.ParameterError, match="^records: .*at most"):
        parapend.horizon(device=dv.Device(), records=20)  # the buoy's curve: its estimate
    with pytest.raises(parapend.ParameterError, match="^hydro: given twice"):
        parapend.power_matrix(device=dv.Device(body, pend), body=body, hs="1,2", tp="5,6")
    with pytest.raises(parapend.ParameterError, match="^sea: expected a Sea"):
        parapend.horizon(sea="jonswap")
    # the take-off's torque limit is in N m, the curve's --torque-limit-nm: checked as such
    # (the same one line as the keyword's)
    with pytest.raises(parapend.ParameterError, match="^torque-limit-nm: ") as want:
        parapend.horizon(device="buoy", hydro=dataset, mass=4000.0, length=1.0,
                         torque_limit_nm=-5.0)
    with pytest.raises(parapend.ParameterError) as got:
        parapend.horizon(device=dv.Device(body, pend, dv.PowerTakeOff(torque_limit=-5.0)))
    assert str(got.value) == str(want.value)


@pytest.mark.parametrize("name, extra", [
    ("wave_height", {}), ("wave_period", {}), ("wave_direction", {"hydro": "x.nc"}),
    ("copper_loss", {"dofs": "surge,heave,pitch"}),
    ("hull_pitch_inertia", {"dofs": "surge,heave,pitch"})])
def test_a_declared_bound_is_the_command_s_check(name, extra):
    """The bounds stand in the declaration: a value past its declared upper bound is refused
    by the command in one line that states that bound (parapend.hydro.declared.check)."""
    _owner, _unit, _default, (_lo, hi), _help = dv.declaration(name)
    bound = re.escape(f"{hi:g}")
    with pytest.raises(parapend.ParameterError,
                       match=rf"^{name.replace('_', '-')}: expected .*{bound}\]?, got"):
        parapend.buoy(**{name: 2 * hi + 1}, **extra)


def test_a_declared_default_is_the_command_s_default(monkeypatch):
    """A default that is one value stands in the declaration: the help states it, and the
    command uses it (a declared default changed is the command's new default)."""
    metas = {f.name: f.metadata for cls in (dv.Sea, dv.Controller)
             for f in dataclasses.fields(cls)}
    valued = {k: m for k, m in metas.items() if m["value"] is not None}
    assert {"spectrum", "gamma_peak", "cutoff", "taper", "horizon", "update_interval",
            "forecast"} <= set(valued)
    for name, meta in valued.items():
        value = meta["value"]
        for v in (value.values() if isinstance(value, dict) else [value]):
            assert (v if isinstance(v, str) else f"{v:g}") in dv.option_help(meta), name
    # the commands read it through default_of: a declared default changed is what they get
    from parapend.hydro import declared

    field = next(f for f in dataclasses.fields(dv.Controller) if f.name == "horizon")
    monkeypatch.setitem(field.metadata["value"], "mpc", 1e6)
    assert declared.default_of("horizon", None, "mpc") == 1e6
    assert declared.default_of("horizon", None, "optimum") is None  # none applies
    assert declared.default_of("horizon", 0.0, "mpc") == 0.0  # a value given is kept


def _script() -> str:
    text = (DOCS / "buoy.md").read_text(encoding="utf-8")
    part = text[text.index("## Inputs that compose"):]
    return re.search(r"```python\n(.*?)```", part, re.S).group(1)


def test_the_documented_script_is_short_and_builds_each_input_once():
    lines = [ln for ln in _script().splitlines() if ln.strip()]
    assert len(lines) <= 20
    code = "\n".join(lines)
    for built in ("Sea.state(", "Pendulum(", "Body.barge(", "PowerTakeOff(copper_loss"):
        assert code.count(built) == 1, built
    assert "hull.with_dofs(\"heave\")" in code  # the causal run's body: the same barge
    for asked in (".optimum(", ".causal(", ".power_matrix("):
        assert asked in code, asked


@pytest.mark.slow
def test_the_documented_script_runs(tmp_path, monkeypatch, capsys):
    """The script as written: the hull's optimum, the heave-only causal run, the 2 x 2 power
    matrix, each a number; the matrix's bins are the hull's optima of their records."""
    monkeypatch.chdir(tmp_path)
    scope = {}
    exec(compile(_script(), "docs/buoy.md", "exec"), scope)  # noqa: S102
    best, run, matrix = scope["best"], scope["run"], scope["matrix"]
    assert best.mode in ("rotation", "swinging") and best.power_w > 0
    assert math.isfinite(run.mean_power_w) and type(run).__name__ == "BuoyMPCResult"
    grid = matrix.power_matrix
    assert len(grid) == 2 and all(len(row) == 2 for row in grid)
    # the bin at Hs 1 m, Tp 6 s holds the sea's own record: the device's optimum again
    assert grid[1][0] == pytest.approx(best.power_w, rel=1e-9)
    assert run.mean_power_w <= run.optimum_power_w * (1 + 1e-6)  # causal: never above it
    assert "optimum" in capsys.readouterr().out


def test_buoy_s_options_are_generated_from_the_declarations():
    """``parapend buoy``'s options of the sea, the pendulum, the body (but ``--body`` and
    ``--hydro``, whose help is the command's), the take-off and the controller are made from
    their declarations: the help states the declared help, unit and default
    (the defaults of the embedded buoy and hull, read from parapend.defaults)."""
    from parapend.defaults import BUOY, HULL

    generated = {f.name: f.metadata for cls in (dv.Sea, dv.Pendulum, dv.Body,
                                                 dv.PowerTakeOff, dv.Controller)
                 for f in dataclasses.fields(cls) if f.name not in ("body", "hydro")}
    options = {a.dest: a for a in _options("buoy")}
    for name, meta in generated.items():
        assert options[name].help == dv.option_help(meta), name
        if meta["choices"]:
            assert tuple(options[name].choices) == meta["choices"], name
    assert options["mass"].help.endswith(f"(default {BUOY['mass']:g}; a hull's "
                                         f"{HULL['mass']:g})")


#: options of horizon and power-matrix named as a declared parameter but written by the
#: command (what is left to generate): the bins, the pendulum's torque limit in m g l, a
#: plain efficiency, the causal column's own controller options, the body's name and dataset
#: (and horizon's hidden --controller, the planner's former name, refused)
OWN = {"horizon": {"torque_limit", "efficiency", "dofs", "body", "hydro", "controller"},
       "power-matrix": {"hs", "tp", "efficiency", "torque_limit", "controller", "horizon",
                        "forecast", "update_interval", "dofs", "body", "hydro"}}


@pytest.mark.parametrize("command", ["horizon", "power-matrix"])
def test_horizon_s_and_power_matrix_s_options_are_generated(command):
    """``horizon``'s and ``power-matrix``'s options of the sea and the pendulum (and the
    body's) are made from the same declarations as ``buoy``'s, with the defaults the
    declaration states for that command (the prescribed-heave pendulum's, the buoy's with
    ``--device buoy``, the curve's shorter records)."""
    from parapend.defaults import BUOY, HORIZON, SEA

    metas = {f.name: f.metadata for cls in (dv.Sea, dv.Pendulum, dv.Body, dv.PowerTakeOff,
                                            dv.Controller) for f in dataclasses.fields(cls)}
    options = {a.dest: a for a in _options(command)}
    generated = [n for n in options if n in metas and n not in OWN[command]]
    assert {"seed", "spectrum", "mass", "length", "damping_coefficient"} <= set(generated)
    for name in generated:
        assert options[name].help == dv.option_help(metas[name], command), name
    assert options["mass"].help.endswith(f"(default {SEA['mass']:g}; {BUOY['mass']:g} with "
                                         "--device buoy)")
    if command == "horizon":
        assert f"default {HORIZON['repeat_periods']:g} Tp;" in options["repeat_period"].help


@pytest.mark.slow
def test_the_barge_in_heave_alone():
    """``--body barge`` without ``--dofs``: the hull's heave coefficients (its floating mass
    and stiffness the barge's, rho L B D and rho g L B) under the heaving buoy's model, the
    energy balance closed and the power within the radiation bound."""
    from parapend.defaults import HULL

    r = parapend.buoy(body="barge", mass=2000.0, length=1.0, damping_coefficient=50.0,
                      wave_height=1.0, wave_period=6.0)
    length, beam, draft = (HULL[k] for k in ("barge_length", "barge_beam", "barge_draft"))
    assert r.body["mass_kg"] == pytest.approx(1025.0 * length * beam * draft, rel=1e-3)
    assert r.body["hydrostatic_stiffness_n_per_m"] == pytest.approx(
        1025.0 * 9.81 * length * beam, rel=1e-3)
    assert r.body["width_m"] == beam
    assert r.energy_balance_residual < 1e-9 and 0 < r.power_w <= r.radiation_bound_w
