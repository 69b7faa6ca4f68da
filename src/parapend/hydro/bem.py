"""The floating body's hydrodynamics: coefficients from Capytaine, cached, or loaded, for its
degrees of freedom (heave alone, or surge, heave and pitch).

A :class:`Hydro` holds the linear potential-flow coefficients of a rigid body heaving at
the free surface, a :class:`HullHydro` those of a hull in surge, heave and pitch about its
rotation centre O, in this project's time convention ``x(t) = Re(X exp(+i w t))``:

- ``added_mass`` ``A(w)`` (kg; (n, 3, 3) for a hull) and ``radiation_damping``
  ``B(w) >= 0`` (N s/m; positive semidefinite), symmetrised;
- ``excitation`` ``F(w)`` (N per metre of wave amplitude), the complex amplitude of the
  force of a regular wave whose elevation at the body's origin is ``Re(exp(+i w t))``
  (waves travelling along +x, Capytaine's wave direction 0);
- ``hydrostatic_stiffness`` ``C`` (N/m; (3, 3) for a hull, with the whole floating mass at
  O) and ``mass`` ``M`` (kg), the displaced mass: a body floating at its draft weighs what
  it displaces, the pendulum inside it included; a hull's ``pitch_inertia`` about O where
  known.

Pitch follows Capytaine's sign: a positive pitch turns a point above O towards +x and a
point at +x downwards (a right-handed rotation about +y).

Capytaine uses ``x(t) = Re(X exp(-i w t))`` (its manual, "Conventions"): its complex
amplitudes are conjugated here on the way in, and nowhere else. ``A`` and ``B`` are real
and the same in both conventions.

Bodies come from parameters (:func:`cylinder`, :func:`sphere`; for a hull :func:`barge`,
:func:`cylinder_hull`, :func:`sphere_hull`), from any mesh file Capytaine reads
(:func:`from_mesh`, :func:`hull_from_mesh`), or from a dataset written by Capytaine
(:func:`load`, :func:`load_hull`; the floating mass by :func:`dataset_mass`). BEM results
are cached on disk (see :func:`cache_dir`), keyed by a hash of the mesh, the frequencies,
``rho``, ``g`` and the water depth, so a second run is instant.

Between the dataset's frequencies the coefficients are interpolated linearly in ``w``
(real and imaginary parts separately). Above the highest frequency ``A`` is held and
``B = F = 0`` (:meth:`Hydro.above_range` says where; the caller warns). Below the lowest,
``A`` is held and ``B`` and ``F`` go linearly to their hydrostatic limits ``B(0) = 0``,
``F(0) = C`` (a long wave lifts the body by the wave's height; for a hull ``F(0) = C[:, 1]``,
which also tilts it by the waterplane's first moment).
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError, check_int, check_positive

__all__ = ["DOFS", "Hydro", "HullHydro", "barge", "body_frequencies", "cache_dir", "cylinder",
           "cylinder_hull", "cylinder_scale", "cylinder_work", "frequencies_for", "from_mesh",
           "dataset_mass", "hull_from_mesh", "load", "load_hull", "mesh_size", "sphere",
           "sphere_hull"]

#: Bump when the cached content or the meshing rule changes (old entries are then ignored).
CACHE_VERSION = 1

#: Panels per shortest wavelength: the largest panel radius is ``wavelength / PANELS_PER_WAVE``
#: (Capytaine's own lower limit is 8 panel radii per wavelength).
PANELS_PER_WAVE = 10

#: Panel radius from the geometry alone: ``scale / GEOMETRY_PANELS`` (``scale`` the smaller of
#: radius and draft): the waterplane area to 0.3 %, A and B to about 1 %.
GEOMETRY_PANELS = 12

#: The finest panel the automatic rule uses: ``scale / FINEST_PANELS``; frequencies whose
#: wavelength that panel cannot resolve are left out of the BEM (they are then above range).
FINEST_PANELS = 24

#: The body's own frequency grid (``omega="body"``, :func:`body_frequencies`): so many
#: frequencies, evenly spaced, from ``2 pi / LONGEST_PERIOD`` to the frequency whose
#: wavelength is ``COARSE * 8`` panel radii of the body's mesh.
BODY_FREQUENCIES = 48

#: The longest wave period (s) the body's grid starts at (``parapend buoy`` takes 0.1 to 100 s).
LONGEST_PERIOD = 100.0

#: The panels of the error estimate's second mesh are this many times larger (panel radius):
#: the grid ends where that mesh still has Capytaine's 8 panel radii per wavelength, so the
#: body's own mesh has 12 there, more than :data:`PANELS_PER_WAVE`.
COARSE = 1.5


def _as_omega(w) -> np.ndarray:
    return np.asarray(w, dtype=float)


def check_frequency_count(n: int) -> None:
    """Refuse ``n`` data frequencies above
    :data:`parapend.limits.BUOY_MAX_DATASET_FREQUENCIES`, in one line, before any work."""
    from .. import limits

    cap = limits.BUOY_MAX_DATASET_FREQUENCIES
    if n > cap:
        raise ParameterError(f"hydro: expected at most {cap} frequencies, got {n} (the "
                             "causal plant's work grows with their square; resample the "
                             "data on fewer)")


def _coefficient_array(name: str, value, dtype=float) -> np.ndarray:
    """``value`` as an array of numbers, or a one-line :class:`ParameterError` naming the
    coefficient (``Hydro("x", ...)`` raised NumPy's bare "could not convert string")."""
    try:
        return np.array(value, dtype=dtype)
    except (TypeError, ValueError):
        kind = "complex numbers" if dtype is complex else "numbers"
        raise ParameterError(f"hydro: expected {name} as an array of {kind}, got "
                             f"{value!r:.40}") from None


@dataclass(frozen=True, eq=False)
class Hydro:
    """Heave coefficients of a floating body (SI units, convention ``exp(+i w t)``).

    Parameters
    ----------
    omega : numpy.ndarray
        Angular frequencies (rad/s), strictly increasing, all > 0.
    added_mass : numpy.ndarray
        Heave added mass ``A(w)`` (kg).
    radiation_damping : numpy.ndarray
        Heave radiation damping ``B(w) >= 0`` (N s/m).
    excitation : numpy.ndarray
        Complex heave excitation force per metre of wave amplitude (N/m), phase relative to
        the wave elevation at the body's origin.
    hydrostatic_stiffness : float
        ``C`` (N/m).
    mass : float
        The floating body's total mass ``M = rho * displaced volume`` (kg).
    rho, g, water_depth : float
        Water density (kg/m^3), gravity (m/s^2), depth (m, ``inf`` for deep water).
    description : str
        What the coefficients are of (geometry, panels, source).
    """

    omega: np.ndarray
    added_mass: np.ndarray
    radiation_damping: np.ndarray
    excitation: np.ndarray
    hydrostatic_stiffness: float
    mass: float
    rho: float = 1025.0
    g: float = 9.81
    water_depth: float = math.inf
    description: str = ""
    #: what reading the data changed (symmetrised matrices, dropped frequencies): the
    #: result's warnings
    notes: tuple = ()
    #: the degrees of freedom these coefficients are of (a class constant, not a field)
    dofs = ("heave",)

    def __post_init__(self):
        w = _coefficient_array("omega", self.omega).ravel()
        check_frequency_count(w.size)
        a, b = (_coefficient_array(n, getattr(self, n)).ravel() for n in (
            "added_mass", "radiation_damping"))
        f = _coefficient_array("excitation", self.excitation, complex).ravel()
        if not (w.size >= 1 and a.size == b.size == f.size == w.size):
            raise ParameterError("hydro: expected omega, added_mass, radiation_damping and "
                                 "excitation of one common length >= 1")
        if not (np.all(np.isfinite(w)) and np.all(np.isfinite(a)) and np.all(np.isfinite(b))
                and np.all(np.isfinite(f))):
            raise ParameterError("hydro: expected finite coefficients (a dataset with NaN or "
                                 "infinite values)")
        if w[0] <= 0 or np.any(np.diff(w) <= 0):
            raise ParameterError("hydro: expected frequencies > 0, strictly increasing")
        c = check_positive("hydrostatic_stiffness", self.hydrostatic_stiffness)
        m = check_positive("mass", self.mass)
        # small negative damping is BEM noise at high frequency; passivity requires B >= 0
        b = np.maximum(b, 0.0)
        for name, arr in (("omega", w), ("added_mass", a), ("radiation_damping", b),
                          ("excitation", f)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "hydrostatic_stiffness", c)
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "rho", check_positive("rho", self.rho))
        object.__setattr__(self, "g", check_positive("g", self.g))
        depth = float(self.water_depth)
        if not depth > 0:
            raise ParameterError(f"water_depth: expected a depth > 0 or inf, got {depth!r}")
        object.__setattr__(self, "water_depth", depth)

    # -- coefficients ------------------------------------------------------------------
    def coefficients(self, w):
        """``(A, B, F)`` at angular frequencies ``w`` (rad/s; arrays shaped like ``w``).

        Linear interpolation in ``w`` between the dataset's frequencies (real and imaginary
        parts of ``F`` separately). Above the highest frequency ``A`` is held and
        ``B = F = 0``; below the lowest ``A`` is held and ``B``, ``F`` are interpolated
        linearly towards ``B(0) = 0``, ``F(0) = C``. ``w = 0`` gives ``(A(w_min), 0, C)``.
        """
        w = np.abs(_as_omega(w))
        wd = np.concatenate(([0.0], self.omega))
        bd = np.concatenate(([0.0], self.radiation_damping))
        fd = np.concatenate(([self.hydrostatic_stiffness], self.excitation))
        a = np.interp(w, self.omega, self.added_mass)
        b = np.interp(w, wd, bd, right=0.0)
        f = np.interp(w, wd, fd.real, right=0.0) + 1j * np.interp(w, wd, fd.imag, right=0.0)
        above = self.above_range(w)
        b = np.where(above, 0.0, b)
        f = np.where(above, 0.0, f)
        return a, b, f

    def above_range(self, w) -> np.ndarray:
        """Boolean array: where :meth:`coefficients` extrapolates above the data."""
        return np.abs(_as_omega(w)) > self.omega[-1] * (1 + 1e-12)

    def impedance(self, w):
        """``D(w) = -w^2 (M + A) + i w B + C`` (N/m), the free buoy's heave impedance."""
        w = _as_omega(w)
        a, b, _ = self.coefficients(w)
        return -w**2 * (self.mass + a) + 1j * w * b + self.hydrostatic_stiffness

    def free_response(self, w):
        """Heave of the free buoy per metre of wave amplitude, ``Z/a = F / D`` (complex)."""
        w = _as_omega(w)
        _, _, f = self.coefficients(w)
        return f / self.impedance(w)

    def radiation_bound(self, w, amplitude) -> float:
        """Most power a heaving body can absorb from a regular wave: ``|F a|^2 / (8 B)`` (W).

        ``amplitude`` is the wave amplitude (m, half the height). 0 where ``B == 0``.
        """
        _, b, f = self.coefficients(float(w))
        b = float(b)
        if b <= 0:
            return 0.0
        return float(abs(complex(f) * amplitude) ** 2 / (8.0 * b))

    def check_covers(self, w_min, w_max, name="wave-period"):
        """Raise :class:`~parapend.errors.ParameterError` unless ``[w_min, w_max]`` (rad/s)
        lies in the data."""
        lo, hi = float(self.omega[0]), float(self.omega[-1])
        w_min, w_max = float(w_min), float(w_max)
        tol = 1e-9
        if w_min >= lo * (1 - tol) and w_max <= hi * (1 + tol):
            return
        t_lo, t_hi = 2 * math.pi / w_max, 2 * math.pi / w_min
        need = f"{t_lo:.4g} s" if f"{t_lo:.4g}" == f"{t_hi:.4g}" else \
            f"{t_lo:.4g} s to {t_hi:.4g} s"
        have = f"{2 * math.pi / hi:.4g} s to {2 * math.pi / lo:.4g} s"
        if name in ("tp", "record"):  # a sea's components, the shortest set by --cutoff
            raise ParameterError(
                f"{name}: the sea's components from {need} (up to --cutoff times the peak "
                f"frequency) lie outside the hydrodynamic data, which cover {have}; expected "
                "a longer --tp or a smaller --cutoff")
        raise ParameterError(f"{name}: {need} lies outside the hydrodynamic data, which cover "
                             f"{have}")

    def natural_frequency(self) -> float:
        """The undamped heave natural frequency (rad/s): the root of ``C = w^2 (M + A(w))``.

        Found by bisection on the interpolated ``A``; ``nan`` if ``C - w^2 (M + A(w))`` does
        not change sign on the data's range.
        """
        def g(w):
            a, _, _ = self.coefficients(w)
            return self.hydrostatic_stiffness - w**2 * (self.mass + float(a))
        lo, hi = 1e-9, float(self.omega[-1])
        if g(lo) * g(hi) > 0:
            return math.nan
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if g(lo) * g(mid) <= 0:
                hi = mid
            else:
                lo = mid
        return 0.5 * (lo + hi)

    def to_dataset(self):
        """The coefficients as a Capytaine-style :class:`xarray.Dataset` (``exp(-i w t)``).

        Write it with ``capytaine.io.xarray.save_dataset_as_netcdf``; :func:`load` reads it
        back.
        """
        return _dataset(self.omega, self.added_mass[:, None, None],
                        self.radiation_damping[:, None, None], self.excitation[:, None],
                        ["Heave"], [[self.hydrostatic_stiffness]], [[self.mass]],
                        rho=self.rho, g=self.g, water_depth=self.water_depth,
                        description=self.description)


def _dataset(omega, a, b, f, dofs, c, inertia, *, rho, g, water_depth, description):
    """A Capytaine-style :class:`xarray.Dataset` (``exp(-i w t)``, wave direction 0) of the
    coefficients ``a``, ``b`` (n, d, d) and ``f`` (n, d, convention ``exp(+i w t)``) over the
    DOFs ``dofs``; ``c`` and ``inertia`` (d, d); ``inertia`` None: no ``inertia_matrix``."""
    import xarray as xr

    mat = ("influenced_dof", "radiating_dof")
    data = {
        "added_mass": (("omega", "radiating_dof", "influenced_dof"), np.asarray(a)),
        "radiation_damping": (("omega", "radiating_dof", "influenced_dof"), np.asarray(b)),
        "excitation_force": (("omega", "wave_direction", "influenced_dof"),
                             np.conj(np.asarray(f))[:, None, :]),
        "hydrostatic_stiffness": (mat, np.asarray(c)),
    }
    if inertia is not None:
        data["inertia_matrix"] = (mat, np.asarray(inertia))
    return xr.Dataset(data, coords={"omega": omega, "radiating_dof": list(dofs),
                                    "influenced_dof": list(dofs), "wave_direction": [0.0],
                                    "rho": rho, "g": g, "water_depth": water_depth},
                      attrs={"description": description})


# -- frequencies ---------------------------------------------------------------------------
def frequencies_for(omegas, harmonics=3, *, count=30, low=0.5):
    """The frequency grid (rad/s) a problem on the wave frequencies ``omegas`` needs.

    Parameters
    ----------
    omegas : float or array_like
        The wave's angular frequencies (rad/s): one for a regular wave, several for a sweep
        over periods (``2 pi / period``) or the band of an irregular record.
    harmonics : int
        The highest multiple of the highest wave frequency at which the coupled problem
        needs ``A`` and ``B`` (the pendulum's reaction has harmonics ``k w``).
    count : int
        Number of frequencies, evenly spaced.
    low : float
        The grid starts at ``low * min(omegas)``.

    Returns
    -------
    numpy.ndarray
        ``count`` frequencies from ``low * min(omegas)`` to ``harmonics * max(omegas)``.
        The lowest and highest wave frequencies are grid points when ``harmonics == 1``;
        otherwise the wave band lies strictly inside the grid.
    """
    w = np.atleast_1d(np.asarray(omegas, dtype=float)).ravel()
    if w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise ParameterError("omegas: expected angular frequencies > 0 (rad/s)")
    harmonics = check_int("harmonics", harmonics, 1)
    count = check_int("count", count, 2)
    low = check_positive("low", low)
    if low > 1:
        raise ParameterError(f"low: expected a number in (0, 1], got {low!r}")
    return np.linspace(low * w.min(), harmonics * w.max(), count)


def body_frequencies(h, *, g=9.81, water_depth=math.inf) -> np.ndarray:
    """The body's frequency grid (rad/s): one for every problem on the body, whichever wave
    periods a call asks for, so that an answer does not depend on the call.

    ``BODY_FREQUENCIES`` frequencies, evenly spaced, from ``2 pi / LONGEST_PERIOD`` to the
    frequency whose wavelength is ``8 COARSE h`` (``h`` the panel radius of the body's mesh):
    there the mesh of panels ``COARSE`` times larger (the error estimate's) still resolves
    the wave, and this one has ``8 COARSE = 12`` panel radii per wavelength.
    """
    h = check_positive("h", h)
    k = 2 * math.pi / (8 * COARSE * h * (1 + 1e-9))
    top = math.sqrt(g * k * (math.tanh(k * water_depth) if math.isfinite(water_depth)
                             else 1.0))
    low = 2 * math.pi / LONGEST_PERIOD
    if not top > low:
        raise ParameterError(f"h: a panel radius of {h:.3g} m resolves no wave shorter than "
                             f"{LONGEST_PERIOD:g} s")
    return np.linspace(low, top, BODY_FREQUENCIES)


def _wavenumber(w, g, depth):
    """Wavenumber (1/m) from the dispersion relation ``w^2 = g k tanh(k h)``."""
    k0 = w * w / g
    if not math.isfinite(depth):
        return k0
    k = max(k0, w / math.sqrt(g * depth))
    for _ in range(100):
        t = math.tanh(k * depth)
        f = g * k * t - w * w
        fp = g * t + g * k * depth * (1 - t * t)
        step = f / fp
        k -= step
        if abs(step) < 1e-14 * k:
            break
    return k


def mesh_size(scale, omega_max, *, g=9.81, water_depth=math.inf, refine=1.0):
    """The panel radius (m) for a body of size ``scale`` (m) up to ``omega_max`` (rad/s).

    ``min(scale / 12, wavelength / 10)``, not finer than ``scale / 24`` (each divided by
    ``refine``): the panel is a fraction of the shortest wavelength and of the geometry.
    """
    k = _wavenumber(float(omega_max), g, water_depth)
    wavelength = 2 * math.pi / k
    h = min(scale / GEOMETRY_PANELS, wavelength / PANELS_PER_WAVE)
    return max(h, scale / FINEST_PANELS) / refine


def cylinder_work(radius, draft, h) -> float:
    """Influence coefficients of one BEM frequency of a vertical cylinder meshed at panel
    radius ``h`` (Capytaine's own panel counts for ``faces_max_radius=h``, rotation-symmetric:
    the panels of one slice times the panels of the mesh, over the slices)."""
    hh = math.sqrt(2) * h
    nr = math.ceil(radius / hh)
    nth = 2 * math.ceil(math.pi * radius / hh)
    nz = math.ceil(2 * draft / hh)
    piece = nr + math.ceil(nz / 2)
    return float(piece * nth * piece)


def cylinder_scale(radius, draft) -> float:
    """The size (m) a cylinder's mesh follows (panel radius ``scale / GEOMETRY_PANELS``): the
    smaller of radius and draft; for a wide, shallow body whose mesh at the draft's scale
    exceeds ``parapend.limits.BUOY_MAX_BEM_WORK``, the smallest scale up to the radius
    whose work is at most half of it (its BEM and the error estimate's on a mesh 1.5 times
    coarser: radius 10 m at the full cap took 109 s under a load of 6, past the minute the
    cap means). The panels then follow the shortest wave solved, not the draft: the body's
    grid (:func:`body_frequencies`) ends where a wavelength is 12 panel radii, and the side
    has fewer than 12 rows (the result's mesh error, from a mesh 1.5 times coarser, says what
    that costs). A tall body (draft above the radius) is left to the caller's refusal."""
    from .. import limits

    scale = min(radius, draft)
    cap = limits.BUOY_MAX_BEM_WORK
    if radius <= draft or cylinder_work(radius, draft, scale / GEOMETRY_PANELS) <= cap:
        return scale
    cap = cap / 2
    lo, hi = scale, radius  # work(lo) > cap; work(radius) fits any radius up to 1e3 m
    if cylinder_work(radius, draft, hi / GEOMETRY_PANELS) > cap:
        return hi
    for _ in range(60):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if cylinder_work(radius, draft, mid / GEOMETRY_PANELS) > cap \
            else (lo, mid)
    return hi


def _resolvable(omega, h, g, depth):
    """Mask of the frequencies whose wavelength is at least 8 panel radii ``h``."""
    return np.array([2 * math.pi / _wavenumber(float(w), g, depth) >= 8 * h * (1 - 1e-9)
                     for w in omega])


# -- the cache -------------------------------------------------------------------------------
def cache_dir() -> Path:
    """Where BEM results are cached: ``$PARAPEND_CACHE/hydro`` or ``~/.cache/parapend/hydro``."""
    root = os.environ.get("PARAPEND_CACHE")
    base = Path(root) if root else Path.home() / ".cache" / "parapend"
    return base / "hydro"


def _cache_key(parts: bytes, omega, rho, g, depth) -> str:
    from importlib.metadata import version

    h = hashlib.sha256()
    meta = {"version": CACHE_VERSION, "capytaine": version("capytaine"), "rho": float(rho),
            "g": float(g), "depth": repr(float(depth))}
    h.update(json.dumps(meta, sort_keys=True).encode())
    h.update(np.ascontiguousarray(np.asarray(omega, dtype=float)).tobytes())
    h.update(parts)
    return h.hexdigest()


def _cache_read(key: str) -> Hydro | None:
    """The cached :class:`Hydro` for ``key``, or None (missing, unreadable or corrupt)."""
    got = _cache_load(key)
    if got is None:
        return None
    z, meta = got
    try:
        return Hydro(omega=z["omega"], added_mass=z["added_mass"],
                     radiation_damping=z["radiation_damping"], excitation=z["excitation"],
                     hydrostatic_stiffness=float(meta["C"]), mass=float(meta["M"]),
                     rho=float(meta["rho"]), g=float(meta["g"]),
                     water_depth=float(meta["depth"]), description=str(meta["description"]))
    except Exception:  # noqa: BLE001 - any failure means: recompute, never trust it
        return None


_ARRAYS = ("omega", "added_mass", "radiation_damping", "excitation")


def _cache_load(key: str):
    """``(arrays, meta)`` stored under ``key`` (arrays: a dict of :data:`_ARRAYS`; meta: the
    decoded JSON), or None when missing, unreadable or corrupt (digest or key mismatch)."""
    path = cache_dir() / f"{key}.npz"
    try:
        with np.load(path, allow_pickle=False) as z:
            if str(z["key"]) != key or _array_digest(z) != str(z["digest"]):
                return None
            return {name: np.array(z[name]) for name in _ARRAYS}, json.loads(str(z["meta"]))
    except Exception:  # noqa: BLE001 - any failure means: recompute, never trust it
        return None


def _array_digest(arrays) -> str:
    h = hashlib.sha256()
    for name in _ARRAYS:
        h.update(np.ascontiguousarray(np.asarray(arrays[name])).tobytes())
    h.update(str(arrays["meta"]).encode())
    return h.hexdigest()


def _cache_write(key: str, hydro: Hydro) -> None:
    """Store ``hydro`` under ``key`` atomically; a cache that cannot be written is skipped."""
    _cache_store(key, {name: getattr(hydro, name) for name in _ARRAYS},
                 {"C": hydro.hydrostatic_stiffness, "M": hydro.mass, "rho": hydro.rho,
                  "g": hydro.g, "depth": repr(hydro.water_depth),
                  "description": hydro.description})


def _cache_store(key: str, arrays: dict, meta: dict) -> None:
    """Store the :data:`_ARRAYS` in ``arrays`` and the JSON ``meta`` under ``key``,
    atomically; a cache that cannot be written is skipped."""
    from ..fileio import write_bytes

    arrays = {name: np.asarray(arrays[name]) for name in _ARRAYS}
    arrays["meta"] = np.array(json.dumps(meta))
    arrays["digest"] = np.array(_array_digest(arrays))
    arrays["key"] = np.array(key)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    with contextlib.suppress(Exception):
        d = cache_dir()
        d.mkdir(parents=True, exist_ok=True)
        write_bytes(d / f"{key}.npz", buf.getvalue())


# -- BEM -------------------------------------------------------------------------------------
def _quiet_capytaine():
    import capytaine as cpt

    cpt.set_logging("ERROR")
    return cpt


def _params(**kw) -> bytes:
    return json.dumps({k: repr(v) for k, v in kw.items()}, sort_keys=True).encode()


def _solve(build, omega, *, rho, g, water_depth, description, cache, key_parts):
    """Hydrostatics and heave BEM of the body ``build()`` returns, cached on disk.

    ``build()`` gives ``(mesh, hull)``: the immersed surface for the BEM (possibly
    rotation-symmetric) and the same surface as a plain mesh for the hydrostatics.
    ``key_parts`` (bytes) determine the mesh: the parameters of a generated mesh, or the
    bytes of a mesh file; with the frequencies, ``rho``, ``g`` and the depth they make the
    cache key, so a cached result is found without meshing.
    """
    omega = np.asarray(omega, dtype=float)
    key = _cache_key(key_parts, omega, rho, g, water_depth)
    if cache:
        hit = _cache_read(key)
        if hit is not None:
            return hit
    cpt = _quiet_capytaine()
    import xarray as xr

    mesh, hull = build()
    dofs = cpt.rigid_body_dofs(only=["Heave"])
    plain = cpt.FloatingBody(mesh=hull, dofs=dofs, center_of_mass=(0.0, 0.0, 0.0))
    c = float(np.asarray(plain.compute_hydrostatic_stiffness(rho=rho, g=g)).ravel()[0])
    volume = float(plain.disp_volume)
    mass = rho * volume
    body = cpt.FloatingBody(mesh=mesh, dofs=dofs, center_of_mass=(0.0, 0.0, 0.0))
    test = xr.Dataset(coords={"omega": omega, "wave_direction": [0.0],
                              "radiating_dof": ["Heave"], "water_depth": [water_depth],
                              "rho": [rho], "g": [g]})
    ds = cpt.BEMSolver().fill_dataset(test, body, n_jobs=1, progress_bar=False)
    hydro = _from_dataset(ds, c=c, mass=mass,
                          description=f"{description}, {hull.nb_faces} panels")
    if cache:
        _cache_write(key, hydro)
    return hydro


def _omega_grid(omega):
    if omega is None:
        return None
    w = np.atleast_1d(np.asarray(omega, dtype=float)).ravel()
    if w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0) or np.any(np.diff(w) <= 0):
        raise ParameterError("omega: expected angular frequencies > 0 (rad/s), strictly "
                             "increasing")
    return w


#: The default frequency grid of the parametric bodies: 0.3 to 12 rad/s (periods 0.52 s to
#: 21 s), 30 points.
DEFAULT_OMEGA = np.linspace(0.3, 12.0, 30)


def _keep_resolvable(omega, h, g, depth):
    keep = _resolvable(omega, h, g, depth)
    if not np.any(keep):
        # the shortest resolvable wave: wavelength 8 h, its period from the dispersion relation
        k = 2 * math.pi / (8 * h)
        period = 2 * math.pi / math.sqrt(g * k * (math.tanh(k * depth) if math.isfinite(depth)
                                                  else 1.0))
        raise ParameterError(f"omega: every frequency is too high for a mesh of panel radius "
                             f"{h:.3g} m: it resolves waves longer than {8 * h:.3g} m, "
                             f"periods above {period:.3g} s")
    # a contiguous lower part: the resolvable frequencies are those below a limit
    return omega[keep]


def cylinder(radius, draft, *, omega=None, rho=1025.0, g=9.81, water_depth=math.inf,
             cache=True, refine=1.0) -> Hydro:
    """Heave coefficients of a vertical circular cylinder floating at ``draft``.

    Parameters
    ----------
    radius, draft : float
        Radius and draft (m), both > 0.
    omega : array_like or "body", optional
        Angular frequencies (rad/s) for the BEM (default ``DEFAULT_OMEGA``; see
        :func:`frequencies_for`). Frequencies too high for the finest panel the meshing
        rule allows are left out (the coefficients are then above range there). ``"body"``:
        the mesh from the geometry alone (panel radius ``scale / GEOMETRY_PANELS``, ``scale``
        the smaller of radius and draft, divided by ``refine``) and the body's own grid
        (:func:`body_frequencies` of the panel radius ``scale / GEOMETRY_PANELS``, whatever
        ``refine``), the same for every call.
    rho, g, water_depth : float
        Water density (kg/m^3), gravity (m/s^2), depth (m; ``inf`` deep water).
    cache : bool
        Read and write the on-disk cache.
    refine : float
        Divide the automatic panel radius (:func:`mesh_size`) by this factor.

    Returns
    -------
    Hydro
    """
    radius = check_positive("radius", radius)
    draft = check_positive("draft", draft)
    rho, g, water_depth, refine = _common(rho, g, water_depth, refine)
    scale = cylinder_scale(radius, draft)
    h, omega = _mesh_and_grid(scale, omega, g, water_depth, refine)
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    kw = dict(length=2 * draft, radius=radius, center=(0.0, 0.0, 0.0), faces_max_radius=h)

    def build():
        cpt = _quiet_capytaine()
        return (cpt.mesh_vertical_cylinder(axial_symmetry=True, **kw).immersed_part(),
                cpt.mesh_vertical_cylinder(**kw).immersed_part())

    desc = f"vertical cylinder, radius {radius:g} m, draft {draft:g} m"
    if scale > min(radius, draft):
        desc += (f", panel radius {h:.3g} m (a wide, shallow body: the panels follow the "
                 "shortest wave solved, not the draft)")
    return _solve(build, omega, rho=rho, g=g, water_depth=water_depth, description=desc,
                  cache=cache, key_parts=_params(body="cylinder", **kw))


def sphere(radius, *, omega=None, rho=1025.0, g=9.81, water_depth=math.inf, cache=True,
           refine=1.0) -> Hydro:
    """Heave coefficients of a sphere floating at its centre (half immersed).

    Parameters as :func:`cylinder`; ``radius`` (m) > 0.
    """
    radius = check_positive("radius", radius)
    rho, g, water_depth, refine = _common(rho, g, water_depth, refine)
    h, omega = _mesh_and_grid(radius, omega, g, water_depth, refine)
    if math.isfinite(water_depth) and radius >= water_depth:
        raise ParameterError(f"radius: expected less than the water depth {water_depth:g} m, "
                             f"got {radius!r}")
    kw = dict(radius=radius, center=(0.0, 0.0, 0.0), faces_max_radius=h)

    def build():
        cpt = _quiet_capytaine()
        return (cpt.mesh_sphere(axial_symmetry=True, **kw).immersed_part(),
                cpt.mesh_sphere(**kw).immersed_part())

    desc = f"sphere floating at its centre, radius {radius:g} m"
    return _solve(build, omega, rho=rho, g=g, water_depth=water_depth, description=desc,
                  cache=cache, key_parts=_params(body="sphere", **kw))


def _mesh_and_grid(scale, omega, g, depth, refine):
    """The panel radius and the frequencies of a parametric body of size ``scale``."""
    if isinstance(omega, str) and omega == "body":
        # the grid is the body's (from its geometry mesh), whatever ``refine``: a refined or
        # a coarsened mesh of the same body answers on the same frequencies
        h = scale / GEOMETRY_PANELS
        return h / refine, body_frequencies(h, g=g, water_depth=depth)
    omega = DEFAULT_OMEGA if omega is None else _omega_grid(omega)
    h = mesh_size(scale, omega[-1], g=g, water_depth=depth, refine=refine)
    return h, _keep_resolvable(omega, h, g, depth)


def _common(rho, g, water_depth, refine):
    rho = check_positive("rho", rho)
    g = check_positive("g", g)
    depth = float(water_depth)
    if not depth > 0:
        raise ParameterError(f"water-depth: expected a depth > 0 m or inf, got {water_depth!r}")
    refine = check_positive("refine", refine)
    return rho, g, depth, refine


def _open_edges(mesh, tol):
    """Edges of ``mesh`` used by exactly one face, as pairs of vertex coordinates."""
    verts = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.faces)
    # merge coincident vertices (many file formats repeat them face by face)
    keys = np.round(verts / tol).astype(np.int64)
    _, ids = np.unique(keys, axis=0, return_inverse=True)
    ids = ids.ravel()
    count: dict = {}
    for face in faces:
        f = [ids[i] for i in face]
        ring = [v for j, v in enumerate(f) if v != f[j - 1]]  # drop degenerate edges
        for j in range(len(ring)):
            e = (min(ring[j - 1], ring[j]), max(ring[j - 1], ring[j]))
            if e[0] != e[1]:
                count[e] = count.get(e, 0) + 1
    first = {}
    for i, k in enumerate(ids):
        first.setdefault(k, i)
    return [(verts[first[a]], verts[first[b]]) for (a, b), n in count.items() if n == 1]


def from_mesh(path, *, omega=None, rho=1025.0, g=9.81, water_depth=math.inf, cache=True,
              file_format=None) -> Hydro:
    """Heave coefficients of the body in a mesh file (any format Capytaine reads).

    The mesh is in the body's floating position (``z = 0`` the free surface, ``z`` up). It
    may be the whole hull or only its wetted part; its immersed part must be closed up to
    the waterline: every edge used by one panel only must lie on ``z = 0``.

    Parameters as :func:`cylinder`; the panel size is the file's (``omega="body"``: the
    body's grid, :func:`body_frequencies`, from the largest panel radius).
    """
    rho, g, water_depth, _ = _common(rho, g, water_depth, 1.0)
    hull, omega, desc, parts = _mesh_file(path, omega, g, water_depth, file_format)
    return _solve(lambda: (hull, hull), omega, rho=rho, g=g, water_depth=water_depth,
                  description=desc, cache=cache, key_parts=parts)


def _mesh_file(path, omega, g, water_depth, file_format):
    """The checked immersed part of the mesh in the file ``path``, the frequencies of its
    BEM, its description and the bytes keying its cache (see :func:`from_mesh`)."""
    body_grid = isinstance(omega, str) and omega == "body"
    omega = DEFAULT_OMEGA if omega is None or body_grid else _omega_grid(omega)
    from .. import limits

    p = Path(path)
    name = "mesh"
    _regular_file(p, name, "a mesh file")
    _gdf_precount(p, file_format, limits.BUOY_MAX_MESH_PANELS)
    cpt = _quiet_capytaine()
    try:
        raw = cpt.load_mesh(p, file_format)
    except Exception as exc:  # noqa: BLE001 - Capytaine raises many types for bad files
        reason = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise ParameterError(f"{name}: cannot read {str(p)!r} as a mesh: {reason}") from None
    raw = _plain(raw)
    if raw.nb_faces == 0:
        raise ParameterError(f"{name}: {str(p)!r} has no panels")
    try:
        hull = raw.immersed_part()
    except Exception:  # noqa: BLE001
        hull = None
    if hull is None or hull.nb_faces == 0:
        raise ParameterError(f"{name}: {str(p)!r} has no immersed part (no panel below z = 0; "
                             "the mesh must be in its floating position)")
    cap = limits.BUOY_MAX_MESH_PANELS
    if hull.nb_faces > cap:
        raise ParameterError(f"{name}: {str(p)!r} has {hull.nb_faces} immersed panels; the BEM "
                             f"(a dense panels x panels solve per frequency) takes at most "
                             f"{cap} in about a minute and 2 GB: coarsen the mesh")
    size = float(np.ptp(np.asarray(hull.vertices), axis=0).max())
    tol = 1e-6 * size
    bad = [e for e in _open_edges(hull, tol)
           if abs(e[0][2]) > 1e-4 * size or abs(e[1][2]) > 1e-4 * size]
    if bad:
        z = min(min(e[0][2], e[1][2]) for e in bad)
        raise ParameterError(f"{name}: {str(p)!r} is not closed: {len(bad)} panel edges "
                             f"below the waterline belong to one panel only (the lowest at "
                             f"z = {z:.3g} m)")
    volume = float(cpt.FloatingBody(mesh=hull).disp_volume)
    if not volume > 0:
        raise ParameterError(f"{name}: {str(p)!r} encloses no displaced volume (are its "
                             "normals pointing outwards?)")
    radii = np.asarray(hull.faces_radiuses)
    h = float(radii.max())
    omega = (body_frequencies(h, g=g, water_depth=water_depth) if body_grid
             else _keep_resolvable(omega, h, g, water_depth))
    desc = f"mesh {p.name}, immersed part"
    parts = b"file|" + str(file_format).encode() + b"|" + p.read_bytes()
    return hull, omega, desc, parts


def _gdf_precount(p: Path, file_format, cap: int) -> None:
    """Refuse a WAMIT ``.gdf`` mesh whose panels lying wholly below the waterline (a lower
    bound of its immersed part) already exceed ``cap``, before Capytaine reads it (its reader
    took 25 s for 40 000 panels). Any other file, or a GDF this simple reading does not
    follow (its panel count and its numbers disagree), is left to Capytaine."""
    fmt = (file_format or p.suffix.lstrip(".")).lower()
    if fmt not in ("gdf", "wamit"):
        return
    try:
        lines = p.read_text().splitlines()
        count = int(lines[3].split()[0])
        xyz = np.array(" ".join(lines[4:]).split(), dtype=float)
    except (OSError, ValueError, IndexError, UnicodeDecodeError):
        return
    if count <= cap or xyz.size != 12 * count:
        return
    below = int(np.sum(np.all(xyz.reshape(count, 4, 3)[:, :, 2] <= 0.0, axis=1)))
    if below > cap:
        raise ParameterError(f"mesh: {str(p)!r} has at least {below} immersed panels; the BEM "
                             f"(a dense panels x panels solve per frequency) takes at most "
                             f"{cap} in about a minute and 2 GB: coarsen the mesh")


def _regular_file(p: Path, name: str, what: str) -> None:
    """Refuse ``p`` unless it is a regular file of at most
    :data:`parapend.limits.BUOY_MAX_FILE_BYTES` (a directory, FIFO or device is named; a FIFO
    is opened without blocking, as :func:`parapend.excitation._read_bounded` does)."""
    import stat

    from .. import limits

    shown = repr(str(p))
    if p.is_dir():
        raise ParameterError(f"{name}: expected {what}, got the directory {shown}")
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise ParameterError(f"{name}: cannot read {shown}: no such file") from None
    except OSError as exc:
        raise ParameterError(f"{name}: cannot read {shown}: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
    finally:
        os.close(fd)
    if not stat.S_ISREG(st.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else
                "a character device" if stat.S_ISCHR(st.st_mode) else
                "a block device" if stat.S_ISBLK(st.st_mode) else
                "a socket" if stat.S_ISSOCK(st.st_mode) else "not a regular file")
        raise ParameterError(f"{name}: expected {what}, got {kind}: {shown} (save it to a "
                             "file first)")
    cap = limits.BUOY_MAX_FILE_BYTES
    if st.st_size > cap:
        raise ParameterError(f"{name}: {shown} is larger than {cap >> 20} MiB; expected {what}")


def _plain(mesh):
    """``mesh`` as a plain Capytaine Mesh (symmetric meshes merged)."""
    if hasattr(mesh, "merged") and type(mesh).__name__ != "Mesh":
        with contextlib.suppress(Exception):
            return mesh.merged()
    return mesh


# -- datasets --------------------------------------------------------------------------------
def _pick(da, dim, label, name, path):
    if dim not in da.dims:
        return da
    labels = [str(v) for v in da[dim].values]
    if label not in labels:
        raise ParameterError(f"hydro: {path} has no heave degree of freedom ({dim} "
                             f"{', '.join(labels) or 'empty'}; expected 'Heave') in {name}")
    return da.isel({dim: labels.index(label)})


def _numeric(values, name, path, kind="f"):
    """``values`` as a float (``kind="f"``) or complex array; refuse a variable that is not
    numeric (a string, an object array) or not finite, in one line."""
    v = np.asarray(values)
    if v.dtype.kind not in "iufcb" or v.dtype.kind == "b":
        raise ParameterError(f"hydro: {path}: {name} is not numeric (type {v.dtype}); "
                             "expected numbers")
    if kind == "f" and v.dtype.kind == "c":
        if np.any(v.imag != 0):
            raise ParameterError(f"hydro: {path}: {name} is complex; expected real numbers")
        v = v.real
    v = v.astype(complex if kind == "c" else float)
    if not np.all(np.isfinite(v)):
        raise ParameterError(f"hydro: {path}: {name} holds NaN or infinite values")
    return v


def _scalar(ds, name, default):
    if name in ds.coords or name in ds.variables:
        v = np.asarray(ds[name].values).ravel()
        if v.size != 1:
            raise ParameterError(f"hydro: expected one value of {name}, got {v.size}")
        if v.dtype.kind not in "iuf":
            raise ParameterError(f"hydro: {name} is not a number (type {v.dtype})")
        return float(v[0])
    return default


def _check_scales(path, rho, g, depth, values):
    """Refuse (one line) a dataset whose water, gravity or coefficients are out of physical
    reach: ``rho`` in :data:`parapend.limits.BUOY_RHO_RANGE`, ``g`` in
    ``UNIT_GRAVITY_RANGE``, a depth of at least ``BUOY_MIN_DEPTH`` (or infinite), every
    coefficient at most ``BUOY_MAX_COEFFICIENT`` in magnitude."""
    from .. import limits

    checks = (("rho", rho, limits.BUOY_RHO_RANGE, "kg/m^3"),
              ("g", g, limits.UNIT_GRAVITY_RANGE, "m/s^2"))
    for name, v, (lo, hi), unit in checks:
        if not lo <= v <= hi:
            raise ParameterError(f"hydro: {path}: expected {name} in [{lo:g}, {hi:g}] "
                                 f"{unit}, got {v:g}")
    if not (depth >= limits.BUOY_MIN_DEPTH):
        raise ParameterError(f"hydro: {path}: expected a water_depth of at least "
                             f"{limits.BUOY_MIN_DEPTH:g} m (or inf, deep water), got {depth:g}")
    cap = limits.BUOY_MAX_COEFFICIENT
    for name, v in values.items():
        top = float(np.max(np.abs(np.asarray(v))))
        if top > cap:
            raise ParameterError(f"hydro: {path}: {name} reaches {top:.3g} in magnitude, "
                                 f"more than {cap:g} (SI units; the powers square it)")


def _direction(fx, wave_direction, path):
    """``fx`` at the chosen wave direction (rad; default 0, the waves travelling along
    +x): one of the dataset's directions, else refused naming them."""
    from .. import limits

    if "wave_direction" not in fx.dims and "wave_direction" not in fx.coords:
        return fx
    dirs = np.atleast_1d(_numeric(fx["wave_direction"].values, "wave_direction", path))
    want = 0.0 if wave_direction is None else float(wave_direction)
    gap = np.abs(np.angle(np.exp(1j * (dirs - want))))
    i = int(np.argmin(gap))
    if gap[i] > limits.BUOY_DIRECTION_TOL:
        have = ", ".join(f"{d:g}" for d in dirs[:8]) + (", ..." if dirs.size > 8 else "")
        raise ParameterError(f"wave-direction: {path} has no wave direction {want:g} rad; "
                             f"choose one of {have} (rad) with --wave-direction")
    return fx.isel(wave_direction=i) if "wave_direction" in fx.dims else fx


def _dof_matrix(da, path, name):
    """``da`` (omega, radiating_dof, influenced_dof) as an array (n, d, d), or None when it
    has one DOF or lacks the dimensions."""
    if not ("radiating_dof" in da.dims and "influenced_dof" in da.dims):
        return None
    rad = [str(v) for v in da["radiating_dof"].values]
    inf = [str(v) for v in da["influenced_dof"].values]
    common = [d for d in rad if d in inf]
    if len(common) < 2:
        return None
    sub = da.sel(radiating_dof=common, influenced_dof=common)
    extra = [d for d in sub.dims if d not in ("omega", "radiating_dof", "influenced_dof")]
    for d in extra:
        sub = sub.isel({d: 0})
    return _numeric(sub.transpose("omega", "radiating_dof", "influenced_dof").values,
                    name, path)


def _physics(w, a_full, b_full, b, path):
    """Check the radiation coefficients as physics: the matrices over the DOFs symmetric
    within ``parapend.limits.BUOY_SYMMETRY_TOL``, the damping positive semidefinite
    at each frequency (heave's ``B >= 0``; where it is negative by less than the tolerance,
    BEM noise, it is set to 0 by :class:`Hydro`, and named in a note). Returns the mask of
    the frequencies kept and the notes; refuses (one line) data whose damping is negative
    beyond the tolerance, or nowhere positive."""
    from .. import limits

    notes = []
    tol = limits.BUOY_SYMMETRY_TOL
    eig_b = None
    for name, m in (("added_mass", a_full), ("radiation_damping", b_full)):
        if m is None:
            continue
        scale = max(float(np.max(np.abs(m))), 1e-300)
        asym = float(np.max(np.abs(m - np.swapaxes(m, 1, 2)))) / scale
        if asym > tol:
            raise ParameterError(f"hydro: {path}: {name} is not symmetric over the degrees of "
                                 f"freedom (relative asymmetry {asym:.2g}, more than {tol:g}): "
                                 "not a body's radiation coefficients")
        if asym > 1e-9:
            notes.append(f"hydro: {name} symmetrised over the degrees of freedom (relative "
                         f"asymmetry {asym:.2g})")
        if name == "radiation_damping":
            eig_b = np.linalg.eigvalsh(0.5 * (m + np.swapaxes(m, 1, 2))).min(axis=1)
    top = float(np.max(b))
    if not top > 0:
        raise ParameterError(f"hydro: {path}: radiation_damping in heave is nowhere positive "
                             f"(largest {top:.3g} N s/m): a floating body radiates, B > 0 "
                             "(negated data, or another sign convention?)")
    low = b if eig_b is None else np.minimum(b, eig_b)
    bad = low < -limits.BUOY_NEGATIVE_DAMPING_TOL * top
    slight = (low < 0) & ~bad
    if np.any(bad):
        i = int(np.argmin(low))
        raise ParameterError(f"hydro: {path}: radiation_damping is negative at "
                             f"{int(np.sum(bad))} of {w.size} frequencies (down to "
                             f"{low[i]:.3g} N s/m at {w[i]:.4g} rad/s, beyond "
                             f"{limits.BUOY_NEGATIVE_DAMPING_TOL:g} of its largest): a passive "
                             "body's damping is positive semidefinite")
    keep = np.ones(w.size, dtype=bool)
    if np.any(slight):
        named = ", ".join(f"{x:.4g}" for x in w[slight][:8]) + (
            ", ..." if np.sum(slight) > 8 else "")
        fix = float(np.max(-low[slight]))
        notes.append(f"hydro: radiation damping slightly negative (BEM noise, at most "
                     f"{limits.BUOY_NEGATIVE_DAMPING_TOL:g} of its largest) set to 0 at "
                     f"{int(np.sum(slight))} frequencies: {named} rad/s (largest "
                     f"correction {fix:.3g} N s/m, {fix / top:.2g} of its largest)")
    return keep, notes


def _by_omega(ds, path):
    """``ds`` with complex values merged and indexed by ``omega`` (from ``period`` or
    ``freq`` where it has no ``omega`` dimension)."""
    from capytaine.io.xarray import merge_complex_values

    for dim in ("omega", "period", "freq"):  # before merging (a copy) or any other work
        if dim in ds.dims:
            check_frequency_count(int(ds.sizes[dim]))
    if "complex" in ds.dims:
        ds = merge_complex_values(ds)
    if "omega" not in ds.dims:
        # a dataset indexed by period or frequency only (assemble_dataset(omega=False))
        if "period" in ds.dims:
            ds = ds.assign_coords(omega=("period", 2 * math.pi / ds["period"].values))
            ds = ds.swap_dims(period="omega")
        elif "freq" in ds.dims:
            ds = ds.assign_coords(omega=("freq", 2 * math.pi * ds["freq"].values))
            ds = ds.swap_dims(freq="omega")
        else:
            raise ParameterError(f"hydro: {path} has no omega (nor period, freq) coordinate")
    return ds


def _excitation(ds, path):
    """The excitation force of a Capytaine dataset: ``excitation_force``, else the sum of
    ``diffraction_force`` and ``Froude_Krylov_force``; refused (one line) without."""
    if "excitation_force" in ds:
        return ds["excitation_force"]
    if "diffraction_force" in ds and "Froude_Krylov_force" in ds:
        return ds["diffraction_force"] + ds["Froude_Krylov_force"]
    raise ParameterError(f"hydro: {path} has no excitation_force (nor diffraction_force "
                         "and Froude_Krylov_force)")


def _read_netcdf(path):
    """``(dataset, shown name, Path)`` of the NetCDF file ``path``, refused in one line
    when it is not a regular, readable NetCDF file."""
    import xarray as xr

    if not isinstance(path, (str, os.PathLike)) or not str(path):
        raise ParameterError(f"hydro: expected a NetCDF path or an xarray.Dataset, got "
                             f"{type(path).__name__}")
    p = Path(path)
    shown = repr(str(p))
    _regular_file(p, "hydro", "a NetCDF dataset")
    try:
        ds = xr.load_dataset(p)
    except Exception as exc:  # noqa: BLE001 - xarray's engines raise many types
        reason = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise ParameterError(f"hydro: cannot read {shown} as a NetCDF dataset: {reason}") \
            from None
    return ds, shown, p


def dataset_mass(ds, inertia_mass, path) -> tuple:
    """The floating mass ``M`` (kg) a Capytaine dataset states, and a note or None.

    The mass comes from the ``inertia_matrix`` (``inertia_mass``, its heave entry:
    Capytaine's ``compute_rigid_body_inertia`` of the floating body, ``rho V``) unless the
    dataset states its displacement: ``disp_mass``, or ``disp_volume`` times the dataset's
    ``rho``, which is then used. Where both are present and differ by more than
    ``parapend.limits.DATASET_MASS_RTOL`` of the displacement, a :class:`UserWarning`
    (and the returned note, which the result carries in its ``warnings``) names both
    numbers and the one used.

    Raises
    ------
    ParameterError
        Neither an ``inertia_matrix`` nor a displacement.
    """
    import warnings

    from ..limits import DATASET_MASS_RTOL

    stated, source = None, None
    if "disp_mass" in ds:
        stated = float(_numeric(np.asarray(ds["disp_mass"].values).ravel()[:1], "disp_mass",
                                path)[0])
        source = "disp_mass"
    elif "disp_volume" in ds:
        rho = _scalar(ds, "rho", 1025.0)
        volume = float(_numeric(np.asarray(ds["disp_volume"].values).ravel()[:1],
                                "disp_volume", path)[0])
        stated, source = rho * volume, f"disp_volume x rho ({volume:.6g} m^3 x {rho:g} kg/m^3)"
    if stated is None:
        if inertia_mass is None:
            raise ParameterError(f"hydro: {path} has no hydrostatics: the mass is missing "
                                 "(expected inertia_matrix, disp_mass or disp_volume)")
        return inertia_mass, None
    if inertia_mass is None or not abs(stated - inertia_mass) > DATASET_MASS_RTOL * abs(stated):
        return stated, None
    note = (f"hydro: {path}: the displacement {source} = {stated:.6g} kg and the "
            f"inertia_matrix's mass {inertia_mass:.6g} kg differ by "
            f"{100 * abs(stated - inertia_mass) / abs(stated):.3g} %; the displacement, "
            f"{stated:.6g} kg, is used as the floating mass")
    warnings.warn(note, UserWarning, stacklevel=3)
    return stated, note


def _from_dataset(ds, *, c=None, mass=None, description="", path="the dataset",
                  check=False, wave_direction=None):
    """A :class:`Hydro` from a Capytaine dataset (complex values merged, ``exp(-i w t)``)."""
    ds = _by_omega(ds, path)
    omega_name = "omega"
    for dim in ("radiating_dof", "influenced_dof"):
        if dim in ds.coords:
            labels = [str(v) for v in ds[dim].values]
            if "Heave" not in labels:
                raise ParameterError(f"hydro: {path} has no heave degree of freedom "
                                     f"({dim}: {', '.join(labels) or 'none'})")
    for var in ("added_mass", "radiation_damping"):
        if var not in ds:
            raise ParameterError(f"hydro: {path} has no {var} (a radiation problem in heave "
                                 "is needed)")
    fx = _excitation(ds, path)
    a = _pick(_pick(ds["added_mass"], "radiating_dof", "Heave", "added_mass", path),
              "influenced_dof", "Heave", "added_mass", path)
    b = _pick(_pick(ds["radiation_damping"], "radiating_dof", "Heave", "radiation_damping",
                    path), "influenced_dof", "Heave", "radiation_damping", path)
    fx = _pick(fx, "influenced_dof", "Heave", "excitation_force", path)
    if check:
        fx = _direction(fx, wave_direction, path)
        a_full = _dof_matrix(ds["added_mass"], path, "added_mass")
        b_full = _dof_matrix(ds["radiation_damping"], path, "radiation_damping")
    elif "wave_direction" in fx.dims:
        dirs = np.asarray(fx["wave_direction"].values, dtype=float)
        fx = fx.isel(wave_direction=int(np.argmin(np.abs(np.angle(np.exp(1j * dirs))))))
    for extra in [d for d in a.dims if d != omega_name]:
        a = a.isel({extra: 0})
    for extra in [d for d in b.dims if d != omega_name]:
        b = b.isel({extra: 0})
    for extra in [d for d in fx.dims if d != omega_name]:
        fx = fx.isel({extra: 0})
    if check:
        w = np.asarray(ds[omega_name].values)
        if w.dtype.kind not in "iuf":
            raise ParameterError(f"hydro: {path}: omega is not numeric (type {w.dtype})")
        w = w.astype(float)
        if np.any(np.isnan(w)) or np.any(w < 0):
            raise ParameterError(f"hydro: {path}: expected frequencies omega >= 0 (rad/s), "
                                 "got NaN or a negative one")
        # rows at omega = 0 or inf are dropped below; Capytaine leaves their excitation NaN
        rows = np.isfinite(w) & (w > 0)
        a, b, fx = (x.transpose(omega_name).values for x in (a, b, fx))
        for x, name in ((a, "added_mass"), (b, "radiation_damping"), (fx, "excitation_force")):
            _numeric(x[rows], name, path, "c" if name == "excitation_force" else "f")
        a = np.asarray(a.real if a.dtype.kind == "c" else a, dtype=float)
        b = np.asarray(b.real if b.dtype.kind == "c" else b, dtype=float)
        f = np.conj(np.asarray(fx, dtype=complex))
    else:
        w = np.asarray(ds[omega_name].values, dtype=float)
        a = np.asarray(a.transpose(omega_name).values, dtype=float)
        b = np.asarray(b.transpose(omega_name).values, dtype=float)
        f = np.conj(np.asarray(fx.transpose(omega_name).values, dtype=complex))
    finite = np.isfinite(w) & (w > 0)  # omega = 0 or inf rows carry no excitation
    order = np.argsort(w[finite])
    w, a, b, f = (x[finite][order] for x in (w, a, b, f))
    if w.size == 0:
        raise ParameterError(f"hydro: {path} has no finite frequency > 0")
    if np.any(np.diff(w) <= 0):
        raise ParameterError(f"hydro: {path} repeats a frequency")
    notes = []
    if check:
        a_full, b_full = ((None if m is None else m[finite][order]) for m in (a_full, b_full))
        keep, notes = _physics(w, a_full, b_full, b, path)
        w, a, b, f = (x[keep] for x in (w, a, b, f))
    if c is None:
        if "hydrostatic_stiffness" not in ds:
            raise ParameterError(f"hydro: {path} has no hydrostatics: hydrostatic_stiffness is "
                                 "missing (compute it with body.compute_hydrostatics)")
        cs = _pick(_pick(ds["hydrostatic_stiffness"], "radiating_dof", "Heave",
                         "hydrostatic_stiffness", path), "influenced_dof", "Heave",
                   "hydrostatic_stiffness", path)
        c = float(_numeric(np.asarray(cs.values).ravel()[:1], "hydrostatic_stiffness",
                           path)[0])
    if mass is None:
        inertia_mass = None
        if "inertia_matrix" in ds:
            ms = _pick(_pick(ds["inertia_matrix"], "radiating_dof", "Heave", "inertia_matrix",
                             path), "influenced_dof", "Heave", "inertia_matrix", path)
            inertia_mass = float(_numeric(np.asarray(ms.values).ravel()[:1], "inertia_matrix",
                                          path)[0])
        mass, note = dataset_mass(ds, inertia_mass, path)
        if note:
            notes.append(note)
    if not (math.isfinite(c) and c > 0):
        raise ParameterError(f"hydro: {path}: expected a heave hydrostatic_stiffness > 0, "
                             f"got {c!r}")
    if not (math.isfinite(mass) and mass > 0):
        raise ParameterError(f"hydro: {path}: expected a heave mass > 0, got {mass!r}")
    if check and np.any(mass + a <= 0):
        i = int(np.argmin(a))
        raise ParameterError(f"hydro: {path}: added_mass makes the heaving mass M + A <= 0 at "
                             f"{int(np.sum(mass + a <= 0))} of {w.size} frequencies (A = "
                             f"{a[i]:.4g} kg at {w[i]:.4g} rad/s, M = {mass:.4g} kg): not a "
                             "floating body's")
    rho = _scalar(ds, "rho", 1025.0)
    g = _scalar(ds, "g", 9.81)
    depth = _scalar(ds, "water_depth", math.inf)
    if check:
        _check_scales(path, rho, g, depth, {"added_mass": a, "radiation_damping": b,
                                            "excitation_force": f,
                                            "hydrostatic_stiffness": c, "mass": mass})
    return Hydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                 hydrostatic_stiffness=c, mass=mass, rho=rho, g=g, water_depth=depth,
                 description=description or str(ds.attrs.get("description", "")),
                 notes=tuple(notes))


def load(path, *, wave_direction=None) -> Hydro:
    """Read heave coefficients from a NetCDF dataset written by Capytaine, or take them
    from the :class:`xarray.Dataset` itself (a Capytaine user's ``fill_dataset`` result).

    Either ``capytaine.io.xarray.save_dataset_as_netcdf(path, ds)`` or
    ``separate_complex_values(ds).to_netcdf(path)``: complex values split along a
    ``complex`` dimension, Capytaine's convention ``exp(-i w t)``. The dataset needs a
    ``Heave`` degree of freedom, ``added_mass``, ``radiation_damping``, the excitation
    (``excitation_force``, or ``diffraction_force`` and ``Froude_Krylov_force``), the
    ``hydrostatic_stiffness`` and the mass (``inertia_matrix`` or ``disp_mass``).
    Rows at ``omega = 0`` or ``inf`` are ignored.

    The data are checked as physics: numbers of numeric type, finite; ``added_mass`` and
    ``radiation_damping`` symmetric over the degrees of freedom within
    ``parapend.limits.BUOY_SYMMETRY_TOL`` (symmetrised, with a note); the damping
    positive semidefinite at each frequency (where it is negative by less than
    ``parapend.limits.BUOY_NEGATIVE_DAMPING_TOL`` of its largest, BEM noise, it is set
    to 0 and the frequencies are named in a note; more is refused). ``wave_direction`` (rad,
    default 0) chooses one of the dataset's wave directions.

    Raises
    ------
    ParameterError
        One line naming what is missing.
    """
    import xarray as xr

    if isinstance(path, xr.Dataset):
        return _from_dataset(path, description=str(path.attrs.get("description", ""))
                             or "an xarray dataset", path="the dataset", check=True,
                             wave_direction=wave_direction)
    ds, shown, p = _read_netcdf(path)
    desc = str(ds.attrs.get("description", "")) or f"dataset {p.name}"
    return _from_dataset(ds, description=desc, path=shown, check=True,
                         wave_direction=wave_direction)


#: The degrees of freedom, in the order of every array (Capytaine's names).
DOFS = ("Surge", "Heave", "Pitch")

#: Bump when the hull's cached content or its BEM's rules (mesh, lid, frequencies left out)
#: change (with :data:`parapend.hydro.bem.CACHE_VERSION`, in every key).
HULL_CACHE_VERSION = 1


def _interp_columns(x, xp, fp, right=None):
    """``np.interp`` of every column of ``fp`` (n, k) at ``x`` (m,): an array (m, k)."""
    return np.stack([np.interp(x, xp, fp[:, j], right=right) for j in range(fp.shape[1])],
                    axis=-1)


def _stated_noise(notes) -> list:
    """The relative noise of the radiation damping stated in ``notes`` (its asymmetry, its
    negative part set to 0): what a cached or loaded dataset's reading measured."""
    import re

    out = []
    for n in notes:
        if "radiation" not in n or "damping" not in n:
            continue
        for pat in (r"relative asymmetry ([0-9.eE+-]+)", r", ([0-9.eE+-]+) of its largest\)"):
            for v in re.findall(pat, n):
                try:
                    out.append(float(v))
                except ValueError:
                    pass
    return out


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
    #: the relative noise of ``B`` (its asymmetry, or its negative eigenvalues set to 0,
    #: over its largest entry; at least as stated in ``notes``): the radiation bound's
    #: pseudo-inverse cuts singular values below it (:func:`parapend.hydro.hull.radiation_bound`)
    damping_noise: float = 0.0
    #: the degrees of freedom these coefficients are of (a class constant, not a field)
    dofs = ("surge", "heave", "pitch")

    def __post_init__(self):
        from .. import limits

        w = _coefficient_array("omega", self.omega).ravel()
        n = w.size
        check_frequency_count(n)
        a, b, c = (_coefficient_array(k, getattr(self, k)) for k in (
            "added_mass", "radiation_damping", "hydrostatic_stiffness"))
        f = _coefficient_array("excitation", self.excitation, complex)
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
        top = max(float(np.max(np.abs(b))), 1e-300)
        noise = max(float(self.damping_noise),
                    float(np.max(np.abs(b - np.swapaxes(b, 1, 2)))) / top,
                    *_stated_noise(self.notes))
        b = 0.5 * (b + np.swapaxes(b, 1, 2))
        notes = tuple(self.notes)
        lam, vec = np.linalg.eigh(b)
        if np.any(lam < -limits.BUOY_NEGATIVE_DAMPING_TOL * top):
            i = int(np.argmin(lam.min(axis=1)))
            raise ParameterError(f"hydro: radiation_damping is not positive semidefinite at "
                                 f"{w[i]:.4g} rad/s (eigenvalue {lam[i].min():.3g}, beyond "
                                 f"{limits.BUOY_NEGATIVE_DAMPING_TOL:g} of its largest entry)")
        # eigenvalues within rounding of 0 are left alone: a dataset written after this
        # correction reads back with the same coefficients and the same notes
        neg = np.any(lam < -64 * np.finfo(float).eps * top, axis=1)
        if np.any(neg):
            # BEM noise: the nearest positive semidefinite matrix (negative eigenvalues to 0)
            b[neg] = np.einsum("nij,nj,nkj->nik", vec[neg], np.maximum(lam[neg], 0.0),
                               vec[neg])
            b[neg] = 0.5 * (b[neg] + np.swapaxes(b[neg], 1, 2))
            fix = float(-lam[neg].min())
            note = (f"hydro: radiation damping slightly indefinite (BEM noise) made positive "
                    f"semidefinite at {int(np.sum(neg))} frequencies (largest "
                    f"correction {fix:.3g}, {fix / top:.2g} of its largest)")
            if note not in notes:
                notes = notes + (note,)
            noise = max(noise, fix / top)
        object.__setattr__(self, "damping_noise", noise)
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

    above_range = Hydro.above_range
    check_covers = Hydro.check_covers

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

    def _single(self, i, inertia) -> Hydro:
        """The DOF ``i`` alone as a heave-like :class:`~parapend.hydro.bem.Hydro`."""
        return Hydro(omega=self.omega, added_mass=self.added_mass[:, i, i],
                         radiation_damping=self.radiation_damping[:, i, i],
                         excitation=self.excitation[:, i],
                         hydrostatic_stiffness=float(self.hydrostatic_stiffness[i, i]),
                         mass=inertia, rho=self.rho, g=self.g, water_depth=self.water_depth,
                         description=self.description, notes=self.notes)

    def heave(self) -> Hydro:
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
        ds = _dataset(self.omega, self.added_mass, self.radiation_damping, self.excitation,
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

    Where the damping is indefinite beyond noise (``_physics``'s threshold: a fraction
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
    ds = _by_omega(ds, path)
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
    fx = _direction(_excitation(ds, path), wave_direction, path)
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
    a = _numeric(a[rows], "added_mass", path)
    b = _numeric(b[rows], "radiation_damping", path)
    f = np.conj(_numeric(f[rows], "excitation_force", path, "c"))
    order = np.argsort(w[rows])
    w, a, b, f = (x[order] for x in (w[rows], a, b, f))
    if w.size == 0:
        raise ParameterError(f"hydro: {path} has no finite frequency > 0")
    if np.any(np.diff(w) <= 0):
        raise ParameterError(f"hydro: {path} repeats a frequency")
    notes = []
    if own:
        w, a, b, f, notes = _resolved(w, a, b, f)
    notes += _physics(w, a, b, b[:, 1, 1], path)[1]
    if c is None:
        if "hydrostatic_stiffness" not in ds:
            raise ParameterError(f"hydro: {path} has no hydrostatics: hydrostatic_stiffness is "
                                 "missing (compute it with body.compute_hydrostatics)")
        c = _numeric(_dof_block(ds["hydrostatic_stiffness"],
                                    ("influenced_dof", "radiating_dof"), path,
                                    "hydrostatic_stiffness"), "hydrostatic_stiffness", path)
    if mass is None:
        inertia_mass = None
        if "inertia_matrix" in ds:
            m = _numeric(_dof_block(ds["inertia_matrix"],
                                        ("influenced_dof", "radiating_dof"), path,
                                        "inertia_matrix"), "inertia_matrix", path)
            inertia_mass = float(m[1, 1])
            if pitch_inertia is None:
                pitch_inertia = float(m[2, 2])
        mass, note = dataset_mass(ds, inertia_mass, path)
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
    rho, g = _scalar(ds, "rho", 1025.0), _scalar(ds, "g", 9.81)
    depth = _scalar(ds, "water_depth", math.inf)
    _check_hull_data(ds, path, rho, g, depth, a, b, f, c, mass, pitch_inertia)
    return HullHydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                     hydrostatic_stiffness=c, mass=mass, pitch_inertia=pitch_inertia,
                     rho=rho, g=g, water_depth=depth,
                     description=description or str(ds.attrs.get("description", "")),
                     notes=tuple(notes))


def _check_hull_data(ds, path, rho, g, depth, a, b, f, c, mass, pitch_inertia):
    """Refuse (one line naming the field) a hull dataset outside the limits the command's
    options have: ``rho``, ``g``, the depth and the coefficients' scales
    (:func:`_check_scales`), a pitch inertia beyond ``--hull-pitch-inertia``'s range
    (:data:`parapend.limits.HULL_PITCH_INERTIA_RANGE`), a rigid-body-plus-added mass matrix
    ``diag(M, M, I) + A(w)`` that is not positive definite at some frequency, and a
    ``rotation_center`` other than the origin O (the point every coefficient, the pivot and
    the wave's phase are taken about; the data are refused rather than moved)."""
    from .. import limits

    _check_scales(path, rho, g, depth, {"added_mass": a, "radiation_damping": b,
                                        "excitation_force": f, "hydrostatic_stiffness": c,
                                        "mass": mass})
    lo, hi = limits.HULL_PITCH_INERTIA_RANGE
    if pitch_inertia is not None and not lo <= pitch_inertia <= hi:
        raise ParameterError(f"hydro: {path}: expected a pitch inertia (inertia_matrix) in "
                             f"[{lo:g}, {hi:g}] kg m^2, got {pitch_inertia:g}")
    rigid = np.diag([mass, mass, 0.0 if pitch_inertia is None else pitch_inertia])
    low = np.linalg.eigvalsh(rigid + a).min(axis=1)
    scale = np.abs(rigid + a).max(axis=(1, 2))
    bad = np.nonzero(low <= 1e-9 * scale)[0]
    if bad.size:
        i = int(bad[0])
        raise ParameterError(f"hydro: {path}: added_mass plus the rigid-body mass is not "
                             f"positive definite at {bad.size} frequencies (eigenvalue "
                             f"{low[i]:.3g} at the first): not a body's inertia")
    rc = None
    for where in (ds.coords, ds.data_vars):
        if "rotation_center" in where:
            rc = np.asarray(where["rotation_center"].values, dtype=float).ravel()
    if "rotation_center" in ds.attrs:
        rc = np.asarray(ds.attrs["rotation_center"], dtype=float).ravel()
    if rc is not None and np.any(np.abs(rc[np.isfinite(rc)]) > 1e-9):
        shown = ", ".join(f"{v:g}" for v in rc[:3])
        raise ParameterError(f"hydro: {path}: rotation_center is ({shown}) m; the hull's "
                             "coefficients must be about the origin O (0, 0, 0), the rotation "
                             "centre the pivot and the wave phase are taken about: recompute "
                             "them with rotation_center=(0, 0, 0)")


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
    ds, shown, p = _read_netcdf(path)
    return _hull_from_dataset(ds, path=shown, wave_direction=wave_direction,
                              description=str(ds.attrs.get("description", ""))
                              or f"dataset {p.name}")


# -- BEM -------------------------------------------------------------------------------------
def _cached(key):
    got = _cache_load(key)
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
    key = _cache_key(f"hull{HULL_CACHE_VERSION}|surge,heave,pitch|".encode() + key_parts,
                         omega, rho, g, water_depth)
    if cache:
        hit = _cached(key)
        if hit is not None:
            return hit
    cpt = _quiet_capytaine()
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
        _cache_store(key, {name: getattr(hyd, name) for name in _ARRAYS},
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
    cpt = _quiet_capytaine()
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
    return mesh, _plain(mesh), (lid if lid.nb_faces else None)


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
    rho, g, water_depth, refine = _common(rho, g, water_depth, refine)
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    if not length**2 > 6 * draft**2:
        raise ParameterError(f"draft: a box barge {length:g} m long with a draft of {draft:g} m "
                             "is unstable in pitch about its waterplane centre (C55 = rho g L B "
                             f"(L^2/12 - D^2/2) <= 0): give a draft below length/sqrt(6) = "
                             f"{length / math.sqrt(6):.4g} m")
    h, omega = _mesh_and_grid(min(length, beam), omega, g, water_depth, refine)
    mass = rho * length * beam * draft
    desc = f"box barge, {length:g} x {beam:g} x {draft:g} m"
    return _solve_hull(lambda: _box_meshes(length, beam, draft, h, omega[-1]), omega,
                       rho=rho, g=g, water_depth=water_depth, description=desc, cache=cache,
                       key_parts=_params(body="barge", size=(length, beam, draft), h=h,
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
    rho, g, water_depth, refine = _common(rho, g, water_depth, refine)
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    if not radius**2 > 2 * draft**2:
        raise ParameterError(f"draft: a cylinder of radius {radius:g} m with a draft of "
                             f"{draft:g} m is unstable in pitch about its waterplane centre "
                             "(C55 = rho g pi R^2 (R^2/4 - D^2/2) <= 0): give a draft below "
                             f"radius/sqrt(2) = {radius / math.sqrt(2):.4g} m")
    h, omega = _mesh_and_grid(min(radius, draft), omega, g, water_depth, refine)
    kw = dict(length=2 * draft, radius=radius, center=(0.0, 0.0, 0.0), faces_max_radius=h)

    def build():
        cpt = _quiet_capytaine()
        return (cpt.mesh_vertical_cylinder(axial_symmetry=True, **kw).immersed_part(),
                cpt.mesh_vertical_cylinder(**kw).immersed_part(), None)

    mass = rho * math.pi * radius**2 * draft
    desc = f"vertical cylinder, radius {radius:g} m, draft {draft:g} m"
    return _solve_hull(build, omega, rho=rho, g=g, water_depth=water_depth, description=desc,
                       cache=cache, key_parts=_params(body="cylinder", **kw),
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
    rho, g, water_depth, refine = _common(rho, g, water_depth, refine)
    if not draft < radius:
        what = ("floating at its centre is neutral" if draft == radius else
                f"with a draft of {draft:g} m is unstable")
        raise ParameterError(f"draft: a sphere of radius {radius:g} m {what} in pitch about "
                             "its waterplane centre with its centre of mass there (C55 = rho g V "
                             "(radius - draft) <= 0): give a draft below the radius")
    if math.isfinite(water_depth) and draft >= water_depth:
        raise ParameterError(f"draft: expected less than the water depth {water_depth:g} m, "
                             f"got {draft!r}")
    h, omega = _mesh_and_grid(min(radius, draft), omega, g, water_depth, refine)
    kw = dict(radius=radius, center=(0.0, 0.0, radius - draft), faces_max_radius=h)

    def build():
        cpt = _quiet_capytaine()
        return (cpt.mesh_sphere(axial_symmetry=True, **kw).immersed_part(),
                cpt.mesh_sphere(**kw).immersed_part(), None)

    _, ix, iz = _cap_integrals(radius, draft)
    desc = f"sphere, radius {radius:g} m, draft {draft:g} m"
    return _solve_hull(build, omega, rho=rho, g=g, water_depth=water_depth, description=desc,
                       cache=cache, key_parts=_params(body="sphere", **kw),
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
    rho, g, water_depth, _ = _common(rho, g, water_depth, 1.0)
    hull, omega, desc, parts = _mesh_file(path, omega, g, water_depth, file_format)

    def unstable(c55):
        return (f"mesh: {str(path)!r} is not stable in pitch about its origin with the centre "
                f"of mass there (C55 = {c55:.4g} N m/rad <= 0): give a dataset (--hydro) "
                "computed with the hull's own centre of mass")

    return _solve_hull(lambda: (hull, hull, None), omega, rho=rho, g=g,
                       water_depth=water_depth, description=desc, cache=cache,
                       key_parts=parts, unstable=unstable)
