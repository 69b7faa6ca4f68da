"""The inputs of the floating body, each parameter declared once: a sea, a pendulum, a body,
a power take-off and a controller (small frozen objects; :mod:`parapend.hydro.device`
composes them into a device and asks the commands), their declarations (unit, default,
bounds, help: :func:`declarations`), the run options (``RUN_OPTIONS``), and
:func:`expand_inputs`, which turns the objects given to a command (``parapend.buoy``,
``horizon``, ``power_matrix``) into its keywords. It imports nothing of the commands, so
that every command can read it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from ..defaults import BUOY, BUOY_HORIZON, HORIZON, HULL, SEA
from ..limits import HULL_PITCH_INERTIA_RANGE, SEA_WAVES_RANGE

__all__ = ["Body", "Controller", "DeviceInputs", "INPUT_KEYWORDS", "Pendulum", "PowerTakeOff",
           "RUN_OPTIONS", "Sea", "check", "declaration", "declarations", "default_of",
           "expand_inputs",
           "has_inputs", "option_help"]


def _param(unit: str, help: str, *, default=None, bounds=None, default_text=None,
           kind: str = "float", choices=None, metavar=None, commands=None, value=None):
    """A parameter's declaration: a field whose metadata hold its unit, bounds (the range the
    command accepts, or None where it depends on other parameters), help, how the command
    line reads it (``kind``: float, int, text; ``choices``, ``metavar``) and the default it
    states (``default_text``; ``default`` None means the command's default). ``commands``:
    what another command (``horizon``, ``power-matrix``) states instead, its own ``help``
    or ``default`` (a documented per-command default: the prescribed-heave pendulum's, or
    the horizon curve's shorter records). ``value``: the command's default itself where it
    is one value (or one per controller, a dict), which the command reads
    (:func:`default_of`) and the help states (``default_text`` then defaults to it)."""
    if default_text is None and value is not None and not isinstance(value, dict):
        default_text = value if isinstance(value, str) else f"{value:g}"
    return field(default=default, metadata={
        "unit": unit, "help": help, "bounds": bounds, "kind": kind, "choices": choices,
        "metavar": metavar, "default": default_text or repr(default),
        "commands": commands or {}, "value": value})


#: the receding-horizon controllers' default horizons, peak periods (the plan controller's
#: measured horizon, docs/buoy.md)
_MPC_HORIZON = {"mpc": 2.0, "one-way-mpc": 1.0}


def _both(name: str, note: str = "") -> str:
    """The default stated for the embedded buoy and the embedded hull
    (``parapend.defaults.BUOY``, ``HULL``)."""
    return f"{BUOY[name]:g}{note}; a hull's {HULL[name]:g}"


def _device(name: str) -> dict:
    """The default ``horizon`` and ``power-matrix`` state: the prescribed-heave pendulum's
    (``parapend.defaults.SEA``), and the buoy's with ``--device buoy``."""
    said = {"default": f"{SEA[name]:g}; {BUOY[name]:g} with --device buoy"}
    return {"horizon": said, "power-matrix": said}


def option_help(meta, command: str | None = None) -> str:
    """The command line's help of a declared parameter: its help, its unit and its default
    (those ``command`` states instead, where its declaration says so)."""
    own = meta.get("commands", {}).get(command, {})
    unit = "" if meta["unit"] == "-" else f", {meta['unit']}"
    stated = own.get("default", meta["default"])
    default = "" if stated == "None" else f" (default {stated})"
    return f"{own.get('help', meta['help'])}{unit}{default}"


class _Inputs:
    """What every input object shares: its keywords for the command's function."""

    def options(self) -> dict:
        """The keywords of :func:`parapend.buoy` this object sets (None fields left out, so
        the command's defaults apply)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if getattr(self, f.name) is not None}


@dataclass(frozen=True)
class Sea(_Inputs):
    """The sea: a regular wave (``regular``), a spectrum's sea state (``state``) or a
    measured record (``measured``), each taken as a periodic record."""

    wave_height: float | None = _param("m", "H, crest to trough", bounds=(1e-4, 30.0),
                                       default_text=_both("wave_height"))
    wave_period: float | str | None = _param(
        "s", "the period; FROM:TO:N or a comma list T1,T2,... for power against period",
        bounds=(0.1, 100.0), default_text=_both("wave_period"), kind="text", metavar="T")
    hs: float | None = _param("m", "significant wave height",
                              default_text=_both("hs", " with --tp"), commands=_device("hs"))
    tp: float | None = _param("s", "peak period", default_text=_both("tp", " with --hs"),
                              commands=_device("tp"))
    spectrum: str | None = _param("-", "spectrum shape", value="jonswap",
                                  kind="text", choices=("jonswap", "pierson-moskowitz"))
    gamma_peak: float | None = _param("-", "JONSWAP peak enhancement in [1, 20]",
                                      bounds=(1.0, 20.0), value=3.3)
    repeat_period: float | None = _param(
        "s", "T_r: the record repeats with it",
        default_text=f"100 Tp; a hull's {HULL['repeat_periods']:g} Tp",
        commands={"horizon": {  # the curve runs many controllers: records that fit 2 min
            "help": f"T_r: the length of each record ({SEA_WAVES_RANGE[0]:g} to "
                    f"{SEA_WAVES_RANGE[1]:g} peak periods)",
            "default": f"{HORIZON['repeat_periods']:g} Tp; "
                       f"{BUOY_HORIZON['repeat_periods']:g} Tp with --device buoy"}})
    seed: int | None = _param("-", "seed of the random phases", default_text="0", kind="int",
                              commands={
                                  "horizon": {"help": "seed of the first record's phases; "
                                                      "record r has seed + r"},
                                  "power-matrix": {"help": "seed of realization 0; "
                                                           "realization r has seed + r"}})
    cutoff: float | None = _param("-", "highest frequency, in units of the peak frequency",
                                  value=3.0)
    record: str | None = _param("s, m", "measured surface elevation at the body, CSV 't,z'",
                                kind="text", metavar="CSV")
    taper: float | None = _param("-", "with --record: fraction under the Tukey taper",
                                 bounds=(0.0, 0.5), value=0.1)
    wave_direction: float | None = _param(
        "rad", "with --hydro: the dataset's wave direction to use",
        bounds=(0.0, 6.283185307179586), default_text="0, the waves travelling along +x",
        metavar="RAD")

    @classmethod
    def regular(cls, height=None, period=None) -> Sea:
        """A regular wave of ``height`` (m) and ``period`` (s)."""
        return cls(wave_height=height, wave_period=period)

    @classmethod
    def state(cls, hs=None, tp=None, **kw) -> Sea:
        """A spectrum's sea state (``spectrum``, ``gamma_peak``, ``repeat_period``, ``seed``,
        ``cutoff`` as keywords)."""
        return cls(hs=hs, tp=tp, **kw)

    @classmethod
    def measured(cls, record, taper=None, cutoff=None) -> Sea:
        """A measured record (CSV ``t,z``, s and m), made periodic."""
        return cls(record=record, taper=taper, cutoff=cutoff)


@dataclass(frozen=True)
class Pendulum(_Inputs):
    """The pendulum on its pivot (SI)."""

    mass: float | None = _param("kg", "m", bounds=(0.0, None), default_text=_both("mass"),
                                commands=_device("mass"))
    length: float | None = _param("m", "pivot to centre of mass l", bounds=(0.0, None),
                                  default_text=_both("length"), commands=_device("length"))
    inertia: float | None = _param("kg m^2", "about the pivot, at least m l^2",
                                   default_text="m l^2")
    damping_coefficient: float | None = _param(
        "N m s/rad", "viscous c", bounds=(0.0, None),
        default_text=_both("damping_coefficient"), commands=dict.fromkeys(
            ("horizon", "power-matrix"),
            {"help": "viscous c (instead of --gamma)",
             "default": f"--gamma; {BUOY['damping_coefficient']:g} with --device buoy"}))


@dataclass(frozen=True)
class Body(_Inputs):
    """The floating body: a built-in shape (``body``: cylinder, sphere, barge), a mesh file or
    a Capytaine dataset; its degrees of freedom; the pivot's placement in it."""

    body: str | None = _param("-", "cylinder, sphere or barge (a hull)",
                              default_text="cylinder; a hull's barge", kind="text")
    radius: float | None = _param("m", "the cylinder's or the sphere's radius",
                                  default_text=_both("radius"))
    draft: float | None = _param("m", "the cylinder's draft (a hull sphere's: r / 2)",
                                 default_text=_both("draft"))
    mesh: str | None = _param("-", "a mesh file Capytaine reads, instead of --body (z = 0 "
                                   "the free surface)", kind="text", metavar="FILE")
    hydro: object = _param("-", "a Capytaine dataset (NetCDF path or xarray.Dataset)",
                           kind="text", metavar="FILE")
    dofs: str | None = _param(
        "-", "the body's degrees of freedom: heave (the heaving buoy) or surge,heave,pitch (a "
             "hull that pitches; the pendulum rotates or swings)", default_text="heave",
        kind="text", metavar="DOFS")
    pivot_height: float | None = _param(
        "m", "the pivot above the rotation centre O: a built-in body's waterplane centre, a "
             "mesh's origin, a dataset's rotation centre",
        default_text=f"{HULL['pivot_height']:g}")
    pivot_offset: float | None = _param("m", "the pivot ahead of O, along the waves' travel",
                                        default_text=f"{HULL['pivot_offset']:g}")
    hull_pitch_inertia: float | None = _param(
        "kg m^2", "the hull's pitch inertia about O, without the pendulum",
        bounds=HULL_PITCH_INERTIA_RANGE,
        default_text="the dataset's, else a homogeneous immersed hull's")
    barge_length: float | None = _param("m", "the box barge's length",
                                        default_text=f"{HULL['barge_length']:g}")
    barge_beam: float | None = _param("m", "the box barge's beam",
                                      default_text=f"{HULL['barge_beam']:g}")
    barge_draft: float | None = _param("m", "the box barge's draft",
                                       default_text=f"{HULL['barge_draft']:g}")

    @classmethod
    def barge(cls, length=None, beam=None, draft=None, **kw) -> Body:
        """The box barge in surge, heave and pitch (the embedded hull design by default;
        ``pivot_height``, ``pivot_offset``, ``hull_pitch_inertia`` as keywords)."""
        return cls(body="barge", dofs=kw.pop("dofs", "surge,heave,pitch"), barge_length=length,
                   barge_beam=beam, barge_draft=draft, **kw)

    @classmethod
    def cylinder(cls, radius=None, draft=None, dofs=None, **kw) -> Body:
        """A vertical cylinder (the embedded buoy design by default)."""
        return cls(body="cylinder", radius=radius, draft=draft, dofs=dofs, **kw)

    def with_dofs(self, dofs) -> Body:
        """The same body with other degrees of freedom (``"heave"``: the heaving buoy's model
        of it; the pivot's placement is then unused)."""
        heave = dofs == "heave"
        return dataclasses.replace(self, dofs=dofs, **({k: None for k in (
            "pivot_height", "pivot_offset", "hull_pitch_inertia")} if heave else {}))


@dataclass(frozen=True)
class PowerTakeOff(_Inputs):
    """The power take-off: all None is the ideal, lossless one."""

    torque_limit: float | None = _param("N m", "largest |torque|", bounds=(0.0, None))
    efficiency: float | str | tuple | None = _param(
        "-", "power take-off efficiency in (0, 1], generating[,motoring]: the motion "
             "maximizes the electrical power", bounds=(0.01, 1.0), kind="text",
        metavar="ETA_G[,ETA_M]")
    copper_loss: float | None = _param(
        "W/(N m)^2", "the generator's winding loss r tau^2 subtracted from the power (with "
                     "--dofs surge,heave,pitch)", bounds=(0.0, 1e6))


@dataclass(frozen=True)
class Controller(_Inputs):
    """How the torque is decided: the non-causal optimum (``controller`` None or
    ``"optimum"``) or a receding-horizon controller (``"mpc"``, ``"one-way-mpc"``) with its
    horizon and update interval (peak periods) and forecast."""

    controller: str | None = _param(
        "-", "optimum: the non-causal coupled optimum; mpc: receding-horizon control planned "
             "on the coupled model with its radiation (the motion planner; with --efficiency "
             "the torque planner); one-way-mpc: planned on the free buoy's heave",
        default_text="optimum", kind="text", choices=("optimum", "mpc", "one-way-mpc"))
    horizon: float | None = _param(
        "peak periods", "with mpc: forecast horizon", value=_MPC_HORIZON,
        default_text=f"{_MPC_HORIZON['mpc']:g}; one-way-mpc {_MPC_HORIZON['one-way-mpc']:g}")
    update_interval: float | None = _param(
        "peak periods", "with mpc: re-planning interval", value=0.125,
        commands={"horizon": {  # the prescribed-heave pendulum's curve re-plans more often
            "help": "receding-horizon update interval",
            "default": f"{HORIZON['update_interval']:g}; "
                       f"{BUOY_HORIZON['update_interval']:g} with --device buoy"}})
    forecast: str | None = _param(
        "-", "with mpc: what the controller knows of the excitation force over the horizon: "
             "perfect (the record's own future) or ar (autoregressive, fitted on the force "
             "measured so far)", value="perfect", kind="text",
        choices=("perfect", "ar"))

    @classmethod
    def receding_horizon(cls, horizon=None, *, forecast=None, update_interval=None,
                         model="mpc") -> Controller:
        """A causal receding-horizon controller planned on the coupled model (``"mpc"``) or
        on the free buoy's heave (``"one-way-mpc"``)."""
        return cls(controller=model, horizon=horizon, forecast=forecast,
                   update_interval=update_interval)


#: options of ``buoy``, ``horizon`` and ``power-matrix`` that belong to the run, not to the
#: device or the sea (docs/buoy.md, "Inputs that compose")
RUN_OPTIONS = {
    "winding": "turns of the pendulum per wave or record (resolution of the motion)",
    "harmonics": "the motion's harmonics",
    "optimize_design": "the pendulum's parameters the design search chooses",
    "mass_bounds": "the design search's range", "length_bounds": "the design search's range",
    "inertia_bounds": "the design search's range",
    "damping_coefficient_bounds": "the design search's range",
    "time_limit": "seconds for the long work", "progress": "a progress callback",
    "device": "prescribed-heave or buoy", "horizons": "the horizon curve's horizons",
    "forecasts": "the horizon curve's forecasts", "baselines": "the curve's baselines",
    "records": "seeded records of the curve", "warm_up": "peak periods before measuring",
    "speed_limit": "the prescribed-heave pendulum's speed limit",
    "gravity": "the prescribed-heave pendulum's g", "gamma": "its non-dimensional damping",
    "torque_limit_nm": "the prescribed-heave pendulum's torque limit in N m",
    "te": "energy periods of the bins", "realizations": "records per bin",
    "waves": "waves per record", "response": "the prescribed heave's response",
    "depth": "water depth of the bins' resource", "density": "water density",
    "width": "the device's width for the capture width", "scatter": "a scatter table",
    "timeseries": "a sea-state time series", "rated_power": "the rated power",
    "store": "the Zarr store", "overwrite": "replace the store", "workers": "processes",
    "scheduler": "a Dask scheduler", "netcdf": "an output file", "zarr": "an output file",
    "csv": "an output file", "command": "the command line recorded",
    "plan_samples": "torque samples per interval of the causal plan",
    "planner": "the horizon curve's receding-horizon planner of the buoy: coupled or plan",
}

_OBJECTS = (Sea, Pendulum, Body, PowerTakeOff, Controller)


def declarations() -> dict:
    """Every declared parameter: name -> ``(object, unit, default, bounds, help)``."""
    return {f.name: (cls.__name__, f.metadata["unit"], f.metadata["default"],
                     f.metadata["bounds"], f.metadata["help"])
            for cls in _OBJECTS for f in dataclasses.fields(cls)}


def _meta(name: str):
    return next(f.metadata for cls in _OBJECTS for f in dataclasses.fields(cls)
                if f.name == name)


def default_of(name: str, given, key=None):
    """``given``, or the declared default of the parameter ``name`` where it is None (a 0
    given is kept, and checked); ``key``: which of its defaults (a controller's name; None
    where it has none)."""
    if given is not None:
        return given
    value = _meta(name)["value"]
    return value.get(key) if isinstance(value, dict) else value


def check(name: str, value, *, why: str | None = None, absolute: bool = False) -> float:
    """``value`` of the declared parameter ``name`` as a float in its declared bounds, or the
    one line that names it (:func:`parapend.errors.check_range`; ``why``, the reason said,
    default the declared unit; ``absolute``: the upper bound on ``|value|``). The commands
    check a declared parameter with this, so its bounds stand in one place."""
    from ..errors import check_range

    meta = _meta(name)
    lo, hi = meta["bounds"]
    return check_range(name.replace("_", "-"), value, lo, hi, absolute=absolute,
                       why=meta["unit"] if why is None else why)


def declaration(name: str):
    """The declaration of one parameter (:func:`declarations`), or None."""
    return declarations().get(name)


#: the keyword each input object is given as (``body`` and ``controller`` also take their
#: field's plain value: a shape's name, a controller's name)
INPUT_KEYWORDS = {"sea": "Sea", "pendulum": "Pendulum", "body": "Body", "pto": "PowerTakeOff",
                  "controller": "Controller", "device": "Device"}


def has_inputs(opts: dict) -> bool:
    """Whether the keywords ``opts`` of a command's call hold an input object (or anything
    in ``sea``, ``pendulum``, ``pto``, which only the objects fill)."""
    return any(isinstance(opts.get(k), (_Inputs, DeviceInputs)) for k in INPUT_KEYWORDS) or any(
        opts.get(k) is not None for k in ("sea", "pendulum", "pto"))


def expand_inputs(fn, opts: dict) -> dict:
    """The keywords of ``fn`` (:func:`parapend.buoy`, ``horizon``, ``power_matrix``) with the
    input objects among ``opts`` (``INPUT_KEYWORDS``; a ``Device`` for its body,
    pendulum and take-off) replaced by their fields: the objects' fields are the command's
    parameters, so the command checks them and applies its defaults as it does its
    keywords. A field the command does not take, or given twice (in two objects, or in an
    object and as a keyword), is refused in one line naming it."""
    import inspect

    from ..errors import ParameterError

    params = inspect.signature(fn).parameters
    command = fn.__name__.replace("_curve", "").replace("_", "-")
    out, objects = {k: v for k, v in opts.items() if k in params}, []
    for key, kind in INPUT_KEYWORDS.items():
        value = out.get(key)
        if isinstance(value, DeviceInputs):
            out[key] = params[key].default if key == "device" and key in params else None
            if isinstance(out[key], str):
                out[key] = "buoy"  # horizon's and power-matrix's device: the floating body
            objects += [(key, value.body), (key, value.pendulum), (key, value.pto)]
        elif isinstance(value, _Inputs):
            if type(value).__name__ != kind:
                raise ParameterError(f"{key}: expected a {kind} (parapend.hydro.device), got "
                                     f"a {type(value).__name__}")
            out[key] = params[key].default if key in params else None
            objects.append((key, value))
        elif value is not None and key in ("sea", "pendulum", "pto"):
            raise ParameterError(f"{key}: expected a {kind} (parapend.hydro.device), got "
                                 f"{type(value).__name__}")
    given = {}
    for key, obj in objects:
        for name, value in obj.options().items():
            if name not in params:
                raise ParameterError(f"{name.replace('_', '-')}: not taken by {command} (from "
                                     f"{key}=); drop it")
            default = params[name].default
            if name in given or not (out.get(name) is default or (
                    isinstance(default, (str, int, float)) and out.get(name) == default)):
                raise ParameterError(f"{name.replace('_', '-')}: given twice (in "
                                     f"{given.get(name, 'a keyword')} and {key}=); give it "
                                     "once")
            given[name] = f"{key}="
            out[name] = value
    return out


@dataclass(frozen=True)
class DeviceInputs:
    """A pendulum in a floating body through a power take-off: the three objects together
    (:class:`parapend.hydro.device.Device` adds the questions asked of them)."""

    body: Body = field(default_factory=Body)
    pendulum: Pendulum = field(default_factory=Pendulum)
    pto: PowerTakeOff = field(default_factory=PowerTakeOff)
