r"""Physical <-> non-dimensional units, converted once at the edge (DESIGN.md section 1).

The physical pendulum (angle ``theta`` from the upright, point mass ``m`` at distance ``l``
from the pivot, or a rigid body of moment of inertia ``I`` about the pivot and centre of mass
at ``l``), on a base that heaves vertically as ``z(t) = A sin(2 pi f t)``::

    I theta_tt + c theta_t - m g l (1 + z_tt/g) sin(theta) = T_phys          (Eq. 14, SI)

becomes paper Eq. 14, ``theta'' + gamma theta' - (1 + q) sin theta = T``, with

=================  =======================================  ==========================
quantity           unit                                     point mass (``I = m l^2``)
=================  =======================================  ==========================
time               ``t0 = sqrt(I / (m g l))``               ``sqrt(l/g)``
torque             ``m g l``                                ``m g l``
power              ``m g l / t0``                           ``m g^1.5 l^0.5``
energy             ``m g l``                                ``m g l``
=================  =======================================  ==========================

and ``omega = 2 pi f t0``, ``q(t) = z_tt/g = -A (2 pi f)^2 / g sin(omega t)``, so
``delta = -A (2 pi f)^2 / g`` (the paper's ``delta < 0`` is a positive displacement
amplitude), ``gamma = c t0 / I`` (``c / (m g^0.5 l^1.5)`` for a point mass).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import limits
from .errors import ParameterError, check_nonnegative, check_positive

__all__ = ["STANDARD_GRAVITY", "Units"]

#: default g, m/s^2
STANDARD_GRAVITY = 9.81


@dataclass(frozen=True)
class Units:
    """Scales of one physical pendulum.

    Parameters
    ----------
    length : float
        Distance ``l`` from the pivot to the centre of mass, m (> 0).
    mass : float
        Pendulum mass ``m``, kg (> 0).
    gravity : float
        ``g``, m/s^2 (> 0, default 9.81).
    inertia : float or None
        Moment of inertia about the pivot, kg m^2; None means a point mass, ``m l^2``.
    """

    length: float
    mass: float
    gravity: float = STANDARD_GRAVITY
    inertia: float | None = None

    def __post_init__(self):
        for name, rng, unit in (("length", limits.UNIT_LENGTH_RANGE, "m"),
                                ("mass", limits.UNIT_MASS_RANGE, "kg"),
                                ("gravity", limits.UNIT_GRAVITY_RANGE, "m/s^2")):
            object.__setattr__(self, name, _in_range(name, getattr(self, name), rng, unit))
        if self.inertia is not None:
            inertia = check_positive("inertia", self.inertia)
            ml2 = self.mass * self.length**2
            lo, hi = (r * ml2 for r in limits.UNIT_INERTIA_RATIO)
            if not lo * (1 - 1e-12) <= inertia <= hi:
                raise ParameterError(
                    f"inertia: expected a moment of inertia about the pivot in [m l^2, "
                    f"{limits.UNIT_INERTIA_RATIO[1]:g} m l^2] = [{lo:.6g}, {hi:.6g}] kg m^2 "
                    f"(I = I_cm + m l^2), got {self.inertia!r}")
            object.__setattr__(self, "inertia", inertia)

    def _derived(self, name: str, value: float, what: str, lo: float, hi: float,
                 given: float, unit: str, absolute: bool = False) -> float:
        """``value`` (the non-dimensional ``what`` that option ``name`` gives) checked
        against ``[lo, hi]`` (``|value|`` with ``absolute``); the error names the option."""
        x = abs(value) if absolute else value
        if math.isfinite(value) and lo <= x <= hi and not (
                what == "delta" and 0 < x < limits.MIN_AMPLITUDE):
            return value
        rng = (f"0 or in [{limits.MIN_AMPLITUDE:g}, {hi:g}]" if what == "delta"
               else f"in [{lo:g}, {hi:g}]")
        raise ParameterError(
            f"{name}: expected a value giving {'|' + what + '|' if absolute else what} "
            f"{rng} for this pendulum (time unit {self.time:.4g} s), got {given!r} {unit} "
            f"({what} = {value:.4g})")

    # -- scales -----------------------------------------------------------------------------
    @property
    def moment_of_inertia(self) -> float:
        """``I`` about the pivot, kg m^2."""
        return self.mass * self.length**2 if self.inertia is None else self.inertia

    @property
    def time(self) -> float:
        """Time unit ``t0 = sqrt(I / (m g l))``, s (``sqrt(l/g)`` for a point mass)."""
        return math.sqrt(self.moment_of_inertia / (self.mass * self.gravity * self.length))

    @property
    def torque(self) -> float:
        """Torque unit ``m g l``, N m."""
        return self.mass * self.gravity * self.length

    @property
    def energy(self) -> float:
        """Energy unit ``m g l``, J."""
        return self.torque

    @property
    def power(self) -> float:
        """Power unit ``m g l / t0``, W (``m g^1.5 l^0.5`` for a point mass)."""
        return self.torque / self.time

    @property
    def damping(self) -> float:
        """Unit of the viscous damping coefficient: ``I / t0``, N m s/rad."""
        return self.moment_of_inertia / self.time

    # -- conversions ------------------------------------------------------------------------
    def omega(self, frequency: float) -> float:
        """Non-dimensional forcing frequency ``omega = 2 pi f t0`` of a base frequency in Hz."""
        f = check_positive("frequency", frequency)
        return self._derived("frequency", 2 * math.pi * f * self.time, "omega",
                             *limits.OMEGA_RANGE, frequency, "Hz")

    def frequency(self, omega: float) -> float:
        """Base frequency in Hz of a non-dimensional ``omega``."""
        return omega / (2 * math.pi * self.time)

    def delta(self, amplitude: float, frequency: float) -> float:
        """``delta = -A (2 pi f)^2 / g`` of a base displacement ``A sin(2 pi f t)`` (A in m)."""
        a = check_nonnegative("amplitude", amplitude)
        f = check_positive("frequency", frequency)
        d = -a * (2 * math.pi * f) ** 2 / self.gravity
        return self._derived("amplitude", d, "delta", 0.0, limits.MAX_AMPLITUDE, amplitude,
                             "m", absolute=True)

    def amplitude(self, delta: float, frequency: float) -> float:
        """Base displacement amplitude (m) of ``delta`` at ``frequency`` Hz (inverse of delta)."""
        return -delta * self.gravity / (2 * math.pi * frequency) ** 2

    def gamma(self, damping_coefficient: float) -> float:
        """Non-dimensional ``gamma = c t0 / I`` of a viscous coefficient ``c`` in N m s/rad."""
        c = check_nonnegative("damping-coefficient", damping_coefficient)
        return self._derived("damping-coefficient", c / self.damping, "gamma", 0.0,
                             limits.MAX_GAMMA, damping_coefficient, "N m s/rad")

    def damping_coefficient(self, gamma: float) -> float:
        """Viscous coefficient (N m s/rad) of a non-dimensional ``gamma``."""
        return gamma * self.damping

    def to_watts(self, power: float) -> float:
        return power * self.power

    def from_watts(self, watts: float) -> float:
        return watts / self.power

    def to_newton_metres(self, torque: float) -> float:
        return torque * self.torque

    def from_newton_metres(self, torque_nm: float) -> float:
        return torque_nm / self.torque

    def to_joules(self, energy: float) -> float:
        return energy * self.energy

    def to_seconds(self, t: float) -> float:
        return t * self.time

    @classmethod
    def from_description(cls, description: dict | None):
        """The units of a result's ``units`` field (:meth:`describe`), or None."""
        if not description or "length_m" not in description:
            return None
        return cls(length=description["length_m"], mass=description["mass_kg"],
                   gravity=description["gravity_m_s2"],
                   inertia=description["inertia_kg_m2"])

    def describe(self) -> dict:
        """The scales, for JSON output (SI units in the key names)."""
        return {"length_m": self.length, "mass_kg": self.mass, "gravity_m_s2": self.gravity,
                "inertia_kg_m2": self.moment_of_inertia, "time_unit_s": self.time,
                "torque_unit_nm": self.torque, "power_unit_w": self.power}


def _in_range(name: str, value, rng: tuple, unit: str) -> float:
    """A positive scale within ``rng`` (> 0 first, so that 0 and negatives say so)."""
    x = check_positive(name, value)
    if not rng[0] <= x <= rng[1]:
        raise ParameterError(f"{name}: expected a number in [{rng[0]:g}, {rng[1]:g}] {unit} "
                             f"(see docs/limits-of-input.md), got {value!r}")
    return x


def from_options(*, length=None, mass=None, gravity=None, inertia=None, frequency=None,
                 amplitude=None, damping_coefficient=None) -> tuple[Units | None, dict]:
    """Units and the non-dimensional parameters they imply, from command-line options.

    Returns ``(units, params)``: ``units`` is None when no physical option is given;
    ``params`` holds ``omega`` (from ``frequency``), ``delta`` (from ``amplitude`` and
    ``frequency``) and ``gamma`` (from ``damping_coefficient``) where those are given.
    ``length`` and ``mass`` are required as soon as any physical option is.
    """
    given = {k: v for k, v in {"gravity": gravity, "inertia": inertia, "frequency": frequency,
                               "amplitude": amplitude,
                               "damping-coefficient": damping_coefficient}.items()
             if v is not None}
    if length is None and mass is None and not given:
        return None, {}
    missing = [n for n, v in (("length", length), ("mass", mass)) if v is None]
    if missing:
        raise ParameterError(f"{', '.join(missing)}: required with physical units (options "
                             f"--length and --mass, given: {', '.join(given) or 'one of them'})")
    u = Units(length, mass, STANDARD_GRAVITY if gravity is None else gravity, inertia)
    params = {}
    if amplitude is not None and frequency is None:
        raise ParameterError("amplitude: needs --frequency (delta = -A (2 pi f)^2 / g)")
    if frequency is not None:
        params["omega"] = u.omega(frequency)
    if amplitude is not None:
        params["delta"] = u.delta(amplitude, frequency)
    if damping_coefficient is not None:
        params["gamma"] = u.gamma(damping_coefficient)
    return u, params


#: axis-label words -> (quantity, SI unit, name of the Units scale)
_SI_AXES = (("torque", "torque", "N m", "torque"), ("power", "power", "W", "power"),
            ("energy", "energy", "J", "energy"), ("damping", "damping c", "N m s/rad", "damping"))


def si_figure(fig, units: Units | None):
    """``fig`` with SI axes beside its non-dimensional ones (:func:`add_si_axes`) and its
    layout redone; ``fig`` unchanged when ``units`` is None. Returns ``fig``."""
    if units is None:
        return fig
    from .style import figure_style

    with figure_style():
        add_si_axes(fig, units)
        engine = fig.get_layout_engine()
        if engine is None or type(engine).__name__ == "TightLayoutEngine":
            fig.tight_layout()  # (a constrained layout adapts by itself)
    return fig


def add_si_axes(fig, units: Units) -> None:
    """Give every axis of ``fig`` that shows a torque, a power, an energy, a damping, a time,
    an angular rate or the forcing frequency omega in the non-dimensional units a secondary
    axis in SI (right or top: omega as the base frequency in Hz),
    labelled with its unit (a time in forcing periods or as the phase tau is left alone).

    The quantity is read from the axis label (a figure keeps its non-dimensional scale and
    gains the SI one beside it); labels already in SI units (W, N m, J) are left alone.
    """
    for ax in list(fig.axes):
        if getattr(ax, "_colorbar", None) is not None:
            continue  # a colour bar is drawn in the units its figure chose
        for which in ("y", "x"):
            label = (ax.get_ylabel() if which == "y" else ax.get_xlabel()).lower()
            if not label or any(f"({u.lower()}" in label for u in ("W", "N m", "J", "kJ")):
                continue
            bare = label.replace("$", "").strip()
            is_time = (bare == "t" or bare.startswith(("t ", "t(")) or "time" in bare) and \
                "period" not in bare and "tau" not in bare and "(s)" not in bare
            # an angular rate in rad per sqrt(l/g) (the unit of time), or a power named only by
            # its unit m g l / t0 (a gap to the limit, say)
            is_rate = "rad per" in bare and "sqrt" in bare
            is_omega = bare.startswith("\\omega") and "sqrt(g/l)" in bare.replace(" ", "")
            is_power = "mgl/t_0" in bare.replace(" ", "")
            for word, name, unit, scale in _SI_AXES + (("", "time", "s", "time"),
                                                       ("", "angular rate", "rad/s", "rate"),
                                                       ("", "power", "W", "power"),
                                                       ("", "frequency", "Hz", "frequency")):
                if (word and word in label) or (not word and (
                        (name == "time" and is_time) or (name == "angular rate" and is_rate)
                        or (name == "power" and is_power)
                        or (name == "frequency" and is_omega))):
                    k = (1.0 / float(units.time) if scale == "rate"
                         else 1.0 / (2 * math.pi * float(units.time)) if scale == "frequency"
                         else float(getattr(units, scale)))
                    funcs = (lambda v, k=k: v * k, lambda v, k=k: v / k)
                    if which == "y":
                        sec = ax.secondary_yaxis("right", functions=funcs)
                        sec.set_ylabel(f"{name} ({unit})")
                    else:
                        sec = ax.secondary_xaxis("top", functions=funcs)
                        sec.set_xlabel(f"{name} ({unit})")
                        if ax.get_title():  # above the new scale, not over it
                            ax.set_title(ax.get_title(), pad=36)
                    break
