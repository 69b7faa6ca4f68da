"""Surge, heave and pitch hydrodynamics of a hull (hydro/bem.py):
interpolation rules, mass matrix, datasets and bad input (no BEM); the BEM of a coarse barge
(144 panels, 4 frequencies, 1 s) against closed forms (hydrostatics, long-wave limits that fix
the signs), a six-DOF dataset Capytaine wrote; the heave entries against bem's heave-only BEM,
Haskind's relation between excitation and damping, a stable sphere (slow)."""

import math

import numpy as np
import pytest
import xarray as xr

from parapend.errors import ParameterError
from parapend.hydro import bem

RHO, G = 1025.0, 9.81


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("PARAPEND_CACHE", str(tmp_path / "cache"))


def synthetic(pitch_inertia=2.0e5):
    """A small hull: symmetric A, B (B positive semidefinite), complex F."""
    w = np.array([0.5, 1.0, 2.0, 4.0])
    base_a = np.array([[1e4, 0, 2e4], [0, 9e4, 0], [2e4, 0, 4e5]])
    base_b = np.array([[1e3, 0, 3e3], [0, 4e4, 0], [3e3, 0, 2e4]])
    a = np.array([base_a * (1 + 0.1 * i) for i in range(4)])
    b = np.array([base_b * (1 + 0.5 * i) for i in range(4)])
    f = np.array([[1e4j * (i + 1), 3e5 - 1e4 * i + 2e3j, 5e3 + 8e4j * (i + 1)]
                  for i in range(4)])
    c = np.diag([0.0, 4.0e5, 3.0e6])
    return bem.HullHydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                        hydrostatic_stiffness=c, mass=4.1e4, pitch_inertia=pitch_inertia,
                        description="synthetic")


def test_interpolation_rules():
    h = synthetic()
    a, b, f = h.coefficients(np.array([1.0, 1.5, 3.0]))
    assert a.shape == (3, 3, 3) and b.shape == (3, 3, 3) and f.shape == (3, 3)
    assert np.allclose(a[0], h.added_mass[1]) and np.allclose(b[0], h.radiation_damping[1])
    assert np.allclose(a[1], 0.5 * (h.added_mass[1] + h.added_mass[2]))
    assert np.allclose(f[2], 0.5 * (h.excitation[2] + h.excitation[3]))
    # above: A held, B = F = 0
    a, b, f = h.coefficients(5.0)
    assert a.shape == (3, 3) and np.allclose(a, h.added_mass[-1])
    assert np.all(b == 0) and np.all(f == 0)
    assert list(h.above_range([4.0, 4.5])) == [False, True]
    # below: A held, B -> 0, F -> C[:, 1] linearly
    a, b, f = h.coefficients(np.array([[0.0, 0.25]]))
    assert a.shape == (1, 2, 3, 3)
    assert np.allclose(a[0, 0], h.added_mass[0]) and np.all(b[0, 0] == 0)
    assert np.allclose(f[0, 0], h.hydrostatic_stiffness[:, 1])
    assert np.allclose(b[0, 1], 0.5 * h.radiation_damping[0])
    assert np.allclose(f[0, 1], 0.5 * (h.hydrostatic_stiffness[:, 1] + h.excitation[0]))
    # the heave entries interpolate as the heave-only Hydro does
    hv = h.heave()
    ws = np.array([0.0, 0.3, 0.7, 3.3, 9.0])
    a3, b3, f3 = h.coefficients(ws)
    a1, b1, f1 = hv.coefficients(ws)
    assert np.allclose(a3[:, 1, 1], a1) and np.allclose(b3[:, 1, 1], b1)
    assert np.allclose(f3[:, 1], f1)


def test_symmetrised_and_psd():
    h = synthetic()
    a = np.array(h.added_mass)
    a[:, 0, 2] *= 1.01
    b = np.array(h.radiation_damping)
    b[:, 1, 1] -= 1e-3 * b[:, 1, 1].max() + b[:, 1, 1]  # slightly negative: noise
    g = bem.HullHydro(omega=h.omega, added_mass=a, radiation_damping=b,
                     excitation=h.excitation, hydrostatic_stiffness=h.hydrostatic_stiffness,
                     mass=h.mass)
    assert np.array_equal(g.added_mass, np.swapaxes(g.added_mass, 1, 2))
    assert np.all(np.linalg.eigvalsh(g.radiation_damping) >= -1e-9 * np.abs(b).max())
    assert any("positive semidefinite" in n for n in g.notes)
    b[:, 1, 1] = -0.5 * np.abs(b).max()
    with pytest.raises(ParameterError, match="not positive semidefinite"):
        bem.HullHydro(omega=h.omega, added_mass=a, radiation_damping=b,
                     excitation=h.excitation, hydrostatic_stiffness=h.hydrostatic_stiffness,
                     mass=h.mass)


def test_mass_matrix_heave_and_periods():
    h = synthetic()
    assert np.array_equal(h.mass_matrix(1000.0), np.diag([4.0e4, 4.0e4, 2.0e5]))
    assert h.mass_matrix(0.0, pitch_inertia=3e5)[2, 2] == 3e5
    with pytest.raises(ParameterError, match="^mass:"):
        h.mass_matrix(5e4)
    with pytest.raises(ParameterError, match="^hull-pitch-inertia:"):
        synthetic(pitch_inertia=None).mass_matrix(10.0)
    with pytest.raises(ParameterError, match="^hull-pitch-inertia:"):
        h.mass_matrix(10.0, pitch_inertia=-1.0)
    hv = h.heave()
    assert isinstance(hv, bem.Hydro) and hv.mass == h.mass
    assert hv.hydrostatic_stiffness == h.hydrostatic_stiffness[1, 1]
    assert np.array_equal(hv.radiation_damping, h.radiation_damping[:, 1, 1])
    # the natural period solves C = w^2 (M + A(w)) (an independent check by substitution)
    for dof, i, m in (("heave", 1, h.mass), ("pitch", 2, h.pitch_inertia)):
        w = 2 * math.pi / h.natural_period(dof)
        a, _, _ = h.coefficients(w)
        assert h.hydrostatic_stiffness[i, i] == pytest.approx(w * w * (m + a[i, i]), rel=1e-9)


@pytest.mark.parametrize("inertia", [2.0e5, None])
def test_dataset_round_trip(tmp_path, inertia):
    from capytaine.io.xarray import save_dataset_as_netcdf

    h = synthetic(pitch_inertia=inertia)
    path = tmp_path / "hull.nc"
    save_dataset_as_netcdf(path, h.to_dataset())
    g = bem.load_hull(path)
    for name in ("omega", "added_mass", "radiation_damping", "excitation",
                 "hydrostatic_stiffness"):
        assert np.allclose(getattr(g, name), getattr(h, name), rtol=1e-14, atol=0), name
    assert g.mass == h.mass and g.pitch_inertia == inertia
    assert g.description == "synthetic"
    # Capytaine's own ordering of DOFs (extra ones ignored) and an omega = inf row with NaN
    # excitation (Capytaine 3) read the same
    ds = h.to_dataset()
    extra = ds.reindex(radiating_dof=["Pitch", "Heave", "Sway", "Surge"],
                       influenced_dof=["Heave", "Surge", "Sway", "Pitch"], fill_value=0.0)
    inf_row = extra.isel(omega=[0]).assign_coords(omega=[np.inf])
    inf_row["excitation_force"] = inf_row["excitation_force"] * np.nan
    g2 = bem.load_hull(xr.concat([extra, inf_row], dim="omega",
                                data_vars="minimal", coords="minimal", compat="override"))
    assert np.allclose(g2.added_mass, h.added_mass) and np.allclose(g2.excitation, h.excitation)
    assert np.allclose(g2.hydrostatic_stiffness, h.hydrostatic_stiffness)


def _bad(ds, match):
    with pytest.raises(ParameterError, match=match) as err:
        bem.load_hull(ds)
    assert "\n" not in str(err.value)


def test_bad_datasets_refused_in_one_line():
    ds = synthetic().to_dataset()
    two = ["Surge", "Heave"]
    _bad(ds.sel(radiating_dof=two, influenced_dof=two), "no pitch degree of freedom")
    two = ["Heave", "Pitch"]
    _bad(ds.sel(radiating_dof=two, influenced_dof=two), "no surge degree of freedom")
    bad = ds.copy(deep=True)
    bad["added_mass"][1, 0, 0] = np.nan
    _bad(bad, "added_mass holds NaN")
    bad = ds.copy(deep=True)
    bad["radiation_damping"][:, 0, 2] *= 3.0
    _bad(bad, "radiation_damping is not symmetric")
    bad = ds.copy(deep=True)
    bad["radiation_damping"][:, 1, 1] = -bad["radiation_damping"][:, 1, 1]
    _bad(bad, "radiation_damping")
    _bad(ds.drop_vars("hydrostatic_stiffness"), "hydrostatic_stiffness is missing")
    _bad(ds.drop_vars("inertia_matrix"), "the mass is missing")
    bad = ds.copy(deep=True)
    bad["hydrostatic_stiffness"][1, 1] = -1.0
    _bad(bad, "heave hydrostatic_stiffness > 0")
    _bad(ds.assign_coords(wave_direction=[1.0]), "no wave direction 0")
    with pytest.raises(ParameterError, match="no such file"):
        bem.load_hull("/nonexistent/hull.nc")


def test_unstable_hulls_refused_before_any_bem():
    with pytest.raises(ParameterError, match=r"^draft: a sphere .* neutral .* draft below"):
        bem.sphere_hull(2.0)
    with pytest.raises(ParameterError, match=r"^draft: a box barge .* below length/sqrt\(6\)"):
        bem.barge(length=2.0, beam=4.0, draft=1.0)
    with pytest.raises(ParameterError, match=r"^draft: a cylinder .* radius/sqrt\(2\)"):
        bem.cylinder_hull(1.0, 1.0)
    with pytest.raises(ParameterError, match="^beam:"):
        bem.barge(beam=-1.0)


@pytest.mark.slow
def test_immersed_inertia_closed_forms():
    # hemisphere: V = 2 pi R^3 / 3, integral of x^2 = integral of z^2 = V R^2 / 5
    v, ix, iz = bem._cap_integrals(2.0, 2.0)
    assert v == pytest.approx(2 * math.pi * 8 / 3, rel=1e-13)
    assert ix == pytest.approx(v * 4 / 5, rel=1e-13) and iz == pytest.approx(v * 4 / 5, rel=1e-13)
    # a shallow cap against the panels' quadrature of the same solid (mesh error only)
    cpt = bem._quiet_capytaine()
    r, d = 3.0, 1.0
    mesh = cpt.mesh_sphere(radius=r, center=(0, 0, r - d), resolution=(60, 80)).immersed_part()
    v, ix, iz = bem._cap_integrals(r, d)
    assert v == pytest.approx(math.pi * d * d * (3 * r - d) / 3, rel=1e-13)
    assert bem._mesh_pitch_inertia(mesh, RHO) == pytest.approx(RHO * (ix + iz), rel=1e-2)
    # box: the midpoint rule on flat panels is exact up to the known dx^2 / 12 term
    L, B, D, h = 10.0, 4.0, 1.0, 1 / 3
    _, hull, _ = bem._box_meshes(L, B, D, h, 3.0)
    dx = L / (2 * math.ceil(L / (2 * math.sqrt(2) * h)))
    exact = RHO * L * B * D * (L * L / 12 - dx * dx / 12 + D * D / 3)
    assert bem._mesh_pitch_inertia(hull, RHO) == pytest.approx(exact, rel=1e-12)


# -- BEM (a coarse barge, cached for the module) ------------------------------------------------
L, B, D = 10.0, 4.0, 1.0
OMEGA = np.array([0.05, 0.6, 1.0, 1.6])


@pytest.fixture(scope="module")
def coarse_barge(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PARAPEND_CACHE", str(tmp_path_factory.mktemp("cache")))
        return bem.barge(L, B, D, omega=OMEGA, refine=0.5)


def _dx(h):
    return L / (2 * math.ceil(L / (2 * math.sqrt(2) * h)))


def test_barge_hydrostatics_and_conventions(coarse_barge):
    h = coarse_barge
    assert np.array_equal(h.omega, OMEGA)
    c = h.hydrostatic_stiffness
    # heave: rho g L B exactly; pitch: rho g (I_wp + V z_b), z_b = -D/2, with I_wp the
    # panels' midpoint rule B L (L^2 - dx^2) / 12 (exact on the flat bottom)
    h_panel = bem.mesh_size(min(L, B), OMEGA[-1]) / 0.5
    i_wp = B * L * (L * L - _dx(h_panel) ** 2) / 12
    assert c[1, 1] == pytest.approx(RHO * G * L * B, rel=1e-12)
    assert c[2, 2] == pytest.approx(RHO * G * (i_wp - L * B * D * D / 2), rel=1e-12)
    assert np.all(c[0] == 0) and abs(c[1, 2]) < 1e-9 * c[1, 1]
    assert h.mass == pytest.approx(RHO * L * B * D, rel=1e-12)
    assert h.pitch_inertia == pytest.approx(h.mass * (L * L / 12 + D * D / 3), rel=1e-14)
    assert np.array_equal(h.added_mass, np.swapaxes(h.added_mass, 1, 2))
    assert np.array_equal(h.radiation_damping, np.swapaxes(h.radiation_damping, 1, 2))
    assert np.all(np.linalg.eigvalsh(h.radiation_damping) >= -1e-9 * h.radiation_damping.max())
    # long-wave limits of the excitation, which fix the conjugation and the pitch sign. The
    # wave exp(i (w t - k x)) has the slope -i k per metre of amplitude: a quarter period
    # after its crest passes O the water is higher at +x, which turns +x up, a negative
    # pitch; so F_pitch -> +i k (C55 + g A_15) (the tilted water's restoring moment, with
    # the added mass's share of the horizontal acceleration). Under the crest the water
    # moves towards +x and accelerates a quarter period earlier: F_surge -> +i k g
    # (rho V + A_11) (G. I. Taylor's long-wave force). A long wave lifts: F_heave -> C33.
    # All to O(k L)^2 and O(k D) (here 3e-4).
    k = OMEGA[0] ** 2 / G
    f, a = h.excitation[0], h.added_mass[0]
    assert f[2].imag / (k * (c[2, 2] + G * a[0, 2])) == pytest.approx(1.0, abs=2e-3)
    assert f[0].imag / (G * k * (h.mass + a[0, 0])) == pytest.approx(1.0, abs=2e-3)
    assert f[1].real / c[1, 1] == pytest.approx(1.0, abs=2e-3)
    assert abs(f[0].real) < 1e-6 * abs(f[0]) and abs(f[2].real) < 1e-6 * abs(f[2])


@pytest.mark.slow
def test_haskind_relation_for_the_barge(coarse_barge):
    """3D deep water: B_ii = k / (8 pi rho g c_g) * integral over directions of |F_i|^2,
    c_g = g / (2 w): the damping of the radiation problems against the excitation of
    diffraction problems from 16 directions on the same mesh and lid."""
    cpt = bem._quiet_capytaine()
    h_panel = bem.mesh_size(min(L, B), OMEGA[-1]) / 0.5
    mesh, _, lid = bem._box_meshes(L, B, D, h_panel, OMEGA[-1])
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid, center_of_mass=(0, 0, 0),
                            dofs=cpt.rigid_body_dofs(only=list(bem.DOFS),
                                                     rotation_center=(0, 0, 0)))
    dirs = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    w = OMEGA[1:3]
    test = xr.Dataset(coords={"omega": w, "wave_direction": dirs, "water_depth": [np.inf],
                              "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver(method="direct").fill_dataset(test, body, n_jobs=1, progress_bar=False)
    fx = (ds["excitation_force"].sel(influenced_dof=list(bem.DOFS))
          .transpose("omega", "wave_direction", "influenced_dof").values)
    # the trapezoidal rule on a periodic function: spectral accuracy in the directions
    integral = np.sum(np.abs(fx) ** 2, axis=1) * (2 * np.pi / dirs.size)
    k = w * w / G
    cg = G / (2 * w)
    haskind = k[:, None] / (8 * np.pi * RHO * G * cg[:, None]) * integral
    b = np.diagonal(coarse_barge.radiation_damping[1:3], axis1=1, axis2=2)
    # the two sides come from different BEM problems: agreement to the mesh's error
    assert np.allclose(b, haskind, rtol=0.05)
    # and the direction-0 excitation is the dataset's (conjugated)
    assert np.allclose(np.conj(fx[:, 0]), coarse_barge.excitation[1:3], rtol=1e-10)


@pytest.mark.slow
def test_cylinder_heave_entries_are_bem_cylinder(tmp_path):
    w = np.array([0.5, 1.0, 2.0])
    h3 = bem.cylinder_hull(2.0, 1.0, omega=w, refine=0.5)
    h1 = bem.cylinder(2.0, 1.0, omega=w, refine=0.5)
    hv = h3.heave()
    assert np.array_equal(hv.omega, h1.omega)
    assert np.allclose(hv.added_mass, h1.added_mass, rtol=1e-9)
    assert np.allclose(hv.radiation_damping, h1.radiation_damping, rtol=1e-9)
    assert np.allclose(hv.excitation, h1.excitation, rtol=1e-9)
    assert hv.hydrostatic_stiffness == pytest.approx(h1.hydrostatic_stiffness, rel=1e-12)
    assert hv.mass == pytest.approx(h1.mass, rel=1e-12)
    # the true cylinder's (the panels' polygon displaces 0.2 % less)
    assert h3.pitch_inertia == pytest.approx(RHO * math.pi * 4 * (4 / 4 + 1 / 3), rel=1e-14)
    # cached: a second call reads the same numbers back
    again = bem.cylinder_hull(2.0, 1.0, omega=w, refine=0.5)
    assert np.array_equal(again.added_mass, h3.added_mass)
    assert again.pitch_inertia == h3.pitch_inertia and again.notes == h3.notes


@pytest.mark.slow
def test_barge_from_a_mesh_file_and_its_dataset(tmp_path, coarse_barge):
    from capytaine.io.xarray import save_dataset_as_netcdf
    from test_buoy_hydro import _gdf

    h_panel = bem.mesh_size(min(L, B), OMEGA[-1]) / 0.5
    _, hull, _ = bem._box_meshes(L, B, D, h_panel, OMEGA[-1])
    path = _gdf(tmp_path / "barge.gdf", hull)
    w = OMEGA[1:3]
    h3 = bem.hull_from_mesh(path, omega=w)
    h1 = bem.from_mesh(path, omega=w)
    # the heave entries are the heave-only BEM's on the same panels (no lid in either)
    hv = h3.heave()
    assert np.allclose(hv.added_mass, h1.added_mass, rtol=1e-9)
    assert np.allclose(hv.radiation_damping, h1.radiation_damping, rtol=1e-9)
    assert np.allclose(hv.excitation, h1.excitation, rtol=1e-9)
    assert hv.mass == pytest.approx(h1.mass, rel=1e-12)
    # the same hydrostatics as the built-in barge; the pitch inertia of the panels' box
    assert np.allclose(h3.hydrostatic_stiffness, coarse_barge.hydrostatic_stiffness,
                       rtol=1e-9, atol=1e-9 * coarse_barge.hydrostatic_stiffness.max())
    dx = _dx(h_panel)
    assert h3.pitch_inertia == pytest.approx(h3.mass * (L * L / 12 - dx * dx / 12 + D * D / 3),
                                             rel=1e-12)
    # the built-in barge's real data through NetCDF and back
    save_dataset_as_netcdf(tmp_path / "barge.nc", coarse_barge.to_dataset())
    back = bem.load_hull(tmp_path / "barge.nc")
    for name in ("omega", "added_mass", "radiation_damping", "excitation",
                 "hydrostatic_stiffness"):
        assert np.allclose(getattr(back, name), getattr(coarse_barge, name), rtol=1e-14,
                           atol=1e-14 * np.abs(getattr(coarse_barge, name)).max()), name
    assert back.pitch_inertia == coarse_barge.pitch_inertia


@pytest.mark.slow
def test_a_sphere_above_its_centre_is_stable():
    r, d = 2.0, 1.0
    h = bem.sphere_hull(r, draft=d, omega=[0.5, 1.0], refine=0.5)
    v = math.pi * d * d * (3 * r - d) / 3
    c = h.hydrostatic_stiffness
    # panels: volume and waterplane to the mesh's error (about 1 %)
    assert h.mass == pytest.approx(RHO * v, rel=0.02)
    assert c[1, 1] == pytest.approx(RHO * G * math.pi * (r * r - (r - d) ** 2), rel=0.02)
    # the metacentre is the sphere's centre: C55 = rho g V (r - d)
    assert c[2, 2] == pytest.approx(RHO * G * v * (r - d), rel=0.05)
    _, ix, iz = bem._cap_integrals(r, d)
    assert h.pitch_inertia == RHO * (ix + iz)


def test_load_a_six_dof_dataset_capytaine_wrote(tmp_path):
    # a user's own run: six DOFs, two directions, omega = inf (NaN excitation), the
    # hydrostatics and inertia Capytaine computes, saved the standard way
    import capytaine as cpt
    from capytaine.io.xarray import save_dataset_as_netcdf

    mesh = cpt.mesh_vertical_cylinder(length=1.0, radius=0.8, center=(0, 0, 0),
                                      resolution=(3, 12, 4)).immersed_part()
    body = cpt.FloatingBody(mesh=mesh, dofs=cpt.rigid_body_dofs(rotation_center=(0, 0, 0)),
                            center_of_mass=(0, 0, -0.2))
    body.inertia_matrix = body.compute_rigid_body_inertia(rho=RHO)
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
    test = xr.Dataset(coords={"omega": [1.0, 2.0, 3.0, np.inf], "wave_direction": [0.0, 1.0],
                              "radiating_dof": list(body.dofs), "water_depth": [np.inf],
                              "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver().fill_dataset(test, body, progress_bar=False)
    save_dataset_as_netcdf(tmp_path / "user.nc", ds)
    h = bem.load_hull(tmp_path / "user.nc")
    w = [1.0, 2.0, 3.0]
    assert np.array_equal(h.omega, w)
    dofs = list(bem.DOFS)
    sub = ds.sel(radiating_dof=dofs, influenced_dof=dofs, omega=w)
    a = sub["added_mass"].transpose("omega", "radiating_dof", "influenced_dof").values
    assert np.allclose(h.added_mass, 0.5 * (a + np.swapaxes(a, 1, 2)), rtol=1e-12)
    f = ds["excitation_force"].sel(influenced_dof=dofs, wave_direction=0.0, omega=w).values
    assert np.allclose(h.excitation, np.conj(f), rtol=1e-12)
    c = body.hydrostatic_stiffness.sel(influenced_dof=dofs, radiating_dof=dofs).values
    assert np.allclose(h.hydrostatic_stiffness, c, rtol=1e-12)
    m = body.inertia_matrix.sel(influenced_dof=dofs, radiating_dof=dofs).values
    assert h.mass == pytest.approx(m[1, 1], rel=1e-12)
    assert h.pitch_inertia == pytest.approx(m[2, 2], rel=1e-12)
    # the other direction on request
    f1 = ds["excitation_force"].sel(influenced_dof=dofs, wave_direction=1.0, omega=w).values
    assert np.allclose(bem.load_hull(tmp_path / "user.nc", wave_direction=1.0).excitation,
                       np.conj(f1), rtol=1e-12)


def test_own_bem_frequencies_with_indefinite_damping_left_out():
    # the BEM run here: asymmetry noted (not refused), a frequency whose damping is
    # indefinite beyond noise left out; a dataset read from a file is refused instead
    h = synthetic()
    ds = h.to_dataset().copy(deep=True)
    ds["radiation_damping"][3, 0, 2] = ds["radiation_damping"][3, 2, 0] = 1e5
    ds["radiation_damping"][1, 0, 2] = 3e4  # asymmetric: a spike
    ds["added_mass"][:, 0, 2] *= 1.05
    g = bem._hull_from_dataset(ds, c=h.hydrostatic_stiffness, mass=h.mass, own=True,
                              path="the BEM")
    assert np.array_equal(g.omega, h.omega[[0, 2]])
    assert any("at 1, 4 rad/s: left out" in n for n in g.notes)
    assert any("added_mass of the BEM symmetrised" in n for n in g.notes)
    _bad(ds, "radiation_damping is not symmetric")
