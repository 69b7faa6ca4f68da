"""Heave hydrodynamics (hydro/bem.py): interpolation rules, datasets, cache, bad input
(fast, no BEM), and the BEM against closed forms (slow)."""

import math
import time

import numpy as np
import pytest
import xarray as xr
from buoy_synthetic import C, M, synthetic

from parapend.errors import ParameterError
from parapend.hydro import bem as hy

RHO, G = 1025.0, 9.81


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("PARAPEND_CACHE", str(tmp_path / "cache"))


def small():
    w = np.array([0.5, 1.0, 2.0, 4.0])
    return hy.Hydro(omega=w, added_mass=[10.0, 20.0, 30.0, 40.0],
                    radiation_damping=[1.0, 3.0, 5.0, 7.0],
                    excitation=[90 + 1j, 80 + 2j, 60 + 4j, 20 + 8j],
                    hydrostatic_stiffness=100.0, mass=50.0)


def test_interpolation_rules():
    h = small()
    a, b, f = h.coefficients([1.0, 1.5, 3.0])
    assert np.allclose(a, [20, 25, 35]) and np.allclose(b, [3, 4, 6])
    assert np.allclose(f, [80 + 2j, 70 + 3j, 40 + 6j])
    # above the data: A held, B = F = 0, flagged
    a, b, f = h.coefficients([5.0])
    assert a[0] == 40 and b[0] == 0 and f[0] == 0
    assert list(h.above_range([4.0, 4.5])) == [False, True]
    # below: A held, B -> 0 and F -> C linearly
    a, b, f = h.coefficients([0.25, 0.0])
    assert np.allclose(a, 10) and np.allclose(b, [0.5, 0]) and np.allclose(f, [95 + 0.5j, 100])


def test_impedance_free_response_bound():
    h = small()
    w = 1.5
    d = -w**2 * (50 + 25) + 1j * w * 4 + 100
    assert complex(h.impedance(w)) == pytest.approx(d)
    assert complex(h.free_response(w)) == pytest.approx((70 + 3j) / d)
    assert h.radiation_bound(w, 0.5) == pytest.approx(abs((70 + 3j) * 0.5) ** 2 / 32)
    assert h.radiation_bound(10.0, 1.0) == 0.0
    # long waves: the body follows the surface, Z/a -> 1
    assert complex(h.free_response(1e-6)) == pytest.approx(1.0, abs=1e-6)


def test_check_covers():
    h = small()
    h.check_covers(0.5, 4.0)
    with pytest.raises(ParameterError, match=r"^wave-period: .* outside .* cover"):
        h.check_covers(0.4, 1.0)
    with pytest.raises(ParameterError, match="omega"):
        h.check_covers(1.0, 5.0, name="omega")


def test_frequencies_for():
    w = hy.frequencies_for([1.0, 2.0], 3, count=11)
    assert w[0] == 0.5 and w[-1] == 6.0 and w.size == 11
    with pytest.raises(ParameterError, match="harmonics"):
        hy.frequencies_for(1.0, 0)
    with pytest.raises(ParameterError, match="omegas"):
        hy.frequencies_for(-1.0)


def test_negative_damping_noise_is_clipped_and_arrays_frozen():
    h = hy.Hydro(omega=[1.0, 2.0], added_mass=[1, 1], radiation_damping=[1.0, -1e-9],
                 excitation=[1, 1], hydrostatic_stiffness=1.0, mass=1.0)
    assert h.radiation_damping[1] == 0.0
    with pytest.raises(ValueError):
        h.omega[0] = 3.0


@pytest.mark.parametrize("how", ["capytaine", "separate"])
def test_dataset_round_trip_and_convention(tmp_path, how):
    from capytaine.io.xarray import save_dataset_as_netcdf, separate_complex_values

    h = synthetic(n=40)
    ds = h.to_dataset()
    # Capytaine's convention exp(-i w t): the file holds the conjugate
    assert np.allclose(ds["excitation_force"].values.ravel(), np.conj(h.excitation))
    path = tmp_path / "h.nc"
    if how == "capytaine":
        save_dataset_as_netcdf(path, ds)
    else:
        separate_complex_values(ds).to_netcdf(path)
    back = hy.load(path)
    for name in ("omega", "added_mass", "radiation_damping", "excitation"):
        assert np.array_equal(getattr(back, name), getattr(h, name))
    assert (back.hydrostatic_stiffness, back.mass, back.rho, back.g) == (C, M, h.rho, h.g)
    assert back.water_depth == math.inf


def test_dataset_indexed_by_period(tmp_path):
    from capytaine.io.xarray import save_dataset_as_netcdf

    h = synthetic(n=12)
    ds = h.to_dataset()
    ds = ds.assign_coords(period=("omega", 2 * np.pi / ds["omega"].values))
    ds = ds.swap_dims(omega="period").drop_vars("omega")
    save_dataset_as_netcdf(tmp_path / "p.nc", ds)
    back = hy.load(tmp_path / "p.nc")
    assert np.allclose(back.omega, h.omega, rtol=1e-14)
    assert np.allclose(back.excitation, h.excitation, rtol=1e-14)


def _write(ds, path):
    from capytaine.io.xarray import save_dataset_as_netcdf

    save_dataset_as_netcdf(path, ds)
    return path


def test_load_errors(tmp_path):
    ds = synthetic(n=10).to_dataset()
    surge = ds.assign_coords(radiating_dof=["Surge"], influenced_dof=["Surge"])
    with pytest.raises(ParameterError, match=r"^hydro: .* no heave degree of freedom"):
        hy.load(_write(surge, tmp_path / "a.nc"))
    with pytest.raises(ParameterError, match="hydrostatic_stiffness is missing"):
        hy.load(_write(ds.drop_vars("hydrostatic_stiffness"), tmp_path / "b.nc"))
    with pytest.raises(ParameterError, match="mass is missing"):
        hy.load(_write(ds.drop_vars("inertia_matrix"), tmp_path / "c.nc"))
    with pytest.raises(ParameterError, match="no excitation_force"):
        hy.load(_write(ds.drop_vars("excitation_force"), tmp_path / "d.nc"))
    with pytest.raises(ParameterError, match="no such file"):
        hy.load(tmp_path / "missing.nc")
    (tmp_path / "junk.nc").write_bytes(b"not a netcdf file")
    with pytest.raises(ParameterError, match="cannot read"):
        hy.load(tmp_path / "junk.nc")
    for err in (ParameterError,):
        try:
            hy.load(_write(surge, tmp_path / "e.nc"))
        except err as exc:
            assert "\n" not in str(exc)


def test_cache_write_read_and_corruption(tmp_path):
    h = synthetic(n=20)
    key = "k" * 64
    hy._cache_write(key, h)
    path = hy.cache_dir() / f"{key}.npz"
    assert path.is_file() and str(path).startswith(str(tmp_path))
    back = hy._cache_read(key)
    assert np.array_equal(back.excitation, h.excitation) and back.mass == h.mass
    assert hy._cache_read("x" * 64) is None
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    assert hy._cache_read(key) is None  # corrupt: recomputed, never trusted
    path.write_bytes(b"")
    assert hy._cache_read(key) is None


def test_bad_geometry():
    with pytest.raises(ParameterError, match="radius"):
        hy.cylinder(-1.0, 1.0)
    with pytest.raises(ParameterError, match="draft"):
        hy.cylinder(1.0, 0.0)
    with pytest.raises(ParameterError, match="radius"):
        hy.sphere(float("nan"))
    with pytest.raises(ParameterError, match="draft"):
        hy.cylinder(1.0, 5.0, water_depth=3.0)


def _gdf(path, mesh, drop=0):
    """Write ``mesh`` (quads or triangles as degenerate quads) as a WAMIT .gdf file."""
    v = np.asarray(mesh.vertices)
    faces = [list(f) + [f[-1]] * (4 - len(f)) for f in mesh.faces][drop:]
    lines = ["parapend test mesh", f"1.0 {G}", "0 0", str(len(faces))]
    for f in faces:
        for i in f:
            lines.append(" ".join(f"{x:.12g}" for x in v[i]))
    path.write_text("\n".join(lines) + "\n")
    return path


def test_from_mesh_errors(tmp_path):
    import capytaine as cpt

    mesh = cpt.mesh_vertical_cylinder(length=1.0, radius=0.5, center=(0, 0, 0),
                                      resolution=(2, 8, 4))
    # a hole below the waterline (first panels of the bottom removed)
    with pytest.raises(ParameterError, match=r"^mesh: .* is not closed"):
        hy.from_mesh(_gdf(tmp_path / "hole.gdf", mesh, drop=3))
    up = mesh.translated_z(2.0)
    with pytest.raises(ParameterError, match=r"^mesh: .* no immersed part"):
        hy.from_mesh(_gdf(tmp_path / "up.gdf", up))
    with pytest.raises(ParameterError, match="no such file"):
        hy.from_mesh(tmp_path / "none.gdf")
    (tmp_path / "bad.gdf").write_text("garbage\n")
    with pytest.raises(ParameterError, match="cannot read"):
        hy.from_mesh(tmp_path / "bad.gdf")


# -- BEM against closed forms (slow) ----------------------------------------------------------
R, D = 0.75, 0.75


@pytest.fixture(scope="module")
def cyl(tmp_path_factory):
    # a cold cache of its own, for this fixture alone: the session's cache (PARAPEND_CACHE)
    # is left as it was, so later modules find the bodies already solved there
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PARAPEND_CACHE", str(tmp_path_factory.mktemp("cyl")))
        t0 = time.perf_counter()
        h = hy.cylinder(R, D)
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        again = hy.cylinder(R, D)
        second = time.perf_counter() - t0
    print(f"\ncylinder BEM {first:.2f} s, cached {second:.3f} s: {h.description}")
    # the cache gives back the solve's bits: a cold and a warm run see the same data
    for name in ("omega", "added_mass", "radiation_damping", "excitation"):
        assert np.array_equal(getattr(again, name), getattr(h, name)), name
    assert (again.hydrostatic_stiffness, again.mass) == (h.hydrostatic_stiffness, h.mass)
    return h


@pytest.mark.slow
def test_cylinder_hydrostatics(cyl):
    # the waterline is a polygon of n sides: C = rho g (n/2) r^2 sin(2 pi / n), within 0.6 %
    # of the circle's rho g pi r^2 for the automatic panel size
    c_circle = RHO * G * math.pi * R**2
    assert cyl.hydrostatic_stiffness == pytest.approx(c_circle, rel=6e-3)
    assert cyl.mass == pytest.approx(RHO * math.pi * R**2 * D, rel=6e-3)
    # the mass and the stiffness see the same polygon: M / C = draft / g exactly
    assert cyl.mass / cyl.hydrostatic_stiffness == pytest.approx(D / G, rel=1e-9)


@pytest.mark.slow
def test_cylinder_haskind_and_resonance(cyl):
    w = cyl.omega
    a, b, f = cyl.coefficients(w)
    # Haskind (deep water, axisymmetric body): B = w^3 |F|^2 / (2 rho g^3), an independent
    # relation between the radiation and the diffraction solutions
    # (to 2 % of the peak: without a lid, the irregular frequencies of the interior problem,
    # from about 5.6 rad/s here, disturb the small high-frequency values)
    sel = b > 1e-2 * b.max()
    hask = w[sel] ** 3 * np.abs(f[sel]) ** 2 / (2 * RHO * G**3)
    assert np.allclose(hask, b[sel], rtol=0.02, atol=0.02 * b.max())
    # the +iwt convention: long waves lift the body in phase, F -> C, and Im F ~ w B > 0
    assert f[0].real == pytest.approx(cyl.hydrostatic_stiffness, rel=0.02)
    assert np.all(f[sel].imag > 0)
    # resonance: undamped natural frequency sqrt(C / (M + A)), peak |Z/a| = |F| / (w B)
    wn = cyl.natural_frequency()
    an, bn, fn = (float(np.real(x)) if i < 2 else complex(x)
                  for i, x in enumerate(cyl.coefficients(wn)))
    assert wn == pytest.approx(math.sqrt(cyl.hydrostatic_stiffness / (cyl.mass + an)),
                               rel=1e-9)
    assert abs(complex(cyl.free_response(wn))) == pytest.approx(abs(fn) / (wn * bn), rel=1e-9)
    # the response there lags the wave by a quarter period less the excitation's phase
    assert np.angle(complex(cyl.free_response(wn))) == pytest.approx(
        np.angle(fn) - math.pi / 2, abs=1e-9)
    # long-wave limit of the response: the body follows the surface
    assert abs(complex(cyl.free_response(w[0])) - 1) < 0.05


@pytest.mark.slow
def test_cylinder_mesh_refinement():
    # the automatic panel for w up to 6 rad/s against one 1.5 times finer
    w = np.linspace(0.5, 6.0, 8)
    coarse = hy.cylinder(R, D, omega=w)
    fine = hy.cylinder(R, D, omega=w, refine=1.5)
    a1, b1, f1 = coarse.coefficients(w)
    a2, b2, f2 = fine.coefficients(w)
    # measured: 0.25 % (A), 0.4 % (B) of the peak; the next refinement changes less
    assert np.max(np.abs(a1 - a2)) < 0.01 * np.max(a2)
    assert np.max(np.abs(b1 - b2)) < 0.01 * np.max(b2)
    assert np.max(np.abs(f1 - f2)) < 0.01 * np.max(np.abs(f2))


@pytest.mark.slow
def test_sphere_hulme_limits():
    # Hulme (1982), floating hemisphere in heave: A / (rho 2/3 pi r^3) = 0.8310 at w -> 0 and
    # 0.5 at w -> infinity. The automatic panel (r / 8 here) gives ~2 %; the mass and the
    # stiffness are within the polygon error.
    import capytaine as cpt

    r = 1.0
    h = hy.sphere(r, omega=np.linspace(0.3, 6.0, 8))
    assert h.hydrostatic_stiffness == pytest.approx(RHO * G * math.pi * r**2, rel=0.01)
    assert h.mass == pytest.approx(RHO * 2 / 3 * math.pi * r**3, rel=0.01)
    size = hy.mesh_size(r, 6.0)
    mesh = cpt.mesh_sphere(radius=r, faces_max_radius=size, axial_symmetry=True)
    body = cpt.FloatingBody(mesh=mesh.immersed_part(), dofs=cpt.rigid_body_dofs(only=["Heave"]))
    test = xr.Dataset(coords={"omega": [0.0, np.inf], "radiating_dof": ["Heave"],
                              "water_depth": [np.inf], "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver().fill_dataset(test, body, progress_bar=False)
    mu = ds["added_mass"].values.ravel() / (RHO * 2 / 3 * math.pi * r**3)
    assert mu[0] == pytest.approx(0.8310, rel=0.02)
    assert mu[1] == pytest.approx(0.5, rel=0.025)


@pytest.mark.slow
def test_from_mesh_matches_cylinder(tmp_path):
    import capytaine as cpt

    h = hy.mesh_size(0.5, 6.0)
    mesh = cpt.mesh_vertical_cylinder(length=1.0, radius=0.5, center=(0, 0, 0),
                                      faces_max_radius=h)
    w = np.array([1.0, 3.0, 6.0])
    from_file = hy.from_mesh(_gdf(tmp_path / "cyl.gdf", mesh), omega=w)
    ref = hy.cylinder(0.5, 0.5, omega=w)
    assert from_file.hydrostatic_stiffness == pytest.approx(ref.hydrostatic_stiffness, rel=1e-6)
    assert np.allclose(from_file.added_mass, ref.added_mass, rtol=1e-3)
    assert np.allclose(from_file.excitation, ref.excitation, rtol=1e-3)


@pytest.mark.slow
def test_load_a_dataset_capytaine_wrote(tmp_path):
    # a dataset as a user's own BEM run gives it: several dofs and directions, hydrostatics
    # from Capytaine, omega = inf included (ignored), saved the standard way
    import capytaine as cpt
    from capytaine.io.xarray import save_dataset_as_netcdf

    mesh = cpt.mesh_vertical_cylinder(length=1.0, radius=0.5, center=(0, 0, 0),
                                      resolution=(3, 12, 4)).immersed_part()
    body = cpt.FloatingBody(mesh=mesh, dofs=cpt.rigid_body_dofs(), center_of_mass=(0, 0, -0.2))
    body.inertia_matrix = body.compute_rigid_body_inertia(rho=RHO)
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
    test = xr.Dataset(coords={"omega": [1.0, 2.0, 3.0, np.inf], "wave_direction": [0.0, 1.0],
                              "radiating_dof": list(body.dofs), "water_depth": [np.inf],
                              "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver().fill_dataset(test, body, progress_bar=False)
    save_dataset_as_netcdf(tmp_path / "user.nc", ds)
    h = hy.load(tmp_path / "user.nc")
    assert np.array_equal(h.omega, [1.0, 2.0, 3.0])
    heave = ds.sel(radiating_dof="Heave", influenced_dof="Heave", omega=[1.0, 2.0, 3.0])
    assert np.allclose(h.added_mass, heave["added_mass"].values)
    f = ds["excitation_force"].sel(influenced_dof="Heave", wave_direction=0.0,
                                   omega=[1.0, 2.0, 3.0]).values
    assert np.allclose(h.excitation, np.conj(f))
    assert h.mass == pytest.approx(RHO * float(body.disp_volume), rel=1e-6)
    assert h.hydrostatic_stiffness == pytest.approx(
        float(body.hydrostatic_stiffness.sel(influenced_dof="Heave", radiating_dof="Heave")))
