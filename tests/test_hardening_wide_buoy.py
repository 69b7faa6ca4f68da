"""Hardening: a wide, shallow buoy (``--radius 10`` beside the 0.5 m draft) was
refused by the BEM's size ("use --draft ..."): its panels followed the draft. Its panels now
follow the shortest wave solved (12 panel radii a wavelength, the body's own grid ending
there), within half the BEM cap; every body that fitted before keeps its mesh."""

from __future__ import annotations

import math

import pytest

import parapend
from parapend import limits
from parapend.cli import main
from parapend.hydro import bem


@pytest.mark.parametrize("radius, draft", [(0.5, 0.5), (1.0, 0.5), (0.3, 0.5), (1.5, 1.0),
                                           (0.5, 2.0), (3.0, 3.0)])
def test_a_body_that_fitted_keeps_its_mesh(radius, draft):
    h = min(radius, draft) / bem.GEOMETRY_PANELS
    assert bem.cylinder_work(radius, draft, h) <= limits.BUOY_MAX_BEM_WORK
    assert bem.cylinder_scale(radius, draft) == min(radius, draft)


@pytest.mark.parametrize("radius", [2.0, 10.0, 100.0, 1000.0])
def test_a_wide_body_is_meshed_within_half_the_cap(radius):
    scale = bem.cylinder_scale(radius, 0.5)
    assert 0.5 < scale <= radius
    cap = limits.BUOY_MAX_BEM_WORK / 2
    assert bem.cylinder_work(radius, 0.5, scale / bem.GEOMETRY_PANELS) <= cap
    # the smallest such scale: 1 % finer panels exceed it
    assert bem.cylinder_work(radius, 0.5, 0.99 * scale / bem.GEOMETRY_PANELS) > cap
    # the grid ends at the wave 12 panel radii long: the scale itself (deep water)
    top = bem.body_frequencies(scale / bem.GEOMETRY_PANELS)[-1]
    assert 2 * math.pi * 9.81 / top**2 == pytest.approx(scale, rel=1e-6)


@pytest.mark.parametrize("args, period", [
    (["--radius", "100"], "4.97"), (["--radius", "1000"], "15.72"),
    (["--body", "sphere", "--radius", "100"], "8.003")])
def test_waves_too_short_for_a_large_body_are_refused_before_the_bem(args, period, capsys,
                                                                      monkeypatch):
    def no_bem(*a, **k):
        raise AssertionError("the BEM ran")

    monkeypatch.setattr(bem, "_solve", no_bem)
    assert main(["buoy", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "error: wave-period: the waves are too short" in err
    assert f"radius {args[-1]} m" in err and f"periods from {period} s up, got 1.8 s" in err


def test_a_tall_body_is_still_refused_by_its_draft(capsys):
    assert main(["buoy", "--draft", "100"]) == 2
    err = capsys.readouterr().err.strip()
    assert "error: draft:" in err and "--draft at most 2.53 m" in err


@pytest.mark.slow
def test_a_ten_metre_buoy_runs_with_its_mesh_error_stated(tmp_path, monkeypatch):
    # one to three minutes (two BEMs, of 7e4 and 2e4 influence coefficients a frequency)
    monkeypatch.setenv("PARAPEND_CACHE", str(tmp_path))
    r = parapend.buoy(radius=10.0, wave_period=5.0, wave_height=1.0, mass=2000.0, length=1.0)
    assert r.success
    assert 0 < r.power_w <= r.radiation_bound_w
    assert "panel radius 0.337 m" in r.body["description"]
    # the mesh error (against the mesh 1.5 times coarser) is stated and small
    assert r.mesh_error_relative is not None and r.mesh_error_relative < 0.02
