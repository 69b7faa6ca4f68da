"""Frozen result objects; their field names are the JSON keys of the command line."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

__all__ = ["CONVENTION", "OptimizeResult", "Record", "Result", "Table", "ThresholdResult",
           "annotate",
           "quantity", "to_jsonable"]

CONVENTION = ("theta from the upright; non-dimensional time (unit sqrt(l/g)); power positive "
              "when harvested, P = -<T theta'> (paper Eqs. 14-16; the paper's tables list -P "
              "of its Eq. 8)")


def to_jsonable(value):
    """Convert numpy scalars/arrays and nested containers to plain JSON types (NaN -> None)."""
    if isinstance(value, dict):
        return {k: to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return [to_jsonable(v) for v in value.tolist()]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    return value


#: Units and long names of the quantities that results hold, by field name. A field named
#: with a unit suffix (``power_w``, ``peak_torque_nm``) takes the suffix's unit
#: (``SUFFIX_UNITS``); the non-dimensional quantities of the paper's model are in the
#: pendulum's scales (time ``sqrt(l/g)``, torque and energy ``m g l``, power
#: ``m g l sqrt(g/l)``, as the design maps write them); counts and ratios have units "1".
_P, _T, _TIME, _RATE = "m g l sqrt(g/l)", "m g l", "sqrt(l/g)", "sqrt(g/l)"
QUANTITIES = {
    "power": (_P, "mean extracted power P = -<T theta'> (positive = harvested)"),
    "uniform_power": (_P, "power of the best uniform rotation (Eq. 17)"),
    "limit_power": (_P, "gamma -> 0 limit of the power (Eqs. 19/24/32)"),
    "upper_bound": (_P, "upper bound of the power"),
    "bound_gap": (_P, "upper bound minus power"),
    "electrical_power": (_P, "mean electrical power"),
    "mechanical_power": (_P, "mean mechanical power -<T theta'> of a lossy take-off (its "
                             "power is the electrical one)"),
    "instantaneous_power": (_P, "instantaneous power -T theta' (positive = harvested)"),
    "instantaneous_electrical_power": (_P, "instantaneous electrical power"),
    "sample_power": (_P, "mean power -T (theta_k+1 - theta_k) / dt of the held sample"),
    "sample_electrical_power": (_P, "electrical power of the held sample"),
    "mean_power": (_P, "mean harvested power"),
    "run_power": (_P, "mean harvested power of the run"),
    "record_power": (_P, "storage-corrected power over the last repeat of the record"),
    "predicted_power": (_P, "power of the target motion"),
    "power_at_threshold": (_P, "optimal power at the threshold"),
    "peak_torque": (_T, "peak torque |T|"),
    "tracked_peak_torque": (_T, "peak torque of the tracked optimum"),
    "torque_limit": (_T, "torque limit"),
    "gamma": (_RATE, "viscous damping gamma"),
    "damping_threshold": (_RATE, "damping threshold gamma*"),
    "uniform_threshold": (_RATE, "damping where the uniform rotation stops extracting"),
    "omega": (_RATE, "forcing frequency omega"),
    "delta": ("1", "base acceleration amplitude over g"),
    "time": (_TIME, "time"),
    "t": (_TIME, "time"),
    "phase": ("1", "time as a fraction of the forcing period"),
    "theta": ("rad", "pendulum angle from the upright"),
    "phi": ("rad", "pendulum angle"),
    "theta_dot": ("rad " + _RATE, "angular speed"),
    "phi_dot": ("rad " + _RATE, "angular speed"),
    "torque": (_T, "take-off torque on the pendulum"),
    "energy": (_T, "energy"),
    "q": ("1", "base acceleration over g"),
    "harmonics": ("1", "number of Fourier harmonics N"),
    "winding": ("1", "turns per forcing period K"),
    "iterations": ("1", "solver iterations"),
    "success": ("1", "the solver converged"),
    "mean_square_speed": (_RATE + "^2", "mean square speed <theta'^2>"),
    "efficiency_generating": ("1", "take-off efficiency while generating"),
    "efficiency_motoring": ("1", "take-off efficiency while motoring"),
    "bound_fraction": ("1", "power over the radiation bound"),
    "capture_width_ratio": ("1", "capture width over the body's width"),
    "one_way_ratio": ("1", "coupled over one-way power"),
    "energy_balance_residual": ("1", "relative residual of the energy balance"),
    "damping_coefficient": ("N m s/rad", "viscous damping coefficient c"),
    "damping_threshold_coefficient": ("N m s/rad",
                                      "damping threshold as a coefficient c* = gamma* I / t0"),
    "uniform_threshold_coefficient": ("N m s/rad", "uniform-rotation threshold as a "
                                                   "damping coefficient"),
    # the causal controller's energy account (track --controller mpc, horizon)
    "harvested_power": (_P, "harvested energy / time after the warm-up"),
    "harvested_energy": (_T, "harvested energy after the warm-up"),
    "stored_energy_change": (_T, "change of the stored energy theta'^2/2 + cos(theta) after "
                                 "the warm-up"),
    "stored_energy": (_T, "stored energy theta'^2/2 + cos(theta)"),
    "averaged_time": (_TIME, "time the powers are averaged over"),
    "seconds": ("s", "wall-clock time of the run"),
    "speed_peak": ("rad " + _RATE, "largest |theta'| after the hand-over"),
    "speed_limit": ("rad " + _RATE, "rated-speed penalty of the plans"),
}


#: A field's unit from its name's suffix (longest first).
SUFFIX_UNITS = (("_w_per_nm2", "W/(N m)^2"), ("_w_per_m", "W/m"), ("_mwh_per_year", "MWh/yr"),
                ("_nm_s_per_rad", "N m s/rad"), ("_m_per_s2", "m/s^2"), ("_rad_per_s", "rad/s"),
                ("_m_per_s", "m/s"), ("_kg_m2", "kg m2"), ("_per_year", "1/yr"),
                ("_kwh", "kWh"), ("_mwh", "MWh"), ("_deg", "degree"), ("_hz", "Hz"),
                ("_nm", "N m"), ("_w", "W"), ("_j", "J"), ("_m", "m"), ("_s", "s"),
                ("_kg", "kg"), ("_n", "N"), ("_h", "h"))


def quantity(name: str) -> tuple[str, str]:
    """``(units, long_name)`` of a result field or Dataset variable named ``name``.

    Names in ``QUANTITIES`` first; then a unit suffix (``SUFFIX_UNITS``:
    ``power_w`` is "W", its long name "power"); anything else is a count or ratio ("1")."""
    if name in QUANTITIES:
        return QUANTITIES[name]
    if name.startswith(("update_time", "forecast_time", "solve_time")):
        return "s", name.replace("_", " ") + " (wall clock)"
    for suffix, unit in SUFFIX_UNITS:
        if name.endswith(suffix) and len(name) > len(suffix):
            base = name[: -len(suffix)]
            return unit, QUANTITIES.get(base, ("", base.replace("_", " ")))[1]
    return "1", name.replace("_", " ")


def annotate(ds, command: str):
    """``ds`` with ``units`` and ``long_name`` on every variable and coordinate (kept where
    already set), and the command and parapend's version in its attributes."""
    from . import __version__

    for name in list(ds.variables):
        attrs = ds[name].attrs
        units, long_name = quantity(str(name))
        attrs.setdefault("units", units)
        attrs.setdefault("long_name", long_name)
    ds.attrs["command"] = command
    ds.attrs["parapend_version"] = __version__
    return ds


def _attr_value(v):
    """A JSON value as a NetCDF attribute: numbers, strings and flat lists of numbers as they
    are, the rest as JSON text (NetCDF has no nested attributes)."""
    import json

    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if isinstance(v, (int, float, str, np.integer, np.floating)):
        return v
    if isinstance(v, (list, tuple, np.ndarray)):  # a flat list of numbers: a NetCDF array
        a = np.asarray(v) if not isinstance(v, np.ndarray) else v
        if a.ndim == 1 and a.size and a.dtype.kind in "biuf":
            return a.astype(np.int64 if a.dtype.kind in "biu" else float)
    return json.dumps(to_jsonable(v))


def scalars_dataset(data: dict, series=None):
    """The Dataset of a result: every numeric scalar of ``data`` (its JSON object) a 0-d
    variable, every other field an attribute (nested values as JSON text), plus ``series``
    (an ``xarray.Dataset`` of the result's curves, or None)."""
    import xarray as xr

    ds = xr.Dataset() if series is None else series.copy()
    for k, v in data.items():
        if k in ds.variables:
            continue
        if isinstance(v, (bool, int, float)):
            dtype = bool if isinstance(v, bool) else np.int64 if isinstance(v, int) else float
            ds[k] = ((), np.asarray(v, dtype=dtype))
        elif v is not None:
            ds.attrs[k] = _attr_value(v)
    return ds


def grid_csv(ds, names) -> str:
    """CSV text of the variables ``names`` of a Dataset over the same dimensions, one row per
    grid point (long format): the dimensions' coordinates first, then the variables; a row
    of names, a row of units, then the values (``repr(float)``)."""
    import csv
    import io

    dims = ds[names[0]].dims
    cols = [str(d) for d in dims] + [str(n) for n in names]
    grids = np.meshgrid(*[np.asarray(ds[d].values, dtype=float) for d in dims],
                        indexing="ij")
    vals = [g.ravel() for g in grids] + [np.asarray(ds[n].transpose(*dims).values).ravel()
                                         for n in names]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    w.writerow([ds[c].attrs.get("units", quantity(c)[0]) for c in cols])
    for row in zip(*vals):  # integers (labels, counts) as integers
        w.writerow([str(int(v)) if isinstance(v, np.integer) else repr(float(v)) for v in row])
    return buf.getvalue()


def dataset_csv(ds) -> str:
    """CSV text of a Dataset's table: the variables along its one dimension as columns (the
    dimension's coordinate first), a header row of names, then a row of units, then the
    values (``repr(float)``: they read back exactly). A Dataset without dimensions gives its
    scalar variables as one row.

    Raises
    ------
    ParameterError
        The Dataset has more than one dimension (a CSV holds one table: save as .nc).
    """
    import csv
    import io

    from .errors import ParameterError

    dims = list(ds.dims)
    if len(dims) > 1:
        raise ParameterError(f"path: a CSV file holds one table, and this result has the "
                             f"dimensions {', '.join(map(str, dims))}; save it as .nc")
    if dims:
        dim = dims[0]
        names = ([dim] if dim in ds.coords else []) + [
            str(k) for k, v in ds.data_vars.items() if v.dims == (dim,)
            and v.dtype.kind in "biuf"]
    else:
        names = [str(k) for k, v in ds.data_vars.items() if v.dtype.kind in "biuf"]
    if not names:
        raise ParameterError("path: this result holds no numbers for a CSV table; save it as "
                             ".json or .nc")
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(names)
    w.writerow([ds[n].attrs.get("units", quantity(n)[0]) for n in names])
    cols = [np.atleast_1d(np.asarray(ds[n].values, dtype=float)) for n in names]
    for row in zip(*cols):
        w.writerow([repr(float(v)) for v in row])
    return buf.getvalue()


#: How a non-dimensional series converts to SI: name -> (SI name, Units attribute, power of
#: it to multiply by).
_SI_SERIES = {"time": ("time_s", "time", 1), "t": ("time_s", "time", 1),
              "theta_dot": ("theta_dot_rad_per_s", "time", -1),
              "torque": ("torque_nm", "torque", 1),
              "instantaneous_power": ("instantaneous_power_w", "power", 1),
              "instantaneous_electrical_power": ("instantaneous_electrical_power_w", "power", 1),
              "sample_power": ("sample_power_w", "power", 1),
              "sample_electrical_power": ("sample_electrical_power_w", "power", 1),
              "energy": ("energy_j", "energy", 1)}


def series(columns: dict, units=None, dim: str = "time"):
    """A Dataset of equal-length ``columns`` over the coordinate ``columns[dim]``;
    with ``units`` (:class:`~parapend.units.Units`) every non-dimensional time, speed,
    torque, power and energy in SI under its SI name (``time_s``, ``theta_dot_rad_per_s``,
    ``torque_nm``, ``power_w``, ``energy_j``; angles and ratios as they are)."""
    import xarray as xr

    cols = {}
    for k, v in columns.items():
        v = np.asarray(v, dtype=float)
        if units is not None and k in _SI_SERIES:
            name, scale, power = _SI_SERIES[k]
            cols[name] = v * float(getattr(units, scale)) ** power
            if k == dim:
                dim = name
        else:
            cols[k] = v
    return xr.Dataset({k: (dim, v) for k, v in cols.items() if k != dim},
                      coords={dim: cols[dim]})


#: File suffixes :meth:`Result.save` writes.
SAVE_SUFFIXES = (".json", ".csv", ".nc", ".png", ".svg", ".pdf")


class Result:
    """The one result protocol of every public function (DESIGN.md section 4).

    - ``to_dict()``: the command's ``--json`` object;
    - ``to_dataset()``: an ``xarray.Dataset`` (every variable with ``units`` and
      ``long_name``; the command and version in its attributes), the result's curves over
      their coordinate and its scalars as 0-d variables;
    - ``plot()``: the figure the command line draws (a matplotlib ``Figure``);
    - ``save(path)``: by extension, ``.json`` (``to_dict``), ``.csv`` (the table of
      ``to_dataset``, with a row of units), ``.nc`` (``to_dataset``), ``.png``/``.svg``/
      ``.pdf`` (``plot``);
    - a short repr with the headline numbers.

    Subclasses set :attr:`command` and :attr:`headline` and override ``_series()``
    (the curves, or None) and ``_figure()``.
    """

    #: the command whose result this is
    command = ""
    #: the fields the repr shows
    headline: tuple = ("success", "status")

    def to_dict(self) -> dict:
        return {f.name: to_jsonable(getattr(self, f.name)) for f in fields(self)
                if not f.name.startswith("_")}

    def _series(self):
        """The result's curves as a Dataset (None: scalars only)."""
        return None

    def to_dataset(self):
        """The result as an ``xarray.Dataset``: its curves (``_series()``) and its scalar
        fields as 0-d variables, the other fields as attributes; every variable with
        ``units`` and ``long_name``."""
        return annotate(scalars_dataset(self.to_dict(), self._series()), self.command)

    def _csv_text(self) -> str:
        """What ``save("x.csv")`` writes: the table of ``to_dataset`` (:func:`dataset_csv`)."""
        return dataset_csv(self.to_dataset())

    def _figure(self):
        from .errors import ParameterError

        raise ParameterError(f"plot: the {self.command} result has no figure")

    def plot(self):
        """The figure of the result, as the command line's ``--plot`` draws it (a matplotlib
        ``Figure``; save it with :meth:`save` or ``fig.savefig``). The figure is not left
        open in pyplot: a notebook shows it once, as the cell's value (pyplot's inline
        backend also showed every figure still open at the cell's end: twice)."""
        fig = self._figure()
        import sys

        plt = sys.modules.get("matplotlib.pyplot")
        if plt is not None and hasattr(fig, "number"):
            plt.close(fig)
        return fig

    def save(self, path):
        """Write the result to ``path`` by its extension: ``.json``, ``.csv`` (with a units
        row), ``.nc``, or a figure ``.png``/``.svg``/``.pdf``; atomically
        (:mod:`parapend.fileio`). Returns the path."""
        import json
        from pathlib import Path

        from . import fileio
        from .errors import ParameterError

        suffix = Path(str(path)).suffix.lower()
        if suffix == ".json":
            return fileio.write_text(path, json.dumps(self.to_dict(), indent=2) + "\n")
        if suffix == ".csv":
            return fileio.write_text(path, self._csv_text())
        if suffix == ".nc":
            return fileio.write_dataset(self.to_dataset(), path)
        if suffix.lstrip(".") in fileio.FIGURE_FORMATS:
            return fileio.save_figure(self.plot(), path)
        raise ParameterError(f"path: expected a file name ending in "
                             f"{', '.join(SAVE_SUFFIXES)}, got {str(path)!r}")

    def __repr__(self) -> str:
        items = []
        for name in self.headline:
            v = getattr(self, name, None)
            if v is None:
                continue
            items.append(f"{name}={v:.6g}" if isinstance(v, float) else f"{name}={v!r}")
        return f"{type(self).__name__}({', '.join(items)})"


_Result = Result  # the older name, used by the result types across the package


class Table(Result):
    """A result that is a table over one parameter (``damping_sweep``, ``harmonics``,
    ``pto_curve``): the ``xarray.Dataset`` read through (``r["power"]``, ``r.attrs``,
    ``r.sel(...)``), with the result protocol on top (``to_dict`` is the ``--json`` object:
    the coordinate, every variable and every attribute).

    Parameters
    ----------
    command : str
        The command whose result this is.
    dataset : xarray.Dataset
        The table, one dimension.
    draw : callable
        ``draw(dataset)``: the command's figure.
    """

    __slots__ = ("_dataset", "_draw", "command")

    def __init__(self, command: str, dataset, draw):
        object.__setattr__(self, "command", command)
        object.__setattr__(self, "_dataset", dataset)
        object.__setattr__(self, "_draw", draw)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(object.__getattribute__(self, "_dataset"), name)

    def __setattr__(self, name, value):
        raise AttributeError(f"{self.command} result is frozen")

    def __getitem__(self, key):
        return self._dataset[key]

    def __contains__(self, key) -> bool:
        return key in self._dataset

    def __iter__(self):
        return iter(self._dataset)

    def __len__(self) -> int:
        return len(self._dataset)

    def __dir__(self):
        return sorted(set(dir(type(self))) | set(self._dataset.variables)
                      | {"attrs", "coords", "data_vars", "dims", "sel", "isel"})

    def to_dict(self) -> dict:
        ds = self._dataset
        out = {name: ds[name].values for name in ds.coords}
        out.update({name: ds[name].values for name in ds.data_vars})
        return to_jsonable({**out, **ds.attrs})

    def to_dataset(self):
        ds = self._dataset.copy()
        ds.attrs = {k: _attr_value(v) for k, v in ds.attrs.items()}
        return annotate(ds, self.command)

    def _figure(self):
        from .units import Units, si_figure

        units = Units.from_description(self._dataset.attrs)
        return si_figure(self._draw(self._dataset), units)

    def __repr__(self) -> str:
        ds = self._dataset
        dim = next(iter(ds.dims), None)
        head = "" if dim is None else (
            f"{dim}: {ds.sizes[dim]} points from {float(ds[dim].values[0]):.6g} to "
            f"{float(ds[dim].values[-1]):.6g}")
        name = "".join(w.capitalize() for w in self.command.replace("-", "_").split("_"))
        return f"{name}Result({head}; variables {', '.join(map(str, ds.data_vars))})"


@dataclass(frozen=True, eq=False, repr=False)
class OptimizeResult(Result):
    """Optimal period-1 rotation for one excitation and damping.

    Attributes
    ----------
    power : float
        Mean extracted power of the optimum (Eq. 15; positive = harvested).
    uniform_power : float
        Best uniform rotation (Eq. 17, phase optimized), same damping.
    limit_power : float
        gamma -> 0 supremum ``omega*TV(q)/(2 pi)`` (Eqs. 19/24/32 generalized).
    gain_over_uniform : float or None
        ``power/uniform_power - 1``; None when the uniform rotation extracts nothing.
    harmonics, gamma, omega : the problem (gamma: viscous damping, the CLI flag --gamma).
    success, status, message, iterations : convergence. ``success`` means the solver
        converged; status "converged", "no_power" (converged, but the optimum is P <= 0:
        gamma at or above gamma*, or a constant q; ``success`` is True), "stalled",
        "max_iterations", "nonfinite" (Fourier) or the BVP's statuses; iterations of the
        winning Newton run.
    coefficients : dict
        ``{"a0": float, "a": [N], "b": [N]}`` of Eq. 10.
    peak_torque : float
        ``max |T(t)|`` over the period (Eq. 14).
    method : str
        "fourier" (Eq. 10, N harmonics) or "bvp" (Euler-Lagrange BVP, Eqs. 13/22/27); for
        "bvp", ``coefficients`` is the N-harmonic Fourier projection of the BVP motion, and
        ``mesh_nodes``, ``max_residual``, ``residual_floor`` (> 0 where elements passed at
        the residual's rounding floor, not at tol: boundary layers at gamma below about
        1e-15), ``continuation_steps`` describe the solve.
    search, candidate_patterns, patterns_tried, polished, abandoned : the evidence of the
        global search (docs/global.md): ``search`` is "exhaustive" (every half-turn
        direction pattern of the limit motion, ``candidate_patterns`` of them, was a seed;
        ``C(2m, m - 1)`` for ``extrema_per_period = 2m``, a float past 2^53, inf past 1e308),
        "dynamic-programme" (too many to list: seeds from the (t, theta) dynamic programme),
        or "bvp-starts"; runs carried to convergence and runs abandoned as unable to win.
    second_power, second_distance : float or None
        The best other distinct local maximum among the runs polished to convergence, and
        the RMS distance of its motion from the optimum's over one period (rad; distinct:
        above 1e-6). Runs abandoned as unable to win are never polished, so a better other
        maximum may exist: ``second_power`` is a lower bound of the second-best maximum.
        None: every polished run reached the optimum. (BVP: the best other start's power,
        distinct by more than 1e-9 relative; no distance.)
    upper_bound, bound_gap : ``limit_power - gamma omega^2`` (no rotation does better, as
        ``<theta'^2> >= omega^2``) and its distance to ``power``.
    torque_limit, efficiency_generating, efficiency_motoring : float or None
        The power take-off (:func:`parapend.pto.optimize_pto`): ``|T| <= torque_limit``
        (m g l), electrical power ``eta_g p`` generating, ``p / eta_m`` motoring; None when
        not set.
    electrical_power : float or None
        Mean electrical power of the motion, unsmoothed efficiency model.
    mechanical_power, mechanical_power_w : float or None
        Through a lossy take-off (an efficiency or a copper loss: ``parapend.optimize``),
        ``power`` and ``power_w`` are the electrical power, the headline, and these the
        mechanical ``P = -<T theta'>`` of the optimum (its ``upper_bound``, ``bound_gap``,
        ``gain_over_uniform`` and ``energy_per_cycle_j`` are mechanical); None otherwise,
        where ``power`` is the mechanical power.
    unconstrained_power : float or None
        The ideal (lossless, unlimited) optimum the PTO solve started from.
    peak_power, motoring_energy, harvested_energy : float or None
        ``max p`` of ``p = -T theta'``, and ``int max(-p, 0) dt``, ``int max(p, 0) dt`` over
        one forcing period (m g l): the energy the machine puts back into, and takes from,
        the pendulum each cycle.
    max_violation : float or None
        ``max(peak_torque / torque_limit - 1, 0)`` on the dense evaluation.
    intervals, refinement_change : int or None, float or None
        The torque-limited optimum is solved in the time domain (``method`` "hermite",
        :mod:`parapend.optimal.hermite`) on ``intervals`` cubic Hermite intervals, the
        efficiency and copper-loss optima (``method`` "collocation",
        :mod:`parapend.optimal.collocation`) on ``intervals`` Hermite-Simpson intervals; both
        checked by one doubling: ``refinement_change`` is the change of the (electrical)
        power between the last two.
    peak_torque_converged : bool or None
        Whether ``peak_torque`` moved by less than 1 % between the last two meshes of a
        time-domain PTO solve. The Fourier optimum at gamma = 0: False (its peak grows like
        N^2 towards the limit's instant flips: 164, 587, 2215 at N = 12, 24, 48); at
        gamma > 0 and for the BVP: None (not checked).
        False where the optimal torque is impulsive (its peak grows with the mesh, as the
        efficiency optimum at gamma = 0: 16, 32, 65, 129 on 128 to 1024 intervals) or
        singular (many torques give the same power): ``peak_torque``, ``peak_torque_nm``
        and ``peak_power`` are then properties of the mesh, not of the motion.
    peak_torque_coarse : float or None
        The peak torque on half the intervals (the last refinement).
    torque_impulse, torque_impulse_change : float or None
        Collocation: ``int |T| dt`` over the arc around the peak where ``T`` keeps its sign
        (the braking impulse, m g l times the time unit), and its change from half the
        intervals; it converges where the peak does not.
    units, power_w, uniform_power_w, limit_power_w, peak_torque_nm, electrical_power_w,
    energy_per_cycle_j, motoring_energy_j : physical values (W, N m, J) when a pendulum's
        length and mass were given (:mod:`parapend.units`); None otherwise.
    uniform_pto_feasible, uniform_pto_power, uniform_pto_electrical_power,
    uniform_pto_peak_torque, uniform_pto_phase : the best uniform rotation through the same
        power take-off (:func:`parapend.pto.uniform_under_pto`): its phase maximizes the
        electrical power among the phases whose peak torque meets the limit; all None
        (``uniform_pto_feasible`` False) when no phase does, None without a take-off.
    gain_over_uniform_pto : float or None
        Like for like: ``electrical_power / uniform_pto_electrical_power - 1`` (the
        mechanical powers when there is no efficiency or copper loss).
    uniform_pto_power_w, uniform_pto_electrical_power_w : float or None
        The same in watts, with physical units.
    omega_rad_per_s, damping_coefficient : float or None
        With physical units, the forcing's angular frequency in rad/s (``omega`` is in units
        of ``sqrt(g/l)``) and the damping as a coefficient in N m s/rad (``gamma I / t0``).
    winding : int
        K, turns per forcing period, ``theta(t + 2 pi/omega) = theta(t) + 2 pi K`` (1: the
        paper's period-1 rotation); ``uniform_power`` is then the uniform rotation with K
        turns and ``upper_bound`` is ``limit - gamma K^2 omega^2``.
    """

    power: float
    uniform_power: float
    limit_power: float
    gain_over_uniform: float | None
    harmonics: int
    gamma: float
    omega: float
    success: bool
    status: str
    message: str
    iterations: int
    coefficients: dict
    peak_torque: float
    method: str = "fourier"
    found_by: str = ""
    local_maxima: list = field(default_factory=list)
    gradient_norm: float = float("nan")
    strict_maximum: bool = False
    quadrature_points: int = 0
    mean_square_speed: float = float("nan")
    search: str = ""
    candidate_patterns: int | float = 1
    extrema_per_period: int = 2
    patterns_tried: int = 0
    polished: int = 0
    abandoned: int = 0
    second_power: float | None = None
    second_distance: float | None = None
    upper_bound: float = float("nan")
    bound_gap: float = float("nan")
    mesh_nodes: int | None = None
    max_residual: float | None = None
    residual_floor: float | None = None
    continuation_steps: int | None = None
    excitation: dict = field(default_factory=dict)
    torque_limit: float | None = None
    efficiency_generating: float | None = None
    efficiency_motoring: float | None = None
    electrical_power: float | None = None
    mechanical_power: float | None = None
    unconstrained_power: float | None = None
    peak_power: float | None = None
    motoring_energy: float | None = None
    harvested_energy: float | None = None
    max_violation: float | None = None
    intervals: int | None = None
    refinement_change: float | None = None
    peak_torque_converged: bool | None = None
    peak_torque_coarse: float | None = None
    torque_impulse: float | None = None
    torque_impulse_change: float | None = None
    units: dict | None = None
    power_w: float | None = None
    uniform_power_w: float | None = None
    limit_power_w: float | None = None
    peak_torque_nm: float | None = None
    electrical_power_w: float | None = None
    mechanical_power_w: float | None = None
    energy_per_cycle_j: float | None = None
    motoring_energy_j: float | None = None
    uniform_pto_feasible: bool | None = None
    uniform_pto_power: float | None = None
    uniform_pto_electrical_power: float | None = None
    uniform_pto_peak_torque: float | None = None
    uniform_pto_phase: float | None = None
    gain_over_uniform_pto: float | None = None
    uniform_pto_power_w: float | None = None
    uniform_pto_electrical_power_w: float | None = None
    omega_rad_per_s: float | None = None
    damping_coefficient: float | None = None
    winding: int = 1
    convention: str = CONVENTION
    _motion: object = field(default=None, repr=False)
    _excitation: object = field(default=None, repr=False)
    _draw: object = field(default=None, repr=False)

    command = "optimize"
    headline = ("power", "power_w", "electrical_power", "electrical_power_w", "peak_torque",
                "peak_torque_nm", "status")

    @property
    def motion(self):
        """The optimal motion: a :class:`~parapend.trajectory.FourierMotion`, or a
        :class:`~parapend.optimal.hermite.HermiteMotion` for ``method`` "hermite", a
        :class:`~parapend.optimal.collocation.CollocationMotion` for "collocation"."""
        return self._motion

    @property
    def excitation_function(self):
        """The excitation ``q(t)`` the optimum was solved for (an
        :class:`~parapend.excitation.Excitation`; ``excitation`` is its description)."""
        return self._excitation

    @property
    def physical_units(self):
        """The pendulum's :class:`~parapend.units.Units` (None without length and mass)."""
        from .units import Units

        return Units.from_description(self.units)

    def samples(self, points: int = 1000) -> dict:
        """One forcing period of the optimum on ``points`` uniform times (non-dimensional
        arrays): ``time``, ``phase`` (``t/T``), ``theta``, ``theta_dot``, ``torque``
        (Eq. 14 solved for T), ``instantaneous_power`` (``-T theta'``, positive when
        harvested; its mean is ``power``) and, with an efficiency,
        ``instantaneous_electrical_power``. ``to_dataset()`` gives them in SI when the
        pendulum was given in SI."""
        from .errors import check_int
        from .model import torque

        npts = check_int("points", points, 2, 10**6)
        exc, motion = self._excitation, self._motion
        t = exc.period * np.arange(npts) / npts
        out = {"time": t, "phase": t / exc.period, "theta": motion.theta(t),
               "theta_dot": motion.theta_dot(t), "torque": torque(motion, exc, self.gamma, t)}
        out["instantaneous_power"] = -out["torque"] * out["theta_dot"]
        if self.efficiency_generating is not None:
            p = out["instantaneous_power"]
            out["instantaneous_electrical_power"] = np.where(
                p > 0, p * self.efficiency_generating, p / self.efficiency_motoring)
        return out

    def _series(self):
        return series(self.samples(), self.physical_units)

    def _figure(self):
        """The figure of the command (:func:`parapend.plotting.plot_optimum`, or
        :func:`parapend.pto.plot_pto_profile` through a take-off), SI axes beside with
        units; ``_draw`` is set by :func:`parapend.optimize`, which knows the figure."""
        from .units import si_figure

        if self._draw is None:
            return super()._figure()
        return si_figure(self._draw(self), self.physical_units)


@dataclass(frozen=True, eq=False, repr=False)
class ThresholdResult(Result):
    """Damping ``gamma*`` beyond which no period-1 rotation extracts power.

    ``power_at_threshold`` is the optimal power at ``damping_threshold`` (zero to the
    solver's tolerance); ``uniform_threshold`` is ``|Q1|/(2 omega)``, where the best uniform
    rotation stops extracting. ``harmonics`` is the final N; ``refinement_change`` is
    ``|gamma*(N) - gamma*(N/2)|``, the check by one refinement (NaN when N was given).
    With a pendulum's length and mass (:mod:`parapend.units`), ``units`` describes them and
    ``damping_threshold_coefficient`` and ``uniform_threshold_coefficient`` are the two
    thresholds as viscous damping coefficients ``c = gamma I / t0`` in N m s/rad.
    """

    damping_threshold: float
    uniform_threshold: float
    power_at_threshold: float
    harmonics: int
    omega: float
    success: bool
    status: str
    message: str
    iterations: int
    mean_square_speed: float = float("nan")
    refinement_change: float = float("nan")
    excitation: dict = field(default_factory=dict)
    units: dict | None = None
    damping_threshold_coefficient: float | None = None
    uniform_threshold_coefficient: float | None = None
    convention: str = CONVENTION
    _excitation: object = field(default=None, repr=False)
    _draw: object = field(default=None, repr=False)

    command = "threshold"
    headline = ("damping_threshold", "damping_threshold_coefficient", "uniform_threshold",
                "status")

    def _figure(self):
        """Power against damping up to beyond gamma* (the threshold marked), as
        ``damping-sweep`` draws it for this excitation (``_draw``, set by
        :func:`parapend.threshold`)."""
        if self._draw is None:
            return super()._figure()
        return self._draw(self)

    @property
    def excitation_function(self):
        """The excitation ``q(t)`` (an :class:`~parapend.excitation.Excitation`)."""
        return self._excitation

    @property
    def physical_units(self):
        """The pendulum's :class:`~parapend.units.Units` (None without length and mass)."""
        from .units import Units

        return Units.from_description(self.units)


class Record(Result):
    """A frozen result whose fields are the keys of a command's JSON object (for the
    commands whose result is not a dataclass: ``figure``, ``reproduce``, ``simulate``,
    ``basins``, ``rotations``, ``sweep``, ``map``, ``power-matrix``, ``optimize`` with
    ``method="all"``). Fields read as attributes or with ``record["key"]``; ``to_dict``
    gives the JSON object.

    The objects behind the fields are public attributes too, named in ``objects``: the
    Dataset (``dataset``; ``to_dataset()`` annotates it), the motion a field describes
    (``source``, whose attributes also read through), a sweep's ``run``, ... The figure is
    ``plot()``.

    Parameters
    ----------
    kind : str
        The command.
    data : dict
        The JSON object.
    draw : callable or None
        ``draw(record)``: the command's figure (a matplotlib ``Figure``).
    series : callable or None
        ``series(record)``: the curves of the result as a Dataset (default: ``dataset``).
    table : callable or None
        ``table(record)``: the CSV text ``save("x.csv")`` writes, for a result of more than
        one dimension (a grid, a matrix; default: the table of ``to_dataset``).
    **objects
        The objects behind the fields, by public name.
    """

    __slots__ = ("_kind", "_data", "_objects", "_draw", "_series_of", "_table_of")

    def __init__(self, kind: str, data: dict, *, draw=None, series=None, table=None,
                 **objects):
        object.__setattr__(self, "_kind", kind)
        object.__setattr__(self, "_data", dict(data))
        object.__setattr__(self, "_objects", objects)
        object.__setattr__(self, "_draw", draw)
        object.__setattr__(self, "_series_of", series)
        object.__setattr__(self, "_table_of", table)

    @property
    def command(self) -> str:
        return self._kind

    def __getattr__(self, name):
        data = object.__getattribute__(self, "_data")
        if name in data:
            return data[name]
        objects = object.__getattribute__(self, "_objects")
        if name in objects:
            return objects[name]
        if name.startswith("_") and name[1:] in objects:  # the older, private spelling
            return objects[name[1:]]
        if "source" in objects and not name.startswith("_"):
            return getattr(objects["source"], name)
        raise AttributeError(f"{object.__getattribute__(self, '_kind')} result has no field "
                             f"{name!r}")

    def __getitem__(self, key):
        return self._data[key]

    def __setattr__(self, name, value):
        raise AttributeError(f"{self._kind} result is frozen")

    def __dir__(self):
        return sorted(set(self._data) | set(self._objects)
                      | {"to_dict", "to_dataset", "plot", "save", "fields"})

    def __repr__(self) -> str:
        items = []
        for k, v in self._data.items():
            if isinstance(v, (bool, int, float, str)) and len(items) < 6 \
                    and not (isinstance(v, str) and len(v) > 40):
                items.append(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v!r}")
        name = "".join(w.capitalize() for w in self._kind.replace("-", "_").split("_"))
        return f"{name}Result({', '.join(items)})"

    def fields(self) -> tuple:
        """The field names, which are the JSON keys."""
        return tuple(self._data)

    def _series(self):
        if self._series_of is not None:
            return self._series_of(self)
        return self._objects.get("dataset")

    def to_dataset(self):
        """The result as an annotated ``xarray.Dataset``: the Dataset behind the record
        (``basins``, ``rotations``, ``sweep``, ``map``, ``power-matrix``: what ``--save``
        writes) or its curves, plus the scalar fields (0-d) and the others as attributes."""
        series = self._series()
        if series is not None and series.attrs:
            data = {k: v for k, v in self.to_dict().items() if k not in series.attrs}
            series = series.copy()
            series.attrs = {k: _attr_value(v) for k, v in series.attrs.items()}
        else:
            data = self.to_dict()
        return annotate(scalars_dataset(data, series), self._kind)

    def _figure(self):
        if self._draw is None:
            return super()._figure()
        return self._draw(self)

    def _csv_text(self) -> str:
        if self._table_of is None:
            return super()._csv_text()
        return self._table_of(self)

    def to_dict(self) -> dict:
        return to_jsonable(self._data)
