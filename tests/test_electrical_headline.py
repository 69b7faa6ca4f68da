"""With an efficiency the headline field is the electrical power.

``optimize`` and ``pto-curve`` through a lossy take-off give ``power``/``power_w`` as the
electrical power (what the take-off delivers, the headline of the text) and the mechanical
``-<T theta'>`` as ``mechanical_power``/``mechanical_power_w``; without an efficiency
``power`` is the mechanical power and there is no mechanical field. Checked against the
efficiency model itself (``e = eta_g p`` generating, ``p / eta_m`` motoring, so the mean
electrical power is at most ``eta_g`` times the mechanical one, equal at eta = 1) and against
the optimum's own instantaneous power series (their means, a second computation). The
constant-brake closed form (``P = T_max omega``, electrical ``eta_g P``) is in
tests/test_pto.py.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import parapend
from parapend.cli import main

#: about 12 s in all (the lossy optimum's fixture): the slow set
pytestmark = pytest.mark.slow

PENDULUM = {"length": 1.0, "mass": 10.0}


@pytest.fixture(scope="module")
def lossy():
    return parapend.optimize(harmonics=6, gamma=0.05, efficiency=0.9, **PENDULUM)


def test_the_headline_power_is_electrical_and_the_mechanical_is_named_so(lossy):
    r = lossy
    assert r.success
    assert r.power == r.electrical_power and r.power_w == r.electrical_power_w
    assert r.mechanical_power is not None and r.mechanical_power_w is not None
    # e(p) <= eta_g p wherever p > 0 and e(p) = p / eta_m < p where p < 0
    assert r.power <= 0.9 * r.mechanical_power + 1e-12
    assert r.power_w == pytest.approx(r.power * r.physical_units.power, rel=1e-14)
    assert r.mechanical_power_w == pytest.approx(r.mechanical_power * r.physical_units.power,
                                                 rel=1e-14)
    d = r.to_dict()
    assert d["power"] == r.power and d["mechanical_power"] == r.mechanical_power
    assert d["power_w"] == r.power_w and d["mechanical_power_w"] == r.mechanical_power_w


def test_the_series_means_are_the_two_powers(lossy):
    """The means over one period of the instantaneous mechanical and electrical powers
    (the saved series, sampled on the motion's own dense grid) are ``mechanical_power``
    and ``power``: the names say which is which."""
    ds = lossy.to_dataset()  # one period, endpoint excluded, 1000 samples
    mech = float(np.mean(ds["instantaneous_power_w"].values))
    elec = float(np.mean(ds["instantaneous_electrical_power_w"].values))
    # the rectangle rule over samples of a power with kinks (the collocation's torque is
    # piecewise linear on 256 intervals, not aligned with the samples): first order in the
    # sample spacing, 5e-4 here; far from the 10 % between the two powers
    assert mech == pytest.approx(lossy.mechanical_power_w, rel=2e-3)
    assert elec == pytest.approx(lossy.power_w, rel=2e-3)


def test_the_json_of_the_command_line_says_the_same(capsys):
    assert main(["optimize", "--harmonics", "6", "--gamma", "0.05", "--efficiency", "0.9",
                 "--length", "1", "--mass", "10", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["power"] == d["electrical_power"] and d["power_w"] == d["electrical_power_w"]
    assert d["power"] < d["mechanical_power"] and d["power_w"] < d["mechanical_power_w"]


def test_without_an_efficiency_power_is_mechanical():
    r = parapend.optimize(harmonics=6, gamma=0.05, torque_limit=2.5)
    assert r.mechanical_power is None and r.mechanical_power_w is None
    assert r.power == pytest.approx(r.electrical_power, rel=1e-12)  # lossless take-off
    assert parapend.optimize(harmonics=4).mechanical_power is None


def test_pto_curve_over_the_efficiency():
    """At eta = 1 the electrical and mechanical powers are one number; below it the
    electrical one is at most eta times the mechanical one."""
    ds = parapend.pto_curve(vary="efficiency", points=2, harmonics=8, gamma=0.05,
                            **PENDULUM)
    eta = ds["value"].values
    p, m = ds["power"].values, ds["mechanical_power"].values
    assert list(eta) == [1.0, 0.5]
    np.testing.assert_array_equal(p, ds["electrical_power"].values)
    np.testing.assert_array_equal(ds["power_w"].values, ds["electrical_power_w"].values)
    assert p[0] == pytest.approx(m[0], rel=1e-12)
    assert p[1] <= eta[1] * m[1] + 1e-12
    assert ds.to_dataset()["mechanical_power_w"].attrs["units"] == "W"
    plain = parapend.pto_curve(points=2, harmonics=8, gamma=0.05)
    assert "mechanical_power" not in plain.to_dataset()
