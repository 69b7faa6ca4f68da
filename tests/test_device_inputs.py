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
#: the commands of the floating body, whose options are generated from the declarations
COMMANDS = ("buoy", "horizon", "power-matrix")
_SUB = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
ALL_COMMANDS = sorted(_SUB.choices)
_METAS = {f.name: f.metadata for cls in (dv.Sea, dv.Pendulum, dv.Body, dv.PowerTakeOff,
                                         dv.Controller) for f in dataclasses.fields(cls)}


def _options(command):
    skip = commands.presentation(command) | {"help"}
    return [a for a in _SUB.choices[command]._actions
            if a.option_strings and a.dest not in skip]


@pytest.mark.parametrize("command", ALL_COMMANDS)
def test_every_option_is_declared_once(command):
    """Every option of every command is a declared parameter of one input object, a run
    option of the floating body's commands or an option of the prescribed-motion commands
    (``RUN_OPTIONS``, ``PRESCRIBED_OPTIONS``: each with what it is), exactly one of them; a
    declaration carries a unit, a default and a help, and names a keyword of
    ``parapend.buoy`` (the objects are its inputs, grouped). Where a command states a
    declared parameter in its own unit (the prescribed-motion pendulum's torque in ``m g
    l``), the declaration says so for that command, and the option's help names that unit."""
    declared = dv.declarations()
    buoy = inspect.signature(parapend.buoy).parameters
    for action in _options(command):
        name = action.dest
        homes = [name in declared, name in dv.RUN_OPTIONS, name in dv.PRESCRIBED_OPTIONS]
        assert sum(homes) == 1, (command, name, homes)
        if name in declared:
            owner, unit, default, _bounds, text = declared[name]
            assert owner in ("Sea", "Pendulum", "Body", "PowerTakeOff", "Controller")
            assert unit and default and text, name
            assert name in buoy, name
            unit = _METAS[name]["commands"].get(command, {}).get("unit", unit)
            if unit != "-" and action.help != argparse.SUPPRESS:
                assert unit in (action.help or ""), (command, name, unit, action.help)


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


def test_the_embedded_designs_defaults_and_bounds_are_declared(monkeypatch):
    """The pendulum's, the sea's and the bodies' defaults of the embedded buoy and hull stand
    in the declarations (``value``, one per body; ``parapend.defaults``), and the
    objects apply them: a declared default changed is what the command gets, for the buoy
    and the hull alike. A hull's sea state given only ``hs`` takes the hull's peak period
    (the small buoy's 2.5 s was taken before). A declared bound is the check."""
    from parapend.defaults import BUOY, HULL
    from parapend.hydro import declared
    from parapend.hydro.inputs import _irregular_wave
    from parapend.units import Units

    assert dv.Pendulum().checked().mass == BUOY["mass"]
    assert dv.Pendulum().checked("hull").mass == HULL["mass"]
    assert dv.Pendulum(mass=7.0).checked("hull").mass == 7.0
    field = next(f for f in dataclasses.fields(dv.Pendulum) if f.name == "mass")
    monkeypatch.setitem(field.metadata["value"], "hull", 1234.0)
    assert dv.Pendulum().checked("hull").mass == 1234.0
    units = Units(1.0, 2000.0, 9.81, None)
    for kind, want in (("buoy", BUOY["tp"]), ("hull", HULL["tp"])):
        _, info = _irregular_wave(1.0, None, "jonswap", 3.3, 40.0, None, 3.0, None, 0.1,
                                  units, kind=kind)
        assert info["tp"] == want and info["seed"] == 0, kind
    for name, bad in (("mass", 0.0), ("length", -1.0), ("inertia", 0.0)):
        with pytest.raises(parapend.ParameterError, match=f"^{name}: expected a number > 0"):
            dv.Pendulum(**{name: bad}).checked()
    lo, hi = dv.declaration("barge_length")[3]
    with pytest.raises(parapend.ParameterError, match=rf"^barge-length: expected .*{hi:g}"):
        parapend.buoy(dofs="surge,heave,pitch", barge_length=2 * hi)
    with pytest.raises(parapend.ParameterError, match=r"^torque-limit: expected .*1e\+12"):
        dv.PowerTakeOff(torque_limit=1e13).hull()
    assert declared.default_of("barge_length", None, "hull") == HULL["barge_length"]


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
    # the hull's own causal run, once it has one, is one word away: device.causal
    assert "heave.causal(" in code and "device.causal" in code
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


@pytest.mark.parametrize("command", COMMANDS)
def test_the_floating_body_s_options_are_generated(command):
    """Every option of ``buoy``, ``horizon`` and ``power-matrix`` named as a declared
    parameter is made from its declaration: the help states the declared help, unit and
    default, or those the declaration states for that command (the prescribed-heave
    pendulum's defaults, the buoy's with ``--device buoy``, the curve's shorter records, the
    matrix's bins and causal column, the curve's torque limit in m g l), with its choices;
    none is written by the command (but horizon's hidden --controller, the planner's former
    name, refused in one line)."""
    from parapend.defaults import BUOY, HORIZON, HULL, SEA

    options = {a.dest: a for a in _options(command)}
    generated = [n for n in options if n in _METAS]
    assert {"seed", "spectrum", "mass", "length", "damping_coefficient", "body", "hydro",
            "torque_limit", "efficiency"} <= set(generated)
    for name in generated:
        action, meta = options[name], _METAS[name]
        if action.help == argparse.SUPPRESS:
            assert (command, name) == ("horizon", "controller")
            continue
        assert action.help == dv.option_help(meta, command), (command, name)
        choices = meta["commands"].get(command, {}).get("choices", meta["choices"])
        assert (tuple(action.choices) if action.choices else None) == choices, name
    if command == "buoy":
        assert options["mass"].help.endswith(f"(default {BUOY['mass']:g}; a hull's "
                                             f"{HULL['mass']:g})")
    else:
        assert options["mass"].help.endswith(f"(default {SEA['mass']:g}; {BUOY['mass']:g} "
                                             "with --device buoy)")
    if command == "horizon":
        assert f"default {HORIZON['repeat_periods']:g} Tp;" in options["repeat_period"].help
        assert ", m g l (default none)" in options["torque_limit"].help
    if command == "power-matrix":
        assert options["hs"].help.endswith("(default 1:3:3)")
        assert tuple(options["controller"].choices) == ("mpc", "none")


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
