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
from ..limits import BUOY_SIZE_RANGE, HULL_PITCH_INERTIA_RANGE, SEA_WAVES_RANGE

__all__ = ["Body", "Controller", "DeviceInputs", "INPUT_KEYWORDS", "PRESCRIBED_OPTIONS",
           "Pendulum", "PowerTakeOff", "RUN_OPTIONS", "Sea", "check", "declaration",
           "declarations", "default_of", "expand_inputs", "has_inputs", "option_help"]


def _param(unit: str, help: str, *, default=None, bounds=None, default_text=None,
           kind: str = "float", choices=None, metavar=None, commands=None, value=None):
    """A parameter's declaration: a field whose metadata hold its unit, bounds (the range the
    command accepts: ``(lo, hi)`` closed, ``hi`` None for none above, ``POSITIVE`` for
    ``> 0``; or None where it depends on other parameters; :func:`check`), help, how the command
    line reads it (``kind``: float, int, text; ``choices``, ``metavar``) and the default it
    states (``default_text``; ``default`` None means the command's default). ``commands``:
    what another command (``horizon``, ``power-matrix``) states instead, its own ``help``
    or ``default`` (a documented per-command default: the prescribed-heave pendulum's, or
    the horizon curve's shorter records), and where the command reads the option otherwise
    its ``unit``, ``kind``, ``choices`` or ``metavar`` (the power matrix's bins, comma lists
    of its causal columns; the prescribed-heave pendulum's torque limit in ``m g l``).
    ``value``: the command's default itself where it
    is one value (or one per controller or per body, a dict: ``"buoy"`` the embedded buoy's,
    ``"hull"`` the embedded hull's, ``parapend.defaults``), which the command reads
    (:func:`default_of`) and the help states (``default_text`` then defaults to it)."""
    if default_text is None and value is not None and not isinstance(value, dict):
        default_text = value if isinstance(value, str) else f"{value:g}"
    return field(default=default, metadata={
        "unit": unit, "help": help, "bounds": bounds, "kind": kind, "choices": choices,
        "metavar": metavar, "default": default_text or repr(default),
        "commands": commands or {}, "value": value})


#: the bounds of a parameter that must be above 0 (:func:`check`)
POSITIVE = (0.0, None, "> 0")


def _per_body(name: str) -> dict:
    """The defaults of the embedded buoy and the embedded hull (``parapend.defaults.BUOY``,
    ``HULL``), the value of a declaration (:func:`default_of` with ``"buoy"`` or
    ``"hull"``)."""
    return {"buoy": BUOY[name], "hull": HULL[name]}


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


def _bins(what: str, default=None) -> dict:
    """``power-matrix``'s own reading of a sea-state parameter: the bins' centres (FROM:TO:N
    or a comma list, as its group of options says)."""
    return {"help": what, "default": default, "kind": "text", "metavar": None}


def option_help(meta, command: str | None = None) -> str:
    """The command line's help of a declared parameter: its help, its unit and its default
    (those ``command`` states instead, where its declaration says so)."""
    own = meta.get("commands", {}).get(command, {})
    unit = own.get("unit", meta["unit"])
    unit = "" if unit == "-" else f", {unit}"
    stated = own.get("default", meta["default"])
    default = "" if stated in (None, "None") else f" (default {stated})"
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
                                       value=_per_body("wave_height"),
                                       default_text=_both("wave_height"))
    wave_period: float | str | None = _param(
        "s", "the period; FROM:TO:N or a comma list T1,T2,... for power against period",
        bounds=(0.1, 100.0), default_text=_both("wave_period"), kind="text", metavar="T",
        value=_per_body("wave_period"))
    hs: float | None = _param("m", "significant wave height", value=_per_body("hs"),
                              default_text=_both("hs", " with --tp"), commands={
                                  **_device("hs"), "power-matrix": _bins(
                                      "significant wave height Hm0", "1:3:3")})
    tp: float | None = _param("s", "peak period", default_text=_both("tp", " with --hs"),
                              value=_per_body("tp"),
                              commands={**_device("tp"), "power-matrix": _bins(
                                  "peak period, instead of --te (Te = (Te/Tp of the "
                                  "spectrum) Tp)")})
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
    seed: int | None = _param("-", "seed of the random phases", value=0, kind="int",
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

    mass: float | None = _param("kg", "m", bounds=POSITIVE, default_text=_both("mass"),
                                value=_per_body("mass"),
                                commands=_device("mass"))
    length: float | None = _param("m", "pivot to centre of mass l", bounds=POSITIVE,
                                  value=_per_body("length"),
                                  default_text=_both("length"), commands=_device("length"))
    inertia: float | None = _param("kg m^2", "about the pivot, at least m l^2", bounds=POSITIVE,
                                   default_text="m l^2")
    damping_coefficient: float | None = _param(
        "N m s/rad", "viscous c", bounds=(0.0, None), value=_per_body("damping_coefficient"),
        default_text=_both("damping_coefficient"), commands=dict.fromkeys(
            ("horizon", "power-matrix"),
            {"help": "viscous c (instead of --gamma)",
             "default": f"--gamma; {BUOY['damping_coefficient']:g} with --device buoy"}))

    def checked(self, kind: str = "buoy"):
        """The pendulum of the coupled model (:class:`parapend.hydro.coupled.Pendulum`): each
        field's declared default (the embedded ``kind``'s, ``"buoy"`` or ``"hull"``) and
        bounds applied (:func:`~parapend.hydro.declared.check`), and what ties the fields
        together checked: the inertia at least ``m l^2`` (its default), the units' ranges
        (``parapend.limits.UNIT_*``, each message naming the option given)."""
        from ..errors import ParameterError
        from ..units import Units
        from .coupled import Pendulum as Coupled

        mass = check("mass", default_of("mass", self.mass, kind))
        length = check("length", default_of("length", self.length, kind))
        Units(length, mass, 9.81, None)
        ml2 = mass * length * length
        inertia = check("inertia", ml2 if self.inertia is None else self.inertia)
        if inertia < ml2 * (1 - 1e-12):
            raise ParameterError(f"inertia: expected at least m l^2 = {ml2:.6g} kg m^2 (the "
                                 f"inertia about the pivot of a mass {mass:g} kg at "
                                 f"{length:g} m), got {inertia:g}")
        c = check("damping_coefficient",
                  default_of("damping_coefficient", self.damping_coefficient, kind))
        Units(length, mass, 9.81, inertia).gamma(c)
        return Coupled(mass=mass, length=length, inertia=inertia, damping_coefficient=c)


@dataclass(frozen=True)
class Body(_Inputs):
    """The floating body: a built-in shape (``body``: cylinder, sphere, barge), a mesh file or
    a Capytaine dataset; its degrees of freedom; the pivot's placement in it."""

    body: str | None = _param(
        "-", "a vertical cylinder or a sphere floating at its centre; with --dofs "
             "surge,heave,pitch also a box barge", default_text="cylinder; a hull's barge",
        kind="text", choices=("cylinder", "sphere", "barge"), commands={"horizon": {
            "help": "a vertical cylinder or a sphere floating at its centre",
            "default": "cylinder", "choices": ("cylinder", "sphere")}})
    radius: float | None = _param("m", "the cylinder's or the sphere's radius",
                                  bounds=BUOY_SIZE_RANGE, value=_per_body("radius"),
                                  default_text=_both("radius"))
    draft: float | None = _param("m", "the cylinder's draft (a hull sphere's: r / 2)",
                                 bounds=BUOY_SIZE_RANGE, value=_per_body("draft"),
                                 default_text=_both("draft"))
    mesh: str | None = _param("-", "a mesh file Capytaine reads, instead of --body (z = 0 "
                                   "the free surface)", kind="text", metavar="FILE")
    hydro: object = _param("-", "a Capytaine dataset (NetCDF; in Python also an "
                                "xarray.Dataset), instead of solving (docs/buoy.md)",
                           kind="text", metavar="FILE")
    dofs: str | None = _param(
        "-", "the body's degrees of freedom: heave (the heaving buoy) or surge,heave,pitch (a "
             "hull that pitches; the pendulum rotates or swings)", default_text="heave",
        kind="text", metavar="DOFS", commands={
            "horizon": {"help": "the body's degrees of freedom: heave (the heaving buoy) or "
                                "surge,heave,pitch (a hull that pitches: its own planner)"},
            "power-matrix": {"help": "the body's degrees of freedom: heave (the heaving buoy) "
                                     "or surge,heave,pitch (a hull that pitches; each "
                                     "record's best of rotation, swinging and rest; its "
                                     "pendulum's defaults the hull's: "
                                     f"{HULL['mass']:g} kg, {HULL['length']:g} m, "
                                     f"{HULL['damping_coefficient']:g} N m s/rad; records of "
                                     "200 peak periods or 20 minutes, the longer, with an "
                                     "ideal take-off (up to 300 waves), 4 with losses (at "
                                     "most about 30 with a torque limit or a copper loss, "
                                     "10 with an efficiency))"}})
    pivot_height: float | None = _param(
        "m", "the pivot above the rotation centre O: a built-in body's waterplane centre, a "
             "mesh's origin, a dataset's rotation centre",
        value=HULL["pivot_height"])
    pivot_offset: float | None = _param("m", "the pivot ahead of O, along the waves' travel",
                                        value=HULL["pivot_offset"])
    hull_pitch_inertia: float | None = _param(
        "kg m^2", "the hull's pitch inertia about O, without the pendulum",
        bounds=HULL_PITCH_INERTIA_RANGE,
        default_text="the dataset's, else a homogeneous immersed hull's")
    barge_length: float | None = _param("m", "the box barge's length",
                                        value=HULL["barge_length"], bounds=BUOY_SIZE_RANGE)
    barge_beam: float | None = _param("m", "the box barge's beam",
                                      value=HULL["barge_beam"], bounds=BUOY_SIZE_RANGE)
    barge_draft: float | None = _param("m", "the box barge's draft",
                                       value=HULL["barge_draft"], bounds=BUOY_SIZE_RANGE)

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

    torque_limit: float | None = _param("N m", "largest |torque|", bounds=(1e-6, 1e12), commands={
        # the prescribed-heave pendulum's curve states its torque in its own unit, m g l
        # (--torque-limit-nm: this declaration's N m)
        "horizon": {"unit": "m g l", "default": "none",
                    "help": "|T| <= T_max for every controller (the prescribed-heave "
                            "pendulum's unit; --torque-limit-nm gives it in N m)"},
        "power-matrix": {"help": "largest |torque|; with --dofs surge,heave,pitch (refused "
                                 "otherwise: not supported over a sea record)"},
        # and so do the commands of the pendulum on a prescribed motion
        **dict.fromkeys(("optimize", "pto-curve", "track", "sweep"), {"unit": "m g l"})})
    efficiency: float | str | tuple | None = _param(
        "-", "power take-off efficiency in (0, 1], generating[,motoring]: the motion "
             "maximizes the electrical power", bounds=(0.01, 1.0), kind="text",
        metavar="ETA_G[,ETA_M]", commands={
            "horizon": {"kind": "float", "metavar": None, "default": "none: lossless",
                        "help": "power take-off efficiency in (0, 1], generating and "
                                "motoring, for every controller"},
            "power-matrix": {"kind": "float", "metavar": None,
                             "help": "power take-off efficiency in [1e-6, 1]: the power "
                                     "reported is the electrical one, the mechanical beside "
                                     "it"}})
    copper_loss: float | None = _param(
        "W/(N m)^2", "the generator's winding loss r tau^2 subtracted from the power (with "
                     "--dofs surge,heave,pitch)", bounds=(0.0, 1e6))

    def hull(self):
        """The hull's take-off (:class:`parapend.hydro.hull.HullPTO`): each field checked
        in its declared bounds (:func:`~parapend.hydro.declared.check`); None the ideal
        one's (no limit, lossless, no copper loss)."""
        from .hull import HullPTO
        from .pto import efficiency_pair

        limit = None if self.torque_limit is None else check("torque_limit", self.torque_limit)
        r = 0.0 if self.copper_loss is None else check("copper_loss", self.copper_loss)
        return HullPTO(efficiency=efficiency_pair(self.efficiency), copper_loss=r,
                       torque_limit=limit)


@dataclass(frozen=True)
class Controller(_Inputs):
    """How the torque is decided: the non-causal optimum (``controller`` None or
    ``"optimum"``) or a receding-horizon controller (``"mpc"``, ``"one-way-mpc"``) with its
    horizon and update interval (peak periods) and forecast."""

    controller: str | None = _param(
        "-", "optimum: the non-causal coupled optimum; mpc: receding-horizon control planned "
             "on the coupled model with its radiation (the motion planner; with --efficiency "
             "the torque planner); one-way-mpc: planned on the free buoy's heave",
        default_text="optimum", kind="text", choices=("optimum", "mpc", "one-way-mpc"),
        commands={"power-matrix": {
            "choices": ("mpc", "none"), "default": "none",
            "help": "mpc: beside the non-causal optimum, the receding-horizon controller on "
                    "the same records (storage-corrected, after --warm-up), and the annual "
                    "energy of each column side by side"}})
    horizon: float | None = _param(
        "peak periods", "with mpc: forecast horizon", value=_MPC_HORIZON,
        default_text=f"{_MPC_HORIZON['mpc']:g}; one-way-mpc {_MPC_HORIZON['one-way-mpc']:g}",
        commands={"track": {"unit": "peak (forcing) periods"}, "power-matrix": {
            "help": "the causal column's horizon, 0.05 to 20 (a hull's at most 10)",
            "default": f"1 with --controller mpc; the buoy's {_MPC_HORIZON['mpc']:g}, 1 with "
                       "--efficiency (a hull's 2 with it too)"}})
    update_interval: float | None = _param(
        "peak periods", "with mpc: re-planning interval", value=0.125,
        commands={"horizon": {  # the prescribed-heave pendulum's curve re-plans more often
            "help": "receding-horizon update interval",
            "default": f"{HORIZON['update_interval']:g}; "
                       f"{BUOY_HORIZON['update_interval']:g} with --device buoy"},
            "power-matrix": {"help": "between two plans of the causal column, 0.001 to 1",
                             "default": "1/32 with --controller mpc; the buoy's 1/8, at "
                                        "least 1/64 (a hull's 1/24)"}})
    forecast: str | None = _param(
        "-", "with mpc: what the controller knows of the excitation force over the horizon: "
             "perfect (the record's own future) or ar (autoregressive, fitted on the force "
             "measured so far)", value="perfect", kind="text",
        choices=("perfect", "ar"), commands={"power-matrix": {
            "choices": None, "metavar": "NAMES",
            "help": "perfect, ar (autoregressive, fitted on the past only) or perfect,ar: one "
                    "causal column each",
            "default": "perfect with --controller mpc; ar costs more (it fits a model at "
                       "every plan)"}})

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
    "winding": "turns of the pendulum per wave or record (resolution of the motion; in a "
               "hull, negative against the sense of a positive pitch)",
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
    "torque_limit_nm": "the torque limit in N m where --torque-limit is in m g l (horizon's, "
                       "the prescribed-motion commands'): a PowerTakeOff's torque_limit",
    "te": "energy periods of the bins", "realizations": "records per bin",
    "waves": "waves per record", "response": "the prescribed heave's response",
    "depth": "water depth of the bins' resource", "density": "water density",
    "width": "the device's width for the capture width", "scatter": "a scatter table",
    "timeseries": "a sea-state time series", "rated_power": "the rated power",
    "store": "the Zarr store", "overwrite": "replace the store", "workers": "processes",
    "scheduler": "a Dask scheduler", "netcdf": "an output file", "zarr": "an output file",
    "csv": "an output file", "command": "the command line recorded",
    "plan_samples": "torque samples per interval of the causal plan",
    "planner": "the receding-horizon controller's horizon solver: the heaving buoy's plan "
               "or coupled, the hull's collocation or lbfgsb",
}

#: options of the commands of the pendulum on a prescribed motion (the paper's
#: non-dimensional problem: ``simulate``, ``optimize``, ``track``, ``sweep``, ...) that no
#: input object declares: its excitation, its solvers' and its outputs' options (each
#: command's help states the range and the default, its function's signature holds the
#: default: tests/test_declared_once.py)
PRESCRIBED_OPTIONS = {
    "excitation": "the kind of q(t): harmonic, two-harmonic, square, fourier, file",
    "omega": "forcing frequency, units sqrt(g/l)", "delta": "q's amplitude, units g",
    "p": "excitation strength of Eq. 1", "square_alpha": "tanh width of the square wave",
    "fourier": "q's Fourier terms k:amp:phase", "file": "one period of q, CSV tau,q",
    "frequency": "base heave frequency, Hz (sets omega)",
    "amplitude": "base heave amplitude, m (sets delta)",
    "resolution": "grid points per axis of the basins", "phi_range": "initial angles, rad",
    "dphi_range": "initial rates, units sqrt(g/l)", "periods": "forcing periods run",
    "steps_per_period": "RK4 steps per forcing period",
    "accuracy_sample": "points re-run to estimate the labels' accuracy",
    "accuracy_seed": "seed of that sample", "split_phases": "one basin per attractor phase",
    "engine": "compiled kernel or NumPy", "gamma_max": "largest damping of the sweep",
    "points": "points of the curve", "n_from": "smallest N", "n_to": "largest N",
    "method": "fourier or bvp", "efficiency_generating": "eta_g, overrides efficiency",
    "efficiency_motoring": "eta_m, overrides efficiency", "vary": "the varied parameter",
    "generator_damping": "generator damping c_g, N m s/rad",
    "duration": "record length, s", "transient": "left out before the window, s",
    "omniscient": "records given the omniscient optimum", "gpu": "integrate on the GPU",
    "p_max": "largest p followed", "phi0": "initial angle, rad",
    "dphi0": "initial rate, units sqrt(g/l)", "points_per_period": "output samples per period",
    "threshold": "also gamma* at every point", "block_points": "points per stored block",
    "torque_margin": "torque limit's share kept for feedback",
    "r_weight": "LQR torque weight", "lock_tolerance": "a locked period's angle error, rad",
    "theta0": "initial angle from upright, rad", "theta_dot0": "initial speed",
    "runs": "seeded runs", "gamma_error": "plant's damping error, relative",
    "delta_error": "plant's amplitude error, relative",
    "noise_theta": "theta's measurement noise, rad", "noise_speed": "theta' noise",
    "irregular": "a seeded JONSWAP record for q", "variable": "the map's variable",
    "x": "the map's horizontal axis", "y": "the map's vertical axis",
    "at": "a further axis's value", "plot": "an output figure", "out": "an output directory",
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
    from ..errors import check_nonnegative, check_positive, check_range

    meta = _meta(name)
    lo, hi = meta["bounds"][:2]
    flag = name.replace("_", "-")
    if hi is None:  # a lower bound alone: 0, included (>= 0) or not (POSITIVE)
        return (check_positive if meta["bounds"] == POSITIVE else check_nonnegative)(
            flag, value)
    return check_range(flag, value, lo, hi, absolute=absolute,
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
