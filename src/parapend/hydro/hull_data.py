"""Surge, heave and pitch hydrodynamics of a floating hull (issue 30): from Capytaine,
cached, or loaded.

A :class:`HullHydro` holds the linear potential-flow coefficients of a rigid hull in the
degrees of freedom ``xi = (x, z, beta)``, in this order: surge, heave, pitch about the
rotation centre O, in this project's time convention ``x(t) = Re(X exp(+i w t))``
(Capytaine's ``exp(-i w t)`` amplitudes are conjugated on the way in, and nowhere else):

- ``added_mass`` ``A(w)`` and ``radiation_damping`` ``B(w)`` (n, 3, 3), symmetrised, ``B``
  positive semidefinite at every frequency;
- ``excitation`` ``F(w)`` (n, 3), complex, per metre of wave amplitude, waves travelling
  along +x (Capytaine's wave direction 0), phase relative to the wave elevation at the
  origin of the data (O for the built-in hulls);
- ``hydrostatic_stiffness`` ``C`` (3, 3), computed with the whole floating mass
  ``rho V`` at O; ``mass = rho V`` and, where known, ``pitch_inertia`` about O.

Pitch follows Capytaine's sign: a positive pitch turns a point above O towards +x and a
point at +x downwards (a right-handed rotation about +y).

Interpolation (the specification of issue 30): between the data linear in ``w`` (real and
imaginary parts separately); above the data ``A`` held, ``B = F = 0``; below the data ``A``
held, ``B`` and ``F`` linear towards ``B(0) = 0`` and ``F(0) = C[:, 1]`` (a long wave lifts
the hull, and tilts it by the waterplane's first moment).

The bodies (:func:`barge`, :func:`cylinder_hull`, :func:`sphere_hull`, :func:`hull_from_mesh`)
are meshed, gridded and cached as :mod:`parapend.hydro.bem` does for heave, whose machinery
this module reuses; :func:`load_hull` reads a Capytaine dataset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_positive
from . import bem

__all__ = ["DOFS", "HullHydro", "barge", "cylinder_hull", "hull_from_mesh", "load_hull",
           "sphere_hull"]

#: The degrees of freedom, in the order of every array (Capytaine's names).
DOFS = ("Surge", "Heave", "Pitch")

#: Bump when the hull's cached content or its BEM's rules (mesh, lid, frequencies left out)
#: change (with :data:`parapend.hydro.bem.CACHE_VERSION`, in every key).
HULL_CACHE_VERSION = 1


def _interp_columns(x, xp, fp, right=None):
    """``np.interp`` of every column of ``fp`` (n, k) at ``x`` (m,): an array (m, k)."""
    return np.stack([np.interp(x, xp, fp[:, j], right=right) for j in range(fp.shape[1])],
                    axis=-1)


@dataclass(frozen=True, eq=False)
class HullHydro:
    """Surge, heave and pitch coefficients of a floating hull (SI, convention ``exp(+i w t)``).

    Parameters
    ----------
    omega : numpy.ndarray
        Angular frequencies (rad/s), (n,), strictly increasing, all > 0.
    added_mass : numpy.ndarray
        ``A(w)`` (n, 3, 3) over (surge, heave, pitch): kg, kg m, kg m^2. Symmetrised.
    radiation_damping : numpy.ndarray
        ``B(w)`` (n, 3, 3), symmetrised; positive semidefinite at every frequency (a negative
        eigenvalue within ``parapend.limits.BUOY_NEGATIVE_DAMPING_TOL`` of the largest
        ``|B|``, BEM noise, is set to 0 and noted; beyond it is refused).
    excitation : numpy.ndarray
        ``F(w)`` (n, 3) complex, per metre of wave amplitude (N/m, N m/m), waves travelling
        along +x, phase relative to the wave elevation at the origin.
    hydrostatic_stiffness : numpy.ndarray
        ``C`` (3, 3), with the whole floating mass ``rho V`` at O; ``C[1, 1] > 0``.
    mass : float
        ``rho V`` (kg), the displaced mass.
    pitch_inertia : float or None
        The hull's pitch inertia about O (kg m^2), or None when unknown.
    rho, g, water_depth : float
        Water density (kg/m^3), gravity (m/s^2), depth (m, ``inf`` for deep water).
    description : str
        What the coefficients are of.
    notes : tuple of str
        What reading the data changed (symmetrised matrices, damping noise set to 0).
    """

    omega: np.ndarray
    added_mass: np.ndarray
    radiation_damping: np.ndarray
    excitation: np.ndarray
    hydrostatic_stiffness: np.ndarray
    mass: float
    pitch_inertia: float | None = None
    rho: float = 1025.0
    g: float = 9.81
    water_depth: float = math.inf
    description: str = ""
    notes: tuple = ()

    def __post_init__(self):
        from .. import limits

        w = np.array(self.omega, dtype=float).ravel()
        n = w.size
        a = np.array(self.added_mass, dtype=float)
        b = np.array(self.radiation_damping, dtype=float)
        f = np.array(self.excitation, dtype=complex)
        c = np.array(self.hydrostatic_stiffness, dtype=float)
        if not (n >= 1 and a.shape == b.shape == (n, 3, 3) and f.shape == (n, 3)
                and c.shape == (3, 3)):
            raise ParameterError("hydro: expected omega (n,), added_mass and "
                                 "radiation_damping (n, 3, 3), excitation (n, 3) and "
                                 "hydrostatic_stiffness (3, 3) over surge, heave and pitch")
        if not all(np.all(np.isfinite(x)) for x in (w, a, b, f, c)):
            raise ParameterError("hydro: expected finite coefficients (a dataset with NaN or "
                                 "infinite values)")
        if w[0] <= 0 or np.any(np.diff(w) <= 0):
            raise ParameterError("hydro: expected frequencies > 0, strictly increasing")
        if not c[1, 1] > 0:
            raise ParameterError(f"hydro: expected a heave hydrostatic stiffness C[1, 1] > 0, "
                                 f"got {c[1, 1]!r}")
        a = 0.5 * (a + np.swapaxes(a, 1, 2))
        b = 0.5 * (b + np.swapaxes(b, 1, 2))
        notes = tuple(self.notes)
        lam, vec = np.linalg.eigh(b)
        top = max(float(np.max(np.abs(b))), 1e-300)
        if np.any(lam < -limits.BUOY_NEGATIVE_DAMPING_TOL * top):
            i = int(np.argmin(lam.min(axis=1)))
            raise ParameterError(f"hydro: radiation_damping is not positive semidefinite at "
                                 f"{w[i]:.4g} rad/s (eigenvalue {lam[i].min():.3g}, beyond "
                                 f"{limits.BUOY_NEGATIVE_DAMPING_TOL:g} of its largest entry)")
        neg = np.any(lam < 0, axis=1)
        if np.any(neg):
            # BEM noise: the nearest positive semidefinite matrix (negative eigenvalues to 0)
            b[neg] = np.einsum("nij,nj,nkj->nik", vec[neg], np.maximum(lam[neg], 0.0),
                               vec[neg])
            b[neg] = 0.5 * (b[neg] + np.swapaxes(b[neg], 1, 2))
            note = (f"hydro: radiation damping slightly indefinite (BEM noise) made positive "
                    f"semidefinite at {int(np.sum(neg))} frequencies")
            if note not in notes:
                notes = notes + (note,)
        for name, arr in (("omega", w), ("added_mass", a), ("radiation_damping", b),
                          ("excitation", f), ("hydrostatic_stiffness", c)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "mass", check_positive("mass", self.mass))
        if self.pitch_inertia is not None:
            object.__setattr__(self, "pitch_inertia",
                               check_positive("hull-pitch-inertia", self.pitch_inertia))
        object.__setattr__(self, "rho", check_positive("rho", self.rho))
        object.__setattr__(self, "g", check_positive("g", self.g))
        depth = float(self.water_depth)
        if not depth > 0:
            raise ParameterError(f"water_depth: expected a depth > 0 or inf, got {depth!r}")
        object.__setattr__(self, "water_depth", depth)
        object.__setattr__(self, "notes", notes)

    # -- coefficients ------------------------------------------------------------------
    def coefficients(self, w):
        """``(A, B, F)`` at angular frequencies ``w`` (rad/s): shapes ``w.shape + (3, 3)``,
        ``w.shape + (3, 3)``, ``w.shape + (3,)``.

        Linear in ``w`` between the data (real and imaginary parts of ``F`` separately);
        above the data ``A`` held, ``B = F = 0``; below, ``A`` held, ``B`` and ``F`` linear
        towards ``B(0) = 0``, ``F(0) = C[:, 1]``.
        """
        w = np.abs(np.asarray(w, dtype=float))
        x = w.ravel()
        n = self.omega.size
        wd = np.concatenate(([0.0], self.omega))
        bd = np.concatenate((np.zeros((1, 9)), self.radiation_damping.reshape(n, 9)))
        fd = np.concatenate((self.hydrostatic_stiffness[None, :, 1], self.excitation))
        a = _interp_columns(x, self.omega, self.added_mass.reshape(n, 9))
        b = _interp_columns(x, wd, bd, right=0.0)
        f = (_interp_columns(x, wd, fd.real, right=0.0)
             + 1j * _interp_columns(x, wd, fd.imag, right=0.0))
        above = self.above_range(x)[:, None]
        b = np.where(above, 0.0, b)
        f = np.where(above, 0.0, f)
        return (a.reshape(w.shape + (3, 3)), b.reshape(w.shape + (3, 3)),
                f.reshape(w.shape + (3,)))

    above_range = bem.Hydro.above_range
    check_covers = bem.Hydro.check_covers

    def mass_matrix(self, pendulum_mass, pitch_inertia=None):
        """``M_h = diag(rho V - m, rho V - m, I_h)`` (kg, kg, kg m^2): the hull without the
        pendulum of mass ``m`` (it floats at its draft: hull and pendulum weigh ``rho V``).

        ``I_h`` is ``pitch_inertia`` (kg m^2, about O), else the ``pitch_inertia`` field, else
        refused (:class:`~parapend.errors.ParameterError` naming ``hull-pitch-inertia``).
        """
        from ..errors import check_nonnegative

        m = check_nonnegative("mass", pendulum_mass)
        if not m < self.mass:
            raise ParameterError(f"mass: expected a pendulum lighter than the hull's displaced "
                                 f"mass {self.mass:.6g} kg, got {m!r}")
        if pitch_inertia is not None:
            inertia = check_positive("hull-pitch-inertia", pitch_inertia)
        elif self.pitch_inertia is not None:
            inertia = self.pitch_inertia
        else:
            raise ParameterError("hull-pitch-inertia: the hydrodynamic data give no pitch "
                                 "inertia; give the hull's about O (kg m^2)")
        return np.diag([self.mass - m, self.mass - m, inertia])

    def _single(self, i, inertia) -> bem.Hydro:
        """The DOF ``i`` alone as a heave-like :class:`~parapend.hydro.bem.Hydro`."""
        return bem.Hydro(omega=self.omega, added_mass=self.added_mass[:, i, i],
                         radiation_damping=self.radiation_damping[:, i, i],
                         excitation=self.excitation[:, i],
                         hydrostatic_stiffness=float(self.hydrostatic_stiffness[i, i]),
                         mass=inertia, rho=self.rho, g=self.g, water_depth=self.water_depth,
                         description=self.description, notes=self.notes)

    def heave(self) -> bem.Hydro:
        """The heave-only coefficients (same frequencies, the heave entries, ``mass = rho V``),
        for the heave-only kernel (``--dofs heave``)."""
        return self._single(1, self.mass)

    def natural_period(self, dof, pitch_inertia=None) -> float:
        """The uncoupled undamped natural period (s) in ``"heave"`` or ``"pitch"``: the root
        of ``C_ii = w^2 (M_ii + A_ii(w))`` (``M`` of :meth:`mass_matrix` without pendulum);
        ``nan`` where there is none on the data's range."""
        i = {"heave": 1, "pitch": 2}.get(dof)
        if i is None:
            raise ParameterError(f"dof: expected heave or pitch, got {dof!r:.40}")
        inertia = float(self.mass_matrix(0.0, pitch_inertia)[i, i])
        w = self._single(i, inertia).natural_frequency()
        return 2 * math.pi / w if w > 0 else math.nan

    def to_dataset(self):
        """The coefficients as a Capytaine-style :class:`xarray.Dataset` (``exp(-i w t)``,
        DOFs Surge, Heave, Pitch); :func:`load_hull` reads it back."""
        inertia = (None if self.pitch_inertia is None
                   else np.diag([self.mass, self.mass, self.pitch_inertia]))
        ds = bem._dataset(self.omega, self.added_mass, self.radiation_damping, self.excitation,
                          DOFS, self.hydrostatic_stiffness, inertia, rho=self.rho, g=self.g,
                          water_depth=self.water_depth, description=self.description)
        if inertia is None:
            ds["disp_mass"] = self.mass
        return ds


# -- datasets --------------------------------------------------------------------------------
def _dof_block(da, dims, path, name, kind="f"):
    """``da`` restricted to :data:`DOFS` along ``dims``, other dimensions (but omega) at
    their first value, as an array in the order ``("omega",) + dims`` (omega if present)."""
    for dim in dims:
        if dim in da.dims:
            da = da.sel({dim: list(DOFS)})
    keep = ("omega",) + tuple(dims)
    for d in [d for d in da.dims if d not in keep]:
        da = da.isel({d: 0})
    if any(d not in da.dims for d in dims):
        raise ParameterError(f"hydro: {path}: {name} lacks the dimensions {', '.join(dims)}")
    return np.asarray(da.transpose(*[d for d in keep if d in da.dims]).values)


def _resolved(w, a, b, f):
    """Our own BEM's answer at the frequencies its mesh resolves, symmetrised, and notes.

    Where the damping is indefinite beyond noise (``bem._physics``'s threshold: a fraction
    ``BUOY_NEGATIVE_DAMPING_TOL`` of the largest heave damping) or asymmetric beyond
    ``BUOY_SYMMETRY_TOL`` of its largest entry, the mesh does not resolve the problem (a
    spike of an irregular frequency the lid misses, or the grid's top, where the wave is
    12 panel radii long): those frequencies are left out, as bem leaves out the ones its mesh
    cannot resolve (they are then interpolated over, or above range). The asymmetry left is
    a measure of the discretisation error, noted.
    """
    from .. import limits

    asym = np.max(np.abs(b - np.swapaxes(b, 1, 2)), axis=(1, 2)) / float(np.max(np.abs(b)))
    b_sym = 0.5 * (b + np.swapaxes(b, 1, 2))
    low = np.linalg.eigvalsh(b_sym).min(axis=1)
    bad = ((low < -limits.BUOY_NEGATIVE_DAMPING_TOL * float(np.max(b[:, 1, 1])))
           | (asym > limits.BUOY_SYMMETRY_TOL))
    notes = []
    if np.any(bad) and not np.all(bad):
        named = ", ".join(f"{x:.4g}" for x in w[bad])
        notes.append(f"hydro: the BEM's radiation damping is indefinite or asymmetric "
                     f"(discretisation error) at {named} rad/s: left out")
        w, a, b, f = (x[~bad] for x in (w, a, b, f))
    for name, m in (("added_mass", a), ("radiation_damping", b)):
        rel = float(np.max(np.abs(m - np.swapaxes(m, 1, 2)))) / float(np.max(np.abs(m)))
        notes.append(f"hydro: {name} of the BEM symmetrised (relative asymmetry {rel:.2g}, "
                     "a measure of its discretisation error)")
    a, b = (0.5 * (m + np.swapaxes(m, 1, 2)) for m in (a, b))
    return w, a, b, f, notes


def _hull_from_dataset(ds, *, c=None, mass=None, pitch_inertia=None, description="",
                       path="the dataset", wave_direction=None, own=False) -> HullHydro:
    """A :class:`HullHydro` from a Capytaine dataset (``exp(-i w t)``), checked as physics
    with :mod:`~parapend.hydro.bem`'s rules. ``own``: the BEM run here, whose asymmetry is
    its discretisation error, symmetrised and noted rather than refused."""
    ds = bem._by_omega(ds, path)
    for dim in ("radiating_dof", "influenced_dof"):
        if dim not in ds.coords:
            raise ParameterError(f"hydro: {path} has no {dim} coordinate (expected the "
                                 "degrees of freedom Surge, Heave and Pitch)")
        labels = [str(v) for v in ds[dim].values]
        missing = [d for d in DOFS if d not in labels]
        if missing:
            raise ParameterError(f"hydro: {path} has no {' and '.join(missing).lower()} "
                                 f"degree of freedom ({dim}: {', '.join(labels) or 'none'}); "
                                 "a hull needs Surge, Heave and Pitch")
    for var in ("added_mass", "radiation_damping"):
        if var not in ds:
            raise ParameterError(f"hydro: {path} has no {var} (radiation problems in surge, "
                                 "heave and pitch are needed)")
    fx = bem._direction(bem._excitation(ds, path), wave_direction, path)
    pair = ("radiating_dof", "influenced_dof")
    w = np.asarray(ds["omega"].values)
    if w.dtype.kind not in "iuf":
        raise ParameterError(f"hydro: {path}: omega is not numeric (type {w.dtype})")
    w = np.atleast_1d(w.astype(float))
    if np.any(np.isnan(w)) or np.any(w < 0):
        raise ParameterError(f"hydro: {path}: expected frequencies omega >= 0 (rad/s), got "
                             "NaN or a negative one")
    a = _dof_block(ds["added_mass"], pair, path, "added_mass")
    b = _dof_block(ds["radiation_damping"], pair, path, "radiation_damping")
    f = _dof_block(fx, ("influenced_dof",), path, "excitation_force")
    if a.ndim != 3 or b.ndim != 3 or f.ndim != 2:
        raise ParameterError(f"hydro: {path}: expected the coefficients indexed by omega")
    # rows at omega = 0 or inf are dropped: Capytaine 3 leaves their excitation NaN
    rows = np.isfinite(w) & (w > 0)
    a = bem._numeric(a[rows], "added_mass", path)
    b = bem._numeric(b[rows], "radiation_damping", path)
    f = np.conj(bem._numeric(f[rows], "excitation_force", path, "c"))
    order = np.argsort(w[rows])
    w, a, b, f = (x[order] for x in (w[rows], a, b, f))
    if w.size == 0:
        raise ParameterError(f"hydro: {path} has no finite frequency > 0")
    if np.any(np.diff(w) <= 0):
        raise ParameterError(f"hydro: {path} repeats a frequency")
    notes = []
    if own:
        w, a, b, f, notes = _resolved(w, a, b, f)
    notes += bem._physics(w, a, b, b[:, 1, 1], path)[1]
    if c is None:
        if "hydrostatic_stiffness" not in ds:
            raise ParameterError(f"hydro: {path} has no hydrostatics: hydrostatic_stiffness is "
                                 "missing (compute it with body.compute_hydrostatics)")
        c = bem._numeric(_dof_block(ds["hydrostatic_stiffness"],
                                    ("influenced_dof", "radiating_dof"), path,
                                    "hydrostatic_stiffness"), "hydrostatic_stiffness", path)
    if mass is None:
        inertia_mass = None
        if "inertia_matrix" in ds:
            m = bem._numeric(_dof_block(ds["inertia_matrix"],
                                        ("influenced_dof", "radiating_dof"), path,
                                        "inertia_matrix"), "inertia_matrix", path)
            inertia_mass = float(m[1, 1])
            if pitch_inertia is None:
                pitch_inertia = float(m[2, 2])
        mass, note = bem.dataset_mass(ds, inertia_mass, path)
        if note:
            notes.append(note)
    if not (math.isfinite(mass) and mass > 0):
        raise ParameterError(f"hydro: {path}: expected a heave mass > 0, got {mass!r}")
    if pitch_inertia is not None and not pitch_inertia > 0:
        raise ParameterError(f"hydro: {path}: expected a pitch inertia > 0 in inertia_matrix, "
                             f"got {pitch_inertia!r}")
    if not np.asarray(c)[1, 1] > 0:
        raise ParameterError(f"hydro: {path}: expected a heave hydrostatic_stiffness > 0, "
                             f"got {np.asarray(c)[1, 1]!r}")
    return HullHydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                     hydrostatic_stiffness=c, mass=mass, pitch_inertia=pitch_inertia,
                     rho=bem._scalar(ds, "rho", 1025.0), g=bem._scalar(ds, "g", 9.81),
                     water_depth=bem._scalar(ds, "water_depth", math.inf),
                     description=description or str(ds.attrs.get("description", "")),
                     notes=tuple(notes))


def load_hull(path, *, wave_direction=None) -> HullHydro:
    """Read surge, heave and pitch coefficients from a Capytaine NetCDF dataset (or take
    them from the :class:`xarray.Dataset` itself).

    As :func:`parapend.hydro.bem.load`, with the degrees of freedom ``Surge``, ``Heave`` and
    ``Pitch`` (others ignored), the 3 x 3 ``hydrostatic_stiffness`` of those DOFs required,
    the mass from ``inertia_matrix`` (its heave entry) or ``disp_mass``, and the pitch
    inertia from ``inertia_matrix`` where present (else unknown: None). The origin of the
    data is O (Capytaine's rotation centre and the point of the wave phase). Rows at
    ``omega = 0`` or ``inf`` are ignored.

    Raises
    ------
    ParameterError
        One line naming what is missing or wrong (a dataset without pitch or surge,
        NaN, asymmetric matrices, negative damping).
    """
    import xarray as xr

    if isinstance(path, xr.Dataset):
        return _hull_from_dataset(path, path="the dataset", wave_direction=wave_direction,
                                  description=str(path.attrs.get("description", ""))
                                  or "an xarray dataset")
    ds, shown, p = bem._read_netcdf(path)
    return _hull_from_dataset(ds, path=shown, wave_direction=wave_direction,
                              description=str(ds.attrs.get("description", ""))
                              or f"dataset {p.name}")


# -- BEM -------------------------------------------------------------------------------------
def _cached(key):
    got = bem._cache_load(key)
    if got is None:
        return None
    z, meta = got
    try:
        return HullHydro(omega=z["omega"], added_mass=z["added_mass"],
                         radiation_damping=z["radiation_damping"], excitation=z["excitation"],
                         hydrostatic_stiffness=np.asarray(meta["C"], dtype=float),
                         mass=float(meta["M"]), pitch_inertia=meta["I"],
                         rho=float(meta["rho"]), g=float(meta["g"]),
                         water_depth=float(meta["depth"]), description=str(meta["description"]),
                         notes=tuple(meta["notes"]))
    except Exception:  # noqa: BLE001 - any failure means: recompute, never trust it
        return None


def _solve_hull(build, omega, *, rho, g, water_depth, description, cache, key_parts,
                pitch_inertia=None, unstable=None, method=None):
    """Hydrostatics and surge-heave-pitch BEM of the body ``build()`` gives, cached on disk.

    ``build()`` gives ``(mesh, hull, lid)``: the immersed surface for the BEM (possibly
    symmetric), the same as a plain mesh for the hydrostatics, and a lid for the irregular
    frequencies (or None). O = the centre of mass = the rotation centre = the origin.
    ``pitch_inertia`` None: the homogeneous immersed hull's from the mesh.
    ``unstable(c55)``: the message refusing a hull unstable in pitch. ``method``:
    Capytaine's BEM formulation (default its own, as :mod:`~parapend.hydro.bem`).
    """
    omega = np.asarray(omega, dtype=float)
    key = bem._cache_key(f"hull{HULL_CACHE_VERSION}|surge,heave,pitch|".encode() + key_parts,
                         omega, rho, g, water_depth)
    if cache:
        hit = _cached(key)
        if hit is not None:
            return hit
    cpt = bem._quiet_capytaine()
    import xarray as xr

    mesh, hull, lid = build()
    dofs = cpt.rigid_body_dofs(only=list(DOFS), rotation_center=(0.0, 0.0, 0.0))
    plain = cpt.FloatingBody(mesh=hull, dofs=dofs, center_of_mass=(0.0, 0.0, 0.0))
    c = plain.compute_hydrostatic_stiffness(rho=rho, g=g)
    c = np.asarray(c.sel(influenced_dof=list(DOFS), radiating_dof=list(DOFS)).values,
                   dtype=float)
    if not c[2, 2] > 0:
        raise ParameterError(unstable(c[2, 2]) if unstable else
                             f"mesh: the hull is not stable in pitch about O with its centre of "
                             f"mass there (C55 = {c[2, 2]:.4g} N m/rad <= 0)")
    mass = rho * float(plain.disp_volume)
    if pitch_inertia is None:
        pitch_inertia = _mesh_pitch_inertia(hull, rho)
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid, dofs=dofs,
                            center_of_mass=(0.0, 0.0, 0.0))
    test = xr.Dataset(coords={"omega": omega, "wave_direction": [0.0],
                              "radiating_dof": list(DOFS), "water_depth": [water_depth],
                              "rho": [rho], "g": [g]})
    solver = cpt.BEMSolver() if method is None else cpt.BEMSolver(method=method)
    ds = solver.fill_dataset(test, body, n_jobs=1, progress_bar=False)
    hyd = _hull_from_dataset(ds, c=c, mass=mass, pitch_inertia=pitch_inertia,
                             description=f"{description}, {hull.nb_faces} panels"
                             + (f" and a lid of {lid.nb_faces}" if lid is not None else ""),
                             path="the BEM", own=True)
    if cache:
        bem._cache_store(key, {name: getattr(hyd, name) for name in bem._ARRAYS},
                         {"C": hyd.hydrostatic_stiffness.tolist(), "M": hyd.mass,
                          "I": hyd.pitch_inertia, "rho": hyd.rho, "g": hyd.g,
                          "depth": repr(hyd.water_depth), "description": hyd.description,
                          "notes": list(hyd.notes)})
    return hyd


def _mesh_pitch_inertia(hull, rho):
    """Pitch inertia about O (kg m^2) of the homogeneous solid (density ``rho``) filling the
    immersed part of ``hull`` up to ``z = 0``: ``rho * integral of (x^2 + z^2) dV``, by the
    divergence theorem on the wetted panels (fields ``(0, 0, x^2 z)`` and ``(0, 0, z^3 / 3)``
    vanish on the waterplane), midpoint rule on each panel."""
    centres = np.asarray(hull.faces_centers, dtype=float)
    nz = np.asarray(hull.faces_normals, dtype=float)[:, 2]
    area = np.asarray(hull.faces_areas, dtype=float)
    x, z = centres[:, 0], centres[:, 2]
    return rho * float(np.sum((x * x * z + z**3 / 3) * nz * area))


def _box_meshes(length, beam, draft, h, omega_max):
    """The barge's wetted surface (reflection-symmetric, an even number of panels of radius
    at most ``h`` along x and y), the same as a plain mesh, and its lid against irregular
    frequencies: panels of radius at most ``h`` at Capytaine's lowest lid position for
    ``omega_max`` (the waterplane where no irregular frequency lies below ``omega_max``)."""
    cpt = bem._quiet_capytaine()
    side = math.sqrt(2) * h
    res = (2 * math.ceil(length / (2 * side)), 2 * math.ceil(beam / (2 * side)),
           math.ceil(draft / side))
    mesh = cpt.mesh_parallelepiped(size=(length, beam, draft), center=(0.0, 0.0, -draft / 2),
                                   resolution=res, missing_sides={"top"},
                                   reflection_symmetry=True)
    with np.errstate(invalid="ignore"):  # NaN: no irregular frequency below omega_max
        z = float(mesh.lowest_lid_position(omega_max=float(omega_max)))
    # the lid's panels as the hull's: Capytaine's default (finer, not aligned with the
    # hull's) gave the default barge a heave damping of -6e5 N s/m at 5.5 rad/s
    lid = mesh.generate_lid(z=min(z, 0.0) if math.isfinite(z) else 0.0, faces_max_radius=h)
    return mesh, bem._plain(mesh), (lid if lid.nb_faces else None)


def barge(length=10.0, beam=4.0, draft=1.0, *, omega=None, rho=1025.0, g=9.81,
          water_depth=math.inf, cache=True, refine=1.0) -> HullHydro:
    """Surge, heave and pitch coefficients of a box barge floating at ``draft``.

    The box ``length`` (along x, the waves' direction) x ``beam`` x ``draft`` (m), O at the
    centre of its waterplane; its wetted surface meshed with two planes of symmetry and a
    lid (Capytaine's ``lid_mesh``, at its lowest position for the highest frequency) that
    removes the irregular frequencies (the first of the default barge, about 3.5 rad/s,
    lies in its grid and makes the damping negative without it). Capytaine's direct
    formulation: at the box's sharp edges it gives a surge-pitch added mass symmetric to
    about 1 % where the indirect one is 10 % off (the matrices are then symmetrised).

    Parameters
    ----------
    length, beam, draft : float
        The box (m), all > 0; pitch-stable: ``length > sqrt(6) draft``.
    omega, rho, g, water_depth, cache, refine
        As :func:`parapend.hydro.bem.cylinder`, with the scale of the mesh rule the smaller of
        length and beam (the default 10 x 4 x 1 m with ``omega="body"``: panel radius 1/3 m,
        412 panels and a lid of 120, 48 frequencies from 0.063 to 3.9 rad/s of which the
        42 up to 3.43 rad/s are resolved and kept; with ``omega=None``: 1412 panels, 13 of
        ``DEFAULT_OMEGA``'s frequencies, 0.3 to 5.5 rad/s). Frequencies where the BEM's
        damping is indefinite or asymmetric beyond the dataset checks' tolerances are left
        out, with a note (``_resolved``).

    Returns
    -------
    HullHydro
        With ``pitch_inertia = M (L^2 / 12 + D^2 / 3)`` (``M = rho L B D``), the homogeneous
        box's about O.
    """
    length = check_positive("length", length)
    beam = check_positive("beam", beam)
    draft = check_positive("draft", draft)
    rho, g, water_depth, refine = bem._common(rho, g, water_depth, refine)
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    if not length**2 > 6 * draft**2:
        raise ParameterError(f"draft: a box barge {length:g} m long with a draft of {draft:g} m "
                             "is unstable in pitch about its waterplane centre (C55 = rho g L B "
                             f"(L^2/12 - D^2/2) <= 0): give a draft below length/sqrt(6) = "
                             f"{length / math.sqrt(6):.4g} m")
    h, omega = bem._mesh_and_grid(min(length, beam), omega, g, water_depth, refine)
    mass = rho * length * beam * draft
    desc = f"box barge, {length:g} x {beam:g} x {draft:g} m"
    return _solve_hull(lambda: _box_meshes(length, beam, draft, h, omega[-1]), omega,
                       rho=rho, g=g, water_depth=water_depth, description=desc, cache=cache,
                       key_parts=bem._params(body="barge", size=(length, beam, draft), h=h,
                                           method="direct", lid="faces_max_radius=h"),
                       pitch_inertia=mass * (length**2 / 12 + draft**2 / 3), method="direct")


def cylinder_hull(radius, draft, *, omega=None, rho=1025.0, g=9.81, water_depth=math.inf,
                  cache=True, refine=1.0) -> HullHydro:
    """Surge, heave and pitch coefficients of a vertical circular cylinder floating at
    ``draft``: the body and mesh of :func:`parapend.hydro.bem.cylinder` (same options, no
    lid, as there), O at the centre of its waterplane.

    Pitch-stable only if ``radius > sqrt(2) draft`` (``C55 = rho g pi R^2 (R^2/4 - D^2/2)``);
    ``pitch_inertia = M (R^2 / 4 + D^2 / 3)`` (``M = rho pi R^2 D``), the homogeneous
    immersed cylinder's about O.
    """
    radius = check_positive("radius", radius)
    draft = check_positive("draft", draft)
    rho, g, water_depth, refine = bem._common(rho, g, water_depth, refine)
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    if not radius**2 > 2 * draft**2:
        raise ParameterError(f"draft: a cylinder of radius {radius:g} m with a draft of "
                             f"{draft:g} m is unstable in pitch about its waterplane centre "
                             "(C55 = rho g pi R^2 (R^2/4 - D^2/2) <= 0): give a draft below "
                             f"radius/sqrt(2) = {radius / math.sqrt(2):.4g} m")
    h, omega = bem._mesh_and_grid(min(radius, draft), omega, g, water_depth, refine)
    kw = dict(length=2 * draft, radius=radius, center=(0.0, 0.0, 0.0), faces_max_radius=h)

    def build():
        cpt = bem._quiet_capytaine()
        return (cpt.mesh_vertical_cylinder(axial_symmetry=True, **kw).immersed_part(),
                cpt.mesh_vertical_cylinder(**kw).immersed_part(), None)

    mass = rho * math.pi * radius**2 * draft
    desc = f"vertical cylinder, radius {radius:g} m, draft {draft:g} m"
    return _solve_hull(build, omega, rho=rho, g=g, water_depth=water_depth, description=desc,
                       cache=cache, key_parts=bem._params(body="cylinder", **kw),
                       pitch_inertia=mass * (radius**2 / 4 + draft**2 / 3))


def _cap_integrals(radius, draft):
    """``(V, integral of x^2 dV, integral of z^2 dV)`` of the part ``-draft < z < 0`` of the
    ball of ``radius`` centred at ``z = radius - draft``, exactly (polynomials in the
    height ``u`` from the centre, slices of radius^2 ``R^2 - u^2``)."""
    from numpy.polynomial import Polynomial as P

    c = radius - draft
    r2 = P([radius**2, 0.0, -1.0])  # slice radius squared at u
    lo, hi = -radius, -c  # u from the bottom to the waterplane (z = u + c)
    def integral(p):
        q = p.integ()
        return float(q(hi) - q(lo))
    return (math.pi * integral(r2), math.pi / 4 * integral(r2 * r2),
            math.pi * integral(r2 * P([c, 1.0]) ** 2))


def sphere_hull(radius, *, draft=None, omega=None, rho=1025.0, g=9.81, water_depth=math.inf,
                cache=True, refine=1.0) -> HullHydro:
    """Surge, heave and pitch coefficients of a floating sphere, O at its waterplane centre.

    ``draft`` (m, default ``radius``: floating at its centre, :func:`parapend.hydro.bem.sphere`'s
    body and mesh) must be below ``radius`` for the sphere to be stable in pitch:
    ``C55 = rho g V (radius - draft)`` (the metacentre is the sphere's centre), 0 at the
    centre, where it is refused. The mesh rule's scale is the smaller of radius and draft.
    ``pitch_inertia = rho * integral of (x^2 + z^2) dV`` over the immersed cap, about O
    (for a hemisphere ``2/5 M R^2``), exactly by ``_cap_integrals``.
    Other parameters as :func:`cylinder_hull`.
    """
    radius = check_positive("radius", radius)
    draft = radius if draft is None else check_positive("draft", draft)
    rho, g, water_depth, refine = bem._common(rho, g, water_depth, refine)
    if not draft < radius:
        what = ("floating at its centre is neutral" if draft == radius else
                f"with a draft of {draft:g} m is unstable")
        raise ParameterError(f"draft: a sphere of radius {radius:g} m {what} in pitch about "
                             "its waterplane centre with its centre of mass there (C55 = rho g V "
                             "(radius - draft) <= 0): give a draft below the radius")
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    h, omega = bem._mesh_and_grid(min(radius, draft), omega, g, water_depth, refine)
    kw = dict(radius=radius, center=(0.0, 0.0, radius - draft), faces_max_radius=h)

    def build():
        cpt = bem._quiet_capytaine()
        return (cpt.mesh_sphere(axial_symmetry=True, **kw).immersed_part(),
                cpt.mesh_sphere(**kw).immersed_part(), None)

    _, ix, iz = _cap_integrals(radius, draft)
    desc = f"sphere, radius {radius:g} m, draft {draft:g} m"
    return _solve_hull(build, omega, rho=rho, g=g, water_depth=water_depth, description=desc,
                       cache=cache, key_parts=bem._params(body="sphere", **kw),
                       pitch_inertia=rho * (ix + iz))


def hull_from_mesh(path, *, omega=None, rho=1025.0, g=9.81, water_depth=math.inf, cache=True,
                   file_format=None) -> HullHydro:
    """Surge, heave and pitch coefficients of the hull in a mesh file (as
    :func:`parapend.hydro.bem.from_mesh`: floating position, ``z = 0`` the free surface,
    closed below the waterline). O, the rotation centre and the centre of mass, is the
    mesh's origin: place the mesh with its waterplane centre there. ``pitch_inertia`` is
    the homogeneous immersed hull's about O (from the panels, midpoint rule). A hull not
    stable in pitch about O (``C55 <= 0``) is refused.
    """
    rho, g, water_depth, _ = bem._common(rho, g, water_depth, 1.0)
    hull, omega, desc, parts = bem._mesh_file(path, omega, g, water_depth, file_format)

    def unstable(c55):
        return (f"mesh: {str(path)!r} is not stable in pitch about its origin with the centre "
                f"of mass there (C55 = {c55:.4g} N m/rad <= 0): give a dataset (--hydro) "
                "computed with the hull's own centre of mass")

    return _solve_hull(lambda: (hull, hull, None), omega, rho=rho, g=g,
                       water_depth=water_depth, description=desc, cache=cache,
                       key_parts=parts, unstable=unstable)
