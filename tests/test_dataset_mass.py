"""Datasets said out loud: the floating mass of a Capytaine dataset (docs/buoy.md, "Bring
your own"). It is the ``inertia_matrix``'s mass (Capytaine's ``compute_rigid_body_inertia``,
``rho V``) unless the dataset states its displacement (``disp_mass``, or ``disp_volume``
times ``rho``), which is then used; where both are present and differ by more than 0.1 %,
a warning names both numbers and the one used, in Python and in the result."""

from __future__ import annotations

import re

import numpy as np
import pytest
from buoy_synthetic import M, synthetic

import parapend
from parapend.cli import main
from parapend.hydro import bem


def _numbers(message):
    return [float(x) for x in re.findall(r"([0-9.]+(?:e[+-]?\d+)?) kg\b", message)]


def test_disp_mass_differing_from_inertia_matrix_is_used_and_said():
    ds = synthetic(n=12).to_dataset().copy(deep=True)
    ds["disp_mass"] = 1.05 * M  # 5 % more than inertia_matrix's mass
    with pytest.warns(UserWarning, match="disp_mass") as caught:
        h = bem.load(ds)
    assert h.mass == 1.05 * M  # the stated displacement is used
    message = str(caught[0].message)
    assert f"{1.05 * M:.6g}" in message and f"{M:.6g}" in message
    assert message.endswith(f"the displacement, {1.05 * M:.6g} kg, is used as the floating mass")
    assert sorted(_numbers(message)) == pytest.approx(sorted([1.05 * M, M, 1.05 * M]),
                                                      rel=1e-5)
    assert message in h.notes  # carried to the result's warnings


def test_disp_volume_times_rho_is_a_stated_displacement():
    ds = synthetic(n=12).to_dataset().copy(deep=True)
    rho = float(ds["rho"])
    ds["disp_volume"] = 0.98 * M / rho
    with pytest.warns(UserWarning, match="disp_volume x rho"):
        h = bem.load(ds)
    assert h.mass == pytest.approx(0.98 * M, rel=1e-14)


def test_agreeing_within_a_thousandth_is_silent_and_missing_both_is_refused():
    ds = synthetic(n=12).to_dataset().copy(deep=True)
    ds["disp_mass"] = M * (1 + 5e-4)
    h = bem.load(ds)  # filterwarnings=error: any warning would fail here
    assert h.mass == M * (1 + 5e-4) and h.notes == ()
    assert bem.load(synthetic(n=12).to_dataset()).mass == M  # inertia_matrix alone
    with pytest.raises(parapend.ParameterError, match="mass is missing"):
        bem.load(ds.drop_vars(["inertia_matrix", "disp_mass"]))


def test_the_hull_reads_its_mass_by_the_same_rule():
    from test_hull_data import synthetic as hull

    h0 = hull()
    ds = h0.to_dataset().copy(deep=True)
    ds["disp_mass"] = h0.mass - 2.0e3  # a 2 t difference on a 41 t hull
    with pytest.warns(UserWarning, match=f"{h0.mass:.6g} kg"):
        h = bem.load_hull(ds)
    assert h.mass == h0.mass - 2.0e3
    assert h.pitch_inertia == h0.pitch_inertia  # the pitch inertia still from inertia_matrix
    assert any("is used as the floating mass" in n for n in h.notes)


def test_the_warning_reaches_the_result_and_the_command_line(tmp_path, capsys):
    from capytaine.io.xarray import save_dataset_as_netcdf

    ds = synthetic(n=40).to_dataset().copy(deep=True)
    ds["disp_mass"] = 1.05 * M
    path = tmp_path / "both.nc"
    save_dataset_as_netcdf(path, ds)
    with pytest.warns(UserWarning, match="disp_mass"):
        r = parapend.buoy(hydro=str(path), wave_period=3.0, mass=50.0, length=0.5)
    said = [w for w in r.warnings if "disp_mass" in w]
    assert len(said) == 1 and f"{1.05 * M:.6g}" in said[0] and f"{M:.6g}" in said[0]
    assert r.body["mass_kg"] == 1.05 * M
    with pytest.warns(UserWarning, match="disp_mass"):
        code = main(["buoy", "--hydro", str(path), "--wave-period", "3", "--mass", "50",
                     "--length", "0.5"])
    assert code == 0
    out = capsys.readouterr().out
    assert re.search(r"note: hydro: .*disp_mass = [0-9.]+ kg and the inertia_matrix's mass",
                     out)
    assert np.isfinite(r.power_w)
