"""The rest of the audit's list: a coefficient that is not a number named in one line, the
data-range error that says one period once and names --cutoff for a sea, and ``buoy
--save`` in every format a result writes."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro.bem import Hydro

PERIOD = 1.3
PEND = ["--mass", "20", "--length", "0.3", "--damping-coefficient", "0.5", "--harmonics", "8"]


def _hydro():
    w = np.linspace(1.0, 5.0, 9)
    return Hydro(w, np.full(9, 100.0), np.full(9, 50.0), np.full(9, 1000.0 + 0j), 8000.0,
                 400.0)


@pytest.mark.parametrize("field", [0, 1, 2, 3])
def test_a_coefficient_that_is_not_a_number_is_named(field):
    args = [np.linspace(1.0, 2.0, 3), np.ones(3), np.ones(3), np.ones(3), 1.0, 1.0]
    args[field] = "x"
    name = ("omega", "added_mass", "radiation_damping", "excitation")[field]
    with pytest.raises(ParameterError, match=f"^hydro: expected {name} as an array of"):
        Hydro(*args)


def test_the_data_range_error_says_one_period_once():
    h = _hydro()
    w = 6.0  # above the data's 5 rad/s
    with pytest.raises(ParameterError) as err:
        h.check_covers(w, w)
    text = str(err.value)
    t = f"{2 * math.pi / w:.4g} s"
    assert text.startswith(f"wave-period: {t} lies outside") and " to " + t not in text
    assert f"{2 * math.pi / 5.0:.4g} s to {2 * math.pi / 1.0:.4g} s" in text


@pytest.mark.parametrize("name", ["tp", "record"])
def test_a_sea_outside_the_data_names_cutoff(name):
    with pytest.raises(ParameterError, match=rf"^{name}: the sea's components from .* "
                                             r"--cutoff .*a smaller --cutoff$"):
        _hydro().check_covers(2.0, 12.0, name=name)


def test_the_cli_names_cutoff_for_a_short_sea(capsys):
    assert main(["buoy", "--hs", "0.5", "--tp", "1.2", "--cutoff", "6"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--cutoff" in err and "rad/s" not in err


@pytest.mark.parametrize("suffix", [".json", ".csv", ".png"])
def test_buoy_save_writes_every_format(sphere_nc, tmp_path, capsys, suffix):
    path = tmp_path / f"motion{suffix}"
    argv = ["buoy", "--hydro", sphere_nc, "--wave-period", str(PERIOD), *PEND, "--json",
            "--save", str(path)]
    assert main(argv) == 0
    shown = json.loads(capsys.readouterr().out)
    data = path.read_bytes()
    if suffix == ".json":
        assert json.loads(data)["power_w"] == shown["power_w"]
    elif suffix == ".csv":
        head, units, first = data.decode().splitlines()[:3]
        assert head.split(",")[0] == "time_s" and units.split(",")[0] == "s"
        assert len(first.split(",")) == len(head.split(","))
    else:
        assert data[:4] == b"\x89PNG"


def test_buoy_save_refuses_an_unknown_format(capsys, tmp_path):
    assert main(["buoy", "--save", str(tmp_path / "motion.xyz")]) == 2
    assert "--save" in capsys.readouterr().err
