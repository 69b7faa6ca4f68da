"""Every public name and command has an entry in the documentation's reference.

Fast: reads the reference's sources (``docs/api.md``, ``docs/cli.rst``), never builds the
site. The public names are the top level's ``_EXPORTS`` (with ``_COMMANDS``), the
``__all__`` of the public modules below and of every subpackage, and the subcommands of
``parapend.cli.build_parser()``. A new public name without a reference entry fails here.
"""

import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import pytest

import parapend
from parapend.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "docs" / "api.md"
CLI = ROOT / "docs" / "cli.rst"

#: modules whose ``__all__`` the API reference documents, besides every subpackage
PUBLIC_MODULES = ("parapend.pto", "parapend.units", "parapend.seas", "parapend.excitation",
                  "parapend.power", "parapend.trajectory", "parapend.results",
                  "parapend.errors", "parapend.limits")

pytestmark = pytest.mark.skipif(not API.exists(), reason="not a source checkout")


def _subpackages() -> list[str]:
    return sorted(f"parapend.{m.name}" for m in pkgutil.iter_modules(parapend.__path__)
                  if m.ispkg and not m.name.startswith("_") and m.name != "cli")


def _documented() -> tuple[set[tuple[str, str]], set[str]]:
    """(module, name) of every autosummary entry, and the modules documented whole
    (``automodule`` with ``:members:``)."""
    entries, whole = set(), set()
    module = None
    for block in re.findall(r"```\{eval-rst\}\n(.*?)```", API.read_text(), re.S):
        lines = block.splitlines()
        in_summary = False
        for i, line in enumerate(lines):
            m = re.match(r"\.\. (?:current)?module:: (\S+)", line)
            if m:
                module, in_summary = m.group(1), False
                continue
            m = re.match(r"\.\. automodule:: (\S+)", line)
            if m:
                module, in_summary = m.group(1), False
                if any(ln.strip() == ":members:" for ln in lines[i + 1:i + 4]):
                    whole.add(m.group(1))
                continue
            if line.startswith(".. autosummary::"):
                in_summary = True
                continue
            if in_summary:
                name = line.strip()
                if name and not name.startswith(":"):
                    assert module, f"autosummary entry {name!r} before any module"
                    entries.add((module, name))
    return entries, whole


def _documented_objects(entries) -> list:
    objs = []
    for module, name in entries:
        obj = getattr(importlib.import_module(module), name)
        if inspect.isclass(obj) or callable(obj):
            objs.append(obj)
    return objs


def test_every_top_level_name_and_command_is_in_the_api_reference():
    entries, _ = _documented()
    top = {name for module, name in entries if module == "parapend"}
    missing = sorted(set(parapend._EXPORTS) - top)
    assert not missing, f"add to docs/api.md (module parapend): {missing}"
    assert set(parapend._COMMANDS) <= top
    extra = sorted(top - set(parapend._EXPORTS) - set(parapend._COMMANDS))
    assert not extra, f"docs/api.md lists names parapend does not export: {extra}"


@pytest.mark.parametrize("module", [*PUBLIC_MODULES, *_subpackages()])
def test_every_public_name_of_a_module_is_in_the_api_reference(module):
    """By name in the module's own section, or the same function or class documented under
    another name (the top level re-exports many); constants only by name."""
    entries, whole = _documented()
    if module in whole:
        return
    mod = importlib.import_module(module)
    names = getattr(mod, "__all__", None)
    assert names is not None, f"{module} has no __all__"
    documented = _documented_objects(entries)
    missing = []
    for name in names:
        if (module, name) in entries:
            continue
        obj = getattr(mod, name)
        if (inspect.isclass(obj) or callable(obj)) and any(obj is d for d in documented):
            continue
        missing.append(name)
    assert not missing, f"add to docs/api.md (section {module}): {missing}"


def test_every_api_entry_exists():
    entries, whole = _documented()
    for module, name in sorted(entries):
        assert hasattr(importlib.import_module(module), name), f"{module}.{name}"
    for module in whole:
        importlib.import_module(module)


def _subcommands(parser) -> list[str]:
    for action in parser._actions:
        if action.__class__.__name__ == "_SubParsersAction":
            return sorted(action.choices)
    return []


def test_cli_reference_is_generated_from_the_whole_parser():
    """docs/cli.rst documents build_parser() itself, every subcommand included; every
    command is a function of the same name in the API reference."""
    text = CLI.read_text()
    directive = re.search(r"\.\. argparse::\n((?:   .*\n?)+)", text)
    assert directive, "docs/cli.rst has no argparse directive"
    options = directive.group(1)
    assert ":module: parapend.cli" in options and ":func: build_parser" in options
    assert ":path:" not in options and ":nosubcommands:" not in options
    commands = _subcommands(build_parser())
    assert commands
    entries, _ = _documented()
    top = {name for module, name in entries if module == "parapend"}
    missing = [c for c in commands if c.replace("-", "_") not in top]
    assert not missing, f"commands without a function in docs/api.md: {missing}"
