"""The coupled buoy as a power-matrix device (``--device buoy``): the design checked as
``parapend buoy`` checks it, the BEM solved once for every bin's band, and one bin's
realization solved as ``parapend buoy --hs --tp`` solves a seeded record.

The record of bin ``(i, j)``, realization ``r`` is the prescribed device's: ``Hs = hm0[i]``,
``Tp = tp[j]`` (the same Te/Tp conversion), ``repeat_period = waves * Tp``, seed
``seed + r``. Per realization the store keeps the coupled optimum's power, the radiation
bound ``sum_k |F_k a_k|^2 / (8 B_k)`` and the one-way answer (the pendulum's reaction left
out), all in W.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, check_int

__all__ = ["band", "body_hydro", "check_buoy", "check_file", "file_digest", "prepare",
           "refuse_for_buoy", "solve_buoy_bin", "water_of", "wave_of"]

#: the per-process coefficients, keyed by the body's description in the spec
_HYDRO: dict = {}


def _units(spec):
    from ..units import Units

    return Units(spec.length, spec.mass, 9.81, spec.inertia)


def wave_of(spec, i: int, j: int, r: int):
    """The Wave of bin ``(i, j)``, realization ``r`` (``parapend buoy``'s record builder on
    the prescribed device's arguments) and its description."""
    from ..hydro.api import _irregular_wave
    from ..seas import steepness_unchecked
    tp = spec.tp[j]
    with steepness_unchecked():  # a rectangle of bins: corners no sea reaches
        return _irregular_wave(spec.hm0[i], tp, spec.spectrum, spec.gamma_peak,
                               spec.repeat_period(j), int(spec.seeds[r]), spec.cutoff,
                               None, 0.1, _units(spec))


def _band(spec, j: int) -> tuple:
    """The significant components' band (rad/s) of period bin ``j`` and the highest
    component: as ``parapend buoy`` takes it from a record (amplitudes do not depend on
    the seed or on Hs, only their scale and phases do)."""
    wave, _ = wave_of(spec, 0, j, 0)
    amps = np.abs(np.asarray(wave.amplitudes))
    sig = np.nonzero(amps >= 1e-3 * amps.max())[0]
    top = np.nonzero(amps)[0][-1]
    return (wave.omega * (sig[0] + 1), wave.omega * (sig[-1] + 1), wave.omega * (top + 1))


def _key(spec) -> str:
    return repr((spec.body, spec.radius, spec.draft, spec.mesh, spec.hydro, spec.digest,
                 spec.band, spec.water_density, spec.water_depth))


def check_file(path, name: str) -> str:
    """A ``--mesh`` or ``--hydro`` path: a name of a regular file, absolute. A FIFO would
    block its reader for ever and ``/dev/zero`` (or a link to it) never ends: both are
    refused here, before the digest or the loader reads a byte."""
    import os
    import stat

    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise ParameterError(f"{name}: expected a file name, got {path!r:.60}")
    try:
        st = os.stat(path)
    except OSError as exc:
        raise ParameterError(f"{name}: cannot read {str(path)!r}: "
                             f"{exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a directory" if stat.S_ISDIR(st.st_mode) else
                "a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else
                "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else
                "not a regular file")
        raise ParameterError(f"{name}: expected a regular file, got {kind}: {str(path)!r}")
    return os.path.abspath(path)


def file_digest(path) -> str | None:
    """sha256 of a ``--mesh`` or ``--hydro`` file (None without one; a file that cannot be
    read is left to the loader's own error), read in blocks of 1 MiB (a 3 GB file was read
    whole into memory)."""
    if path is None:
        return None
    import hashlib

    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return None
    return h.hexdigest()


def body_hydro(spec):
    """The body's coefficients on the body's own frequency grid, the same as ``parapend
    buoy``'s (BEM solved once, cached on disk; one load per process), and the body's width
    (None for a mesh or a dataset)."""
    key = _key(spec)
    if key not in _HYDRO:
        from ..hydro.api import _hydro

        if spec.hydro is not None or (spec.water_density == 1025.0
                                      and spec.water_depth is None):
            _HYDRO[key] = _hydro(spec.body, spec.radius, spec.draft, spec.mesh, spec.hydro)
        else:
            _HYDRO[key] = _body_in_water(spec)
    return _HYDRO[key]


def _body_in_water(spec):
    """The body of ``spec`` solved in the matrix's water (``water_density``, ``water_depth``;
    ``parapend buoy`` solves it at 1025 kg/m^3 in deep water): the same checks and mesh as
    :func:`parapend.hydro.api._hydro`, another ``rho`` and depth; in deep water its
    frequency grid too, at a finite depth :func:`_finite_grid` (a ``--mesh``: 48
    frequencies over the bins' band); deeper than ``DEEP_RATIO`` wavelengths of its lowest
    frequency, in deep water (the flux then too). The BEM refuses a draft (a sphere's
    radius) not less than the depth in one line."""
    from ..hydro import bem as hy
    from ..hydro.api import _dimensions
    from .resource import DEEP_RATIO

    depth = math.inf if spec.water_depth is None else spec.water_depth

    def deep(omega):
        # deeper than DEEP_RATIO wavelengths at the lowest frequency (the flux's rule):
        # deep water to about exp(-4 pi DEEP_RATIO) ~ 1e-11; Capytaine's finite-depth Green
        # function gave NaN coefficients at 1e300 m
        return depth >= DEEP_RATIO * 2 * math.pi * 9.81 / float(omega[0]) ** 2

    if spec.mesh is not None:
        for name in ("radius", "draft"):
            if getattr(spec, name) is not None:
                raise ParameterError(f"{name}: the body comes from --mesh; drop it")
        if spec.body not in (None, "cylinder"):
            raise ParameterError("body: the body comes from --mesh; drop --body")
        omega = "body"
        if math.isfinite(depth):  # the band's grid (the file's mesh kept), see _finite_grid
            lo, hi = spec.band
            omega = np.linspace(0.9 * lo, 1.05 * hi, hy.BODY_FREQUENCIES)
            if deep(omega):
                omega, depth = "body", math.inf
        return hy.from_mesh(spec.mesh, omega=omega, rho=spec.water_density,
                            water_depth=depth), None
    r, d = _dimensions(spec.body, spec.radius, spec.draft)
    scale = r if spec.body == "sphere" else hy.cylinder_scale(r, d)  # bem.cylinder's
    omega = "body" if not math.isfinite(depth) else _finite_grid(spec, scale, depth)
    if not isinstance(omega, str) and deep(omega):
        omega, depth = "body", math.inf
    water = {"rho": spec.water_density, "water_depth": depth}
    if spec.body == "sphere":
        return hy.sphere(r, omega=omega, **water), 2 * r
    return hy.cylinder(r, d, omega=omega, **water), 2 * r


def _finite_grid(spec, scale: float, depth: float) -> np.ndarray:
    """The body's own frequency grid in water of ``depth`` (the same mesh: its top
    frequency sets the panel), from its last point at or below the matrix's band: Capytaine's
    finite-depth Green function gives NaN at the grid's first point (a 100 s wave, ``k h``
    below its tables), which no bin uses."""
    from ..hydro import bem as hy

    full = hy.body_frequencies(scale / hy.GEOMETRY_PANELS, g=9.81, water_depth=depth)
    first = max(0, int(np.searchsorted(full, spec.band[0], side="right")) - 1)
    return full[first:]


def refuse_for_buoy(*, response, gamma, gravity) -> None:
    """The prescribed device's options the buoy (and the hull) refuses, one line each."""
    if response is not None:
        raise ParameterError("response: the buoy's heave is solved, not prescribed; drop "
                             "--response with --device buoy")
    if gamma is not None:
        raise ParameterError("gamma: the buoy's pendulum takes its damping in SI; give "
                             "--damping-coefficient (N m s/rad) with --device buoy")
    if gravity != 9.81:
        raise ParameterError(f"gravity: the buoy's hydrodynamics use g = 9.81 m/s^2, got "
                             f"{gravity:g}; drop --gravity with --device buoy")


def check_buoy(*, response, gamma, gravity, winding, harmonics, efficiency, mass, length,
               inertia, damping_coefficient):
    """The options the buoy device refuses or takes in its own sense; returns the checked
    pendulum (``parapend buoy``'s checks) and ``(winding, harmonics)``."""
    from ..hydro.api import _pendulum

    refuse_for_buoy(response=response, gamma=gamma, gravity=gravity)
    if efficiency is not None:
        from .check import check_efficiency

        efficiency = check_efficiency(efficiency)
    if isinstance(winding, str):
        raise ParameterError(f"winding: expected a positive integer with --device buoy (turns "
                             f"per record), got {winding!r:.40}")
    winding = check_int("winding", winding, 1, 64)
    if harmonics is not None:
        harmonics = check_int("harmonics", harmonics, 2, 4096)
    pend = _pendulum(mass, length, inertia, damping_coefficient)  # the declared defaults
    # the damping's non-dimensional gamma = c t0 / I is what the solver takes (at most
    # MAX_GAMMA): checked here, not in every bin (1e300 N m s/rad failed each bin alone)
    from ..units import Units

    Units(pend.length, pend.mass, 9.81, pend.inertia).gamma(pend.damping_coefficient)
    return pend, winding, harmonics, None if efficiency is None else float(efficiency)


def prepare(spec):
    """Solve (or load) the body over every bin's band, check each bin is covered and that
    the pendulum floats; returns the body's width."""
    h, width = body_hydro(spec)
    pk = spec.period_kind
    for j, per in enumerate(spec.period):
        lo, hi, _ = _band(spec, j)
        try:
            h.check_covers(lo, hi, name="record")
        except ParameterError as err:
            raise ParameterError(f"{pk}: the record of the bin {per:g} s spans "
                                 + str(err).split(": ", 1)[1]) from None
    from ..hydro.api import _check_floats

    _check_floats(h, pendulum(spec))
    return width


def water_of(spec, body=None) -> tuple:
    """``(density, depth)`` of the water the body was solved in (``depth`` None: deep), for
    the waves' energy flux: a ``--hydro`` dataset's own ``rho`` and depth, the matrix's
    (``spec.water_density``, ``spec.water_depth``) for a body solved here. A dataset's
    ``g`` must be the pendulum's 9.81 m/s^2 and its ``rho`` a water's (a rho of 1e-300
    gave a capture width of 5.6e302 m). ``body``: the coefficients when the caller holds
    them (the hull's, :func:`.hull_device.hull_of`), else the body's of ``spec``."""
    h = body if body is not None else body_hydro(spec)[0]
    rho, g, depth = float(h.rho), float(h.g), float(h.water_depth)
    where = f" of {spec.hydro}" if spec.hydro is not None else ""
    if not abs(g - 9.81) <= 1e-9 * 9.81:
        raise ParameterError(f"hydro: the dataset{where} is solved at g = {g:g} m/s^2; the "
                             "buoy's pendulum and waves use 9.81: solve it at g = 9.81")
    if not 500.0 <= rho <= 2000.0:
        raise ParameterError(f"hydro: the dataset{where} has rho = {rho:g} kg/m^3; expected "
                             "a water's density, 500 to 2000 kg/m^3")
    return rho, (None if math.isinf(depth) else depth)


def band(spec) -> tuple:
    """``(w_lo, w_hi)`` of every period bin together: the BEM's range (rad/s)."""
    bands = [_band(spec, j) for j in range(len(spec.period))]
    return (float(min(b[0] for b in bands)), float(max(b[2] for b in bands)))


def pendulum(spec):
    from ..hydro.coupled import Pendulum

    return Pendulum(mass=spec.mass, length=spec.length, inertia=spec.inertia,
                    damping_coefficient=spec.damping_coefficient)


def solve_buoy_bin(spec, i: int, j: int, r: int) -> dict:
    """The coupled optimum, the radiation bound and the one-way optimum of one record (and,
    with ``--controller mpc``, the causal column on it: :mod:`.causal`)."""
    from ..hydro.result import _solve
    from ..maps.spec import _CODE

    h, _ = body_hydro(spec)
    wave, _ = wave_of(spec, i, j, r)
    eta = spec.efficiency
    sol, ow, _ = _solve(h, pendulum(spec), wave, winding=spec.winding,
                        harmonics=spec.harmonics, torque_limit=None,
                        efficiency=None if eta is None or eta == 1.0 else eta)
    p = float(sol.power)
    out = {}
    if eta is not None:
        # the electrical optimum (parapend buoy --efficiency); power is its motion's
        # mechanical power; efficiency 1 is the ideal optimum itself
        e = sol.electrical_power if sol.electrical_power is not None else p
        out["electrical_power"] = float(e)
        p_ok = e
    else:
        p_ok = p
    if p_ok <= 0:
        status = "no_power"
    elif sol.success:
        status = "converged"
    else:
        head = str(sol.status).split(";")[0].strip()
        status = head if head in _CODE and head != "converged" else "other"
    return {"power": p, "radiation_bound_power": float(sol.radiation_bound),
            "one_way_power": float(ow.power) if math.isfinite(ow.power) else math.nan,
            **out, "status": status}
