"""Each command's parameters are declared once: in the signature of its function.

The command line reads every option's default from the signature of the command's function
(``parapend.cli._common._Parser.declare_defaults``), so there is no second copy to drift:
changing a default in the signature changes the command line's, for every option of every
command; the parser that ``main`` uses (the defaults read when the command is parsed)
gives the same values as the one built with every default read at once; and ``sea``,
``buoy`` and ``horizon`` are the implementing functions themselves, not wrappers that
restate their signatures; ``sweep`` and ``power-matrix`` take the signatures of the
implementations (:func:`parapend.maps.sweep`, :func:`parapend.performance.power_matrix`) and
shape their answers, restating nothing. The defaults the help texts state (77 options) agree
with the signatures.
"""

from __future__ import annotations

import argparse
import inspect

import pytest

import parapend
from parapend import commands
from parapend.cli import build_parser


def _subparsers(**kw):
    parser = build_parser(**kw)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


COMMANDS = sorted(_subparsers())


def _function(command):
    return getattr(commands, command.replace("-", "_"))


def _parameter_options(parser, command):
    """The parser's options that are parameters of the command's function."""
    params = inspect.signature(_function(command)).parameters
    skip = commands.presentation(command)
    return [a for a in parser._actions
            if a.option_strings and a.dest in params and a.dest not in skip]


@pytest.mark.parametrize("command", COMMANDS)
def test_the_option_default_is_the_signature_default(command, monkeypatch):
    """Give every parameter a new default (a marker no parser could hold of its own), in the
    function that declares it (the implementation's, for ``sweep`` and ``power-matrix``):
    every option's default follows, so neither the parser nor a forwarding function keeps a
    default of its own."""
    fn = inspect.unwrap(_function(command))
    marks = {name: ("declared once", command, name) for name in fn.__kwdefaults__}
    monkeypatch.setattr(fn, "__kwdefaults__", {**fn.__kwdefaults__, **marks})
    if fn.__defaults__:  # positional parameters with defaults (the sweep's store)
        code = fn.__code__
        names = code.co_varnames[:code.co_argcount][-len(fn.__defaults__):]
        marks.update({name: ("declared once", command, name) for name in names})
        monkeypatch.setattr(fn, "__defaults__", tuple(marks[name] for name in names))
    options = _parameter_options(_subparsers()[command], command)
    assert options, command
    for action in options:
        if isinstance(action, argparse._AppendAction):
            assert action.default == list(marks[action.dest]), (command, action.dest)
        else:
            assert action.default is marks[action.dest], (command, action.dest)


@pytest.mark.parametrize("command", COMMANDS)
def test_each_option_default_equals_the_function_default(command):
    """Parsed as ``main`` parses (defaults read when the command is parsed), the command with
    no options gives every parameter option the function's default, and every option of the
    command (but the presentation ones) is a parameter of the function."""
    fn = _function(command)
    params = inspect.signature(fn).parameters
    sub = _subparsers(declare=False)[command]
    skip = commands.presentation(command) | {"help"}
    for action in sub._actions:
        if action.dest not in skip and action.option_strings:
            assert action.dest in params, f"{command}: --{action.dest} is not a parameter"
    argv = [command] + (["5"] if command == "figure" else [])
    ns = vars(build_parser(declare=False).parse_args(argv))
    for action in _parameter_options(sub, command):
        want = params[action.dest].default
        got = ns[action.dest]
        if isinstance(action, argparse._AppendAction):
            assert tuple(got) == tuple(want), (command, action.dest)
        else:
            assert got == want and type(got) is type(want), (command, action.dest, got, want)


@pytest.mark.parametrize("name, module, function", [
    ("sea", "parapend.irregular", "sea"), ("buoy", "parapend.hydro.api", "buoy"),
    ("horizon", "parapend.control.horizon", "horizon_curve")])
def test_the_implementation_is_the_public_function(name, module, function):
    """No forwarding wrapper restates these signatures: ``parapend.<name>`` is the function
    that answers the command, and its docstring documents its parameters."""
    import importlib

    impl = getattr(importlib.import_module(module), function)
    assert getattr(parapend, name) is impl is getattr(commands, name)
    assert "Parameters" in impl.__doc__


@pytest.mark.parametrize("name, module, function", [
    ("sweep", "parapend.maps.run", "sweep"),
    ("power_matrix", "parapend.performance", "power_matrix")])
def test_a_forwarding_command_has_the_implementation_s_signature(name, module, function):
    """``parapend.sweep`` and ``parapend.power_matrix`` shape the answer of the function that
    answers the command into the command's result, and take its parameters as they are: the
    signature is the implementation's (no second copy in ``commands.py``), and every argument
    reaches the implementation unchanged."""
    import importlib

    impl = getattr(importlib.import_module(module), function)
    fn = getattr(parapend, name)
    assert fn is getattr(commands, name) and fn is not impl
    assert inspect.unwrap(fn) is impl
    assert inspect.signature(fn) == inspect.signature(impl)
    import re

    assert f"def {name}(" not in inspect.getsource(commands)
    shape = commands.FORWARDED[name][2]
    assert fn.__doc__ == shape.__doc__ and "Returns" in fn.__doc__
    # no parameter list restated in a call either (``omega=omega, ...``)
    passed = set(re.findall(r"\b(\w+)=\1\b", inspect.getsource(shape)))
    assert not passed & set(inspect.signature(impl).parameters), passed


def test_the_forwarded_arguments_reach_the_implementation(monkeypatch):
    """Every argument of ``parapend.sweep`` is handed to :func:`parapend.maps.sweep` as given
    (defaults applied from its signature), positional ``store`` included; an unknown one is
    refused as the implementation refuses it."""
    import parapend.maps.run as mr

    seen = {}

    class Stop(Exception):
        pass

    def fake(*args, **kwargs):
        seen.update(args=args, kwargs=kwargs)
        raise Stop

    fake.__signature__ = inspect.signature(mr.sweep)
    monkeypatch.setattr(commands, "sweep", commands._forward("sweep", fake,
                                                              commands._sweep_result))
    with pytest.raises(Stop):
        commands.sweep("m.zarr", omega="1:2:3", efficiency=0.9)
    defaults = {k: p.default for k, p in inspect.signature(mr.sweep).parameters.items()}
    assert seen["args"] == ("m.zarr",)
    assert seen["kwargs"] == {**{k: v for k, v in defaults.items() if k != "store"},
                              "omega": "1:2:3", "efficiency": 0.9}
    with pytest.raises(TypeError, match="not_an_option"):
        parapend.sweep(not_an_option=1)


def test_horizon_takes_its_controller_options_by_keyword():
    """``parapend.horizon(horizons=..., records=..., update_interval=...)`` was refused with
    "got multiple values for keyword argument": every option is one keyword parameter."""
    params = inspect.signature(parapend.horizon).parameters
    for name in ("horizons", "forecasts", "baselines", "records", "update_interval",
                 "torque_limit_nm", "hs", "tp", "seed"):
        assert params[name].kind is inspect.Parameter.KEYWORD_ONLY
    with pytest.raises(parapend.ParameterError, match="torque-limit-nm: give either"):
        parapend.horizon(horizons="1", records=1, update_interval=0.0625, torque_limit=1.0,
                         torque_limit_nm=5.0)
    with pytest.raises(parapend.ParameterError, match="horizons"):
        parapend.horizon(horizons="0.001", records=1, update_interval=0.0625)


def test_sea_refuses_a_sea_state_beside_a_record(tmp_path):
    """The check the wrapper made is the implementation's own: a sea-state parameter given
    beside a measured record is refused, whatever its value (the default's included)."""
    f = tmp_path / "r.csv"
    f.write_text("t,z\n" + "".join(f"{0.5 * i},0\n" for i in range(64)))
    with pytest.raises(parapend.ParameterError, match="hs, seed: not used with --record"):
        parapend.sea(record=str(f), hs=2.0, seed=0)


def _stated(text):
    """The value a help text states as its default, ``(default X)`` or ``(default X;``, as
    a float, a tuple of floats (``-3:3``) or the text; None where it states none."""
    import re

    m = re.search(r"\(default ([^;()]+)[;)]", text)
    if m is None:
        return None
    tok = m.group(1).strip()
    try:
        return float(tok)
    except ValueError:
        pass
    try:
        return tuple(float(x) for x in tok.split(":"))
    except ValueError:
        return tok


@pytest.mark.parametrize("command", COMMANDS)
def test_a_default_stated_in_the_help_is_the_signature_default(command):
    """Where an option's help states its default as a number or a word and the signature's
    default is a value (not None, resolved inside the function), the two agree: the help
    text is the one copy left beside the signature, and this keeps it from drifting."""
    params = inspect.signature(_function(command)).parameters
    checked = 0
    for action in _parameter_options(_subparsers()[command], command):
        want = params[action.dest].default
        stated = _stated(action.help or "")
        if stated is None or want is None or isinstance(want, bool):
            continue
        if isinstance(stated, float) and isinstance(want, (int, float)):
            assert stated == want, (command, action.dest, stated, want)
        elif isinstance(stated, tuple) and isinstance(want, tuple):
            assert stated == want, (command, action.dest, stated, want)
        elif isinstance(stated, str) and isinstance(want, str):
            assert stated == want, (command, action.dest, stated, want)
        else:
            continue
        checked += 1
    assert checked or command in ("figure", "reproduce", "buoy"), command
