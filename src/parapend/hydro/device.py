"""Inputs that compose: a sea, a pendulum, a body, a power take-off and a controller, small
frozen objects built once and handed to every question asked of the floating body.

Each parameter is declared once, as a field of one of these objects with its unit, default,
bounds and help (:func:`declaration`); its name is the keyword of :func:`parapend.buoy` and
the command line's flag (dashes for underscores). A field left None takes the command's
default (the embedded buoy's or hull's design, ``parapend.defaults``), and the command checks
it, so a value is refused in the same one line whichever way it came::

    from parapend.hydro.device import Body, Device, Pendulum, PowerTakeOff, Sea

    sea = Sea.state(hs=1.0, tp=6.0, repeat_period=24.0, seed=0)
    device = Device(Body.barge(), Pendulum(mass=2000.0, length=1.0), PowerTakeOff())
    best = device.optimum(sea)                      # the coupled non-causal optimum
    run = device.with_dofs("heave").causal(sea)     # heave alone: its causal controller
    matrix = device.power_matrix(hs="0.5,1", tp="5,6", realizations=1, waves=4)

The functions below (:func:`optimum`, :func:`causal`, :func:`horizon`,
:func:`power_matrix`) take the objects and call the command's function with their keywords;
:data:`RUN_OPTIONS` names the options of ``buoy``, ``horizon`` and ``power-matrix`` that are
not properties of the device or the sea but of the run (its resolution, its limits, its
outputs).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from ..defaults import BUOY, HULL

__all__ = ["Body", "Controller", "Device", "Pendulum", "PowerTakeOff", "RUN_OPTIONS", "Sea",
           "causal", "declaration", "declarations", "horizon", "option_help", "optimum",
           "power_matrix"]


def _param(unit: str, help: str, *, default=None, bounds=None, default_text=None,
           kind: str = "float", choices=None, metavar=None):
    """A parameter's declaration: a field whose metadata hold its unit, bounds (the range the
    command accepts, or None where it depends on other parameters), help, how the command
    line reads it (``kind``: float, int, text; ``choices``, ``metavar``) and the default it
    states (``default_text``; ``default`` None means the command's default)."""
    return field(default=default, metadata={
        "unit": unit, "help": help, "bounds": bounds, "kind": kind, "choices": choices,
        "metavar": metavar, "default": default_text or repr(default)})


def _both(name: str, note: str = "") -> str:
    """The default stated for the embedded buoy and the embedded hull
    (``parapend.defaults.BUOY``, ``HULL``)."""
    return f"{BUOY[name]:g}{note}; a hull's {HULL[name]:g}"


def option_help(meta) -> str:
    """The command line's help of a declared parameter: its help, its unit and its
    default."""
    unit = "" if meta["unit"] == "-" else f", {meta['unit']}"
    default = "" if meta["default"] == "None" else f" (default {meta['default']})"
    return f"{meta['help']}{unit}{default}"


class _Inputs:
    """What every input object shares: its keywords for the command's function."""

    def options(self) -> dict:
        """The keywords of :func:`parapend.buoy` this object sets (None fields left out, so
        the command's defaults apply)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if getattr(self, f.name) is not None}


@dataclass(frozen=True)
class Sea(_Inputs):
    """The sea: a regular wave (:meth:`regular`), a spectrum's sea state (:meth:`state`) or a
    measured record (:meth:`measured`), each taken as a periodic record."""

    wave_height: float | None = _param("m", "H, crest to trough", bounds=(1e-4, 30.0),
                                       default_text=_both("wave_height"))
    wave_period: float | str | None = _param(
        "s", "the period; FROM:TO:N or a comma list T1,T2,... for power against period",
        bounds=(0.1, 100.0), default_text=_both("wave_period"), kind="text", metavar="T")
    hs: float | None = _param("m", "significant wave height",
                              default_text=_both("hs", " with --tp"))
    tp: float | None = _param("s", "peak period", default_text=_both("tp", " with --hs"))
    spectrum: str | None = _param("-", "spectrum shape", default_text="jonswap",
                                  kind="text", choices=("jonswap", "pierson-moskowitz"))
    gamma_peak: float | None = _param("-", "JONSWAP peak enhancement in [1, 20]",
                                      bounds=(1.0, 20.0), default_text="3.3")
    repeat_period: float | None = _param(
        "s", "T_r: the record repeats with it",
        default_text=f"100 Tp; a hull's {HULL['repeat_periods']:g} Tp")
    seed: int | None = _param("-", "seed of the random phases", default_text="0", kind="int")
    cutoff: float | None = _param("-", "highest frequency, in units of the peak frequency",
                                  default_text="3")
    record: str | None = _param("s, m", "measured surface elevation at the body, CSV 't,z'",
                                kind="text", metavar="CSV")
    taper: float | None = _param("-", "with --record: fraction under the Tukey taper",
                                 bounds=(0.0, 0.5), default_text="0.1")
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

    mass: float | None = _param("kg", "m", bounds=(0.0, None), default_text=_both("mass"))
    length: float | None = _param("m", "pivot to centre of mass l", bounds=(0.0, None),
                                  default_text=_both("length"))
    inertia: float | None = _param("kg m^2", "about the pivot, at least m l^2",
                                   default_text="m l^2")
    damping_coefficient: float | None = _param("N m s/rad", "viscous c", bounds=(0.0, None),
                                               default_text=_both("damping_coefficient"))


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
        bounds=(1e-6, 1e12), default_text="the dataset's, else a homogeneous immersed hull's")
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
    horizon: float | None = _param("peak periods", "with mpc: forecast horizon",
                                   default_text="2; one-way-mpc 1")
    update_interval: float | None = _param("peak periods", "with mpc: re-planning interval",
                                           default_text="0.125")
    forecast: str | None = _param(
        "-", "with mpc: what the controller knows of the excitation force over the horizon: "
             "perfect (the record's own future) or ar (autoregressive, fitted on the force "
             "measured so far)", default_text="perfect", kind="text",
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
}

_OBJECTS = (Sea, Pendulum, Body, PowerTakeOff, Controller)


def declarations() -> dict:
    """Every declared parameter: name -> ``(object, unit, default, bounds, help)``."""
    return {f.name: (cls.__name__, f.metadata["unit"], f.metadata["default"],
                     f.metadata["bounds"], f.metadata["help"])
            for cls in _OBJECTS for f in dataclasses.fields(cls)}


def declaration(name: str):
    """The declaration of one parameter (:func:`declarations`), or None."""
    return declarations().get(name)


def _keywords(*objects) -> dict:
    out = {}
    for obj in objects:
        if obj is not None:
            out.update(obj.options())
    return out


def optimum(sea: Sea, pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
            **run):
    """The coupled non-causal optimum (:func:`parapend.buoy`) of the device in ``sea``;
    ``run``: :data:`RUN_OPTIONS` of ``buoy`` (``winding``, ``harmonics``, ...)."""
    from .api import buoy

    return buoy(**_keywords(sea, pendulum, body, pto), **run)


def causal(sea: Sea, pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
           controller: Controller | None = None, **run):
    """A causal run (:func:`parapend.buoy` with ``controller``; default the receding-horizon
    controller planned on the coupled model) of the device in ``sea``. A hull has no causal
    controller yet: refused in one line; its heave-only model runs
    (``body.with_dofs("heave")``)."""
    from .api import buoy

    controller = controller or Controller.receding_horizon()
    return buoy(**_keywords(sea, pendulum, body, pto, controller), **run)


def horizon(sea: Sea, pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
            controller: Controller | None = None, **run):
    """The causal power against the forecast horizon (:func:`parapend.horizon`,
    ``device="buoy"``): the curve sweeps the horizons and forecasts (``run``: ``horizons``,
    ``forecasts``, ...); of ``controller`` it takes the update interval. (The command's
    ``--controller`` there names the planner, ``coupled`` or ``plan``: a run option.)"""
    import inspect

    from ..control.horizon import horizon_curve
    from ..errors import ParameterError
    from .api import refuse_hull

    refuse_hull(body.dofs, "horizon --device buoy")
    kw = {**_keywords(sea, pendulum, body, pto), **run}
    if controller is not None:  # the curve sweeps the horizon and the forecast itself
        if controller.controller not in (None, "mpc"):
            raise ParameterError(f"controller: the horizon curve runs the coupled receding-"
                                 f"horizon controller (mpc), got {controller.controller!r}")
        if controller.update_interval is not None:
            kw["update_interval"] = controller.update_interval
    taken = inspect.signature(horizon_curve).parameters
    for name in kw:
        if name not in taken:
            raise ParameterError(f"{name.replace('_', '-')}: not taken by horizon --device "
                                 "buoy; drop it")
    return horizon_curve(device="buoy", **kw)


def power_matrix(pendulum: Pendulum, body: Body, pto: PowerTakeOff | None = None,
                 controller: Controller | None = None, **run):
    """The device's power matrix (:func:`parapend.power_matrix`, ``device="buoy"``: its
    :class:`~parapend.results.Record`) over the bins of ``run`` (``hs``, ``tp`` or ``te``,
    ``realizations``, ``waves``, ...)."""
    from .. import commands

    kw = _keywords(pendulum, body, pto, controller)
    return commands.power_matrix(device="buoy", **kw, **run)


@dataclass(frozen=True)
class Device:
    """A pendulum in a floating body through a power take-off, built once: its optimum, a
    causal run, the horizon curve and the power matrix in any sea."""

    body: Body = field(default_factory=Body)
    pendulum: Pendulum = field(default_factory=Pendulum)
    pto: PowerTakeOff = field(default_factory=PowerTakeOff)

    def with_dofs(self, dofs) -> Device:
        """The same device with the body's other degrees of freedom (``"heave"``)."""
        return dataclasses.replace(self, body=self.body.with_dofs(dofs))

    def optimum(self, sea: Sea, **run):
        return optimum(sea, self.pendulum, self.body, self.pto, **run)

    def causal(self, sea: Sea, controller: Controller | None = None, **run):
        return causal(sea, self.pendulum, self.body, self.pto, controller, **run)

    def horizon(self, sea: Sea, controller: Controller | None = None, **run):
        return horizon(sea, self.pendulum, self.body, self.pto, controller, **run)

    def power_matrix(self, controller: Controller | None = None, **run):
        return power_matrix(self.pendulum, self.body, self.pto, controller, **run)
