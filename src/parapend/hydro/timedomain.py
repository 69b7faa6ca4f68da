"""Time-domain simulation of the buoy and its pendulum: Cummins' equation, coupled.

Heave ``z`` (up from static equilibrium) and the pendulum's angle ``theta`` (from the
upright) obey

    (M + A_inf) z'' + m l (cos theta)'' = -C z - mu(t) + F_exc(t)
    I theta'' + c theta' - m l (g + z'') sin(theta) = tau

with the radiation memory ``mu(t) = int_0^inf K(s) z'(t - s) ds`` and the impulse response
``K(t) = (2/pi) int_0^inf B(w) cos(w t) dw``. As ``(cos theta)'' = -sin(theta) theta'' -
cos(theta) theta'^2`` contains ``theta''``, both accelerations are found at each step from
the symmetric 2x2 mass matrix

    [[M + A_inf, -m l sin(theta)], [-m l sin(theta), I]]

(positive definite: its determinant is ``(M + A_inf) I - (m l sin theta)^2 > 0`` for
``I >= m l^2`` and ``M >= m``), the mass matrix of the Lagrangian
``1/2 M z'^2 - m l sin(theta) z' theta' + 1/2 I theta'^2``.

``K`` is the exact cosine transform of ``B`` as ``Hydro.coefficients`` interpolates it
(piecewise linear from ``B(0) = 0``, zero above the data), so the simulation and the
frequency domain use the same damping. ``A_inf`` follows from the Kramers-Kronig relation
``A(w) = A_inf - (2/pi) PV int_0^inf B(v) / (w^2 - v^2) dv``, evaluated exactly for the
piecewise-linear ``B`` at every data frequency; the median of these estimates is used and
their spread (a measure of how far the data's ``A`` and ``B`` are from causal) is returned.

The equations are integrated with the classical 4th-order Runge-Kutta method on a fixed step
``dt``; the memory ``mu`` is a trapezoidal sum over the stored velocity at the step points,
extrapolated quadratically inside a step (so the scheme is explicit; its error is checked
by halving ``dt`` in the tests).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, check_nonnegative, check_positive

__all__ = ["a_infinity", "model_impedance", "radiation_kernel", "regular_wave_force",
           "simulate"]


def _b_nodes(hydro):
    """The nodes of the piecewise-linear ``B(w)``: from ``(0, 0)`` through the data."""
    w = np.concatenate(([0.0], hydro.omega))
    b = np.concatenate(([0.0], hydro.radiation_damping))
    return w, b


def radiation_kernel(hydro, t):
    """``K(t) = (2/pi) int_0^inf B(w) cos(w t) dw`` (N/m, per second), exact for the
    piecewise-linear ``B`` that ``Hydro.coefficients`` interpolates (zero above the data).

    Parameters
    ----------
    hydro : Hydro
    t : array_like
        Times (s), >= 0.
    """
    t = np.asarray(t, dtype=float)
    w, b = _b_nodes(hydro)
    w0, w1 = w[:-1], w[1:]
    b0, b1 = b[:-1], b[1:]
    s = (b1 - b0) / (w1 - w0)
    out = np.empty(t.shape)
    flat = t.ravel()
    res = out.ravel()
    for i, ti in enumerate(flat):
        if ti == 0.0:
            res[i] = np.sum(0.5 * (b0 + b1) * (w1 - w0))
        else:
            # int (b0 + s (v - w0)) cos(v t) dv = [(b(v) sin(v t)) / t + s cos(v t) / t^2]
            up = b1 * np.sin(w1 * ti) / ti + s * np.cos(w1 * ti) / ti**2
            lo = b0 * np.sin(w0 * ti) / ti + s * np.cos(w0 * ti) / ti**2
            res[i] = np.sum(up - lo)
    return (2.0 / math.pi) * out


def a_infinity(hydro):
    """Estimates of the infinite-frequency added mass (kg) at each data frequency.

    ``A_inf(w_i) = A(w_i) + (2/pi) PV int_0^inf B(v) / (w_i^2 - v^2) dv`` with ``B``
    piecewise linear (exact integrals). The highest frequency, where ``B`` drops to zero
    and the principal value diverges, is left out.

    Returns
    -------
    numpy.ndarray
        One estimate per data frequency but the last (all of them if there is only one).
    """
    w, b = _b_nodes(hydro)
    nodes = hydro.omega if hydro.omega.size == 1 else hydro.omega[:-1]
    amass = hydro.added_mass if hydro.omega.size == 1 else hydro.added_mass[:-1]
    v0, v1 = w[:-1], w[1:]
    b0, b1 = b[:-1], b[1:]
    s = (b1 - b0) / (v1 - v0)
    alpha = b0 - s * v0  # b(v) = alpha + s v on each segment
    est = np.empty(nodes.size)
    for i, om in enumerate(nodes):
        def prim(v, om=om):
            lm = np.log(np.abs(om - v), where=np.abs(om - v) > 1e-12 * om,
                        out=np.zeros_like(v))
            lp = np.log(om + v)
            return (alpha / (2 * om)) * (lp - lm) - 0.5 * s * (lm + lp)
        pv = np.sum(prim(v1) - prim(v0))
        est[i] = amass[i] + (2.0 / math.pi) * pv
    return est


def regular_wave_force(hydro, omega, amplitude, phase=0.0):
    """The excitation force ``F_exc(t) = Re(F(w) a exp(i (w t + phase)))`` (N) of a regular
    wave of amplitude ``a`` (m) whose elevation at the body is ``a cos(w t + phase)``."""
    omega = check_positive("omega", omega)
    _, _, f = hydro.coefficients(omega)
    c = complex(f) * float(amplitude) * np.exp(1j * float(phase))

    def force(t):
        return np.real(c * np.exp(1j * omega * np.asarray(t, dtype=float)))
    return force


def _memory_weights(hydro, dt, memory):
    """Trapezoidal weights ``w_j`` of ``mu = sum_j w_j zdot(t - j dt)``, and their count - 1."""
    if memory is None:
        k0 = float(radiation_kernel(hydro, 0.0))
        tk = np.arange(0.0, 60.0 + dt, dt)
        kk = radiation_kernel(hydro, tk)
        big = np.nonzero(np.abs(kk) > 1e-4 * abs(k0))[0]
        last = int(big[-1]) if big.size else 0
        nk = min(tk.size - 1, max(2, int(1.2 * last) + 2))
        kern = kk[: nk + 1]
    else:
        memory = check_positive("memory", memory)
        nk = max(2, math.ceil(memory / dt))
        kern = radiation_kernel(hydro, np.arange(nk + 1) * dt)
    weights = kern * dt
    weights[0] *= 0.5
    weights[-1] *= 0.5
    return weights, nk


def _a_inf(hydro, a_inf, match_omega, est):
    if a_inf is not None:
        return check_nonnegative("a_inf", a_inf)
    if match_omega is not None:
        nodes = hydro.omega if hydro.omega.size == 1 else hydro.omega[:-1]
        return float(np.interp(check_positive("match_omega", match_omega), nodes, est))
    return float(np.median(est))


def model_impedance(hydro, w, *, dt, memory=None, a_inf=None, match_omega=None):
    """The heave impedance the time-domain model integrates (free buoy), at ``w`` (rad/s).

    ``D_td(w) = -w^2 (M + A_inf - Ks(w) / w) + i w Kc(w) + C`` with ``Kc``, ``Ks`` the
    cosine and sine sums of the discrete memory (the same weights as :func:`simulate`
    with these ``dt``, ``memory``, ``a_inf``, ``match_omega``). Its difference from
    :meth:`parapend.hydro.bem.Hydro.impedance` is the model error that is not the integrator's.
    """
    w = np.asarray(w, dtype=float)
    weights, nk = _memory_weights(hydro, check_positive("dt", dt), memory)
    ainf = _a_inf(hydro, a_inf, match_omega, a_infinity(hydro))
    s = np.arange(nk + 1) * dt
    kc = np.cos(np.multiply.outer(w, s)) @ weights
    ks = np.sin(np.multiply.outer(w, s)) @ weights
    return (-w**2 * (hydro.mass + ainf) + w * ks + 1j * w * kc
            + hydro.hydrostatic_stiffness)


def simulate(hydro, *, mass, length, inertia, damping_coefficient=0.0, torque=None, wave=None,
             t_end, theta0=0.0, omega0=0.0, z0=0.0, zdot0=0.0, history=None, dt=None,
             memory=None, a_inf=None, match_omega=None, g=None):
    """Integrate the buoy's heave and the pendulum together (Cummins' equation).

    Parameters
    ----------
    hydro : Hydro
        The buoy's coefficients; its ``mass`` is the total floating mass, pendulum included.
    mass, length, inertia, damping_coefficient : float
        The pendulum: mass ``m`` (kg, >= 0; 0 leaves the buoy free), distance of its centre
        of mass from the pivot ``l`` (m), inertia about the pivot ``I`` (kg m^2, >= m l^2,
        > 0) and viscous damping ``c`` (N m s).
    torque : callable, optional
        ``tau(t, theta, omega)`` (N m), the generator's torque on the pendulum (harvested
        power ``-tau theta'``); default none.
    wave : callable, optional
        ``F_exc(t)`` (N), the heave excitation force; default none. See
        :func:`regular_wave_force`.
    t_end : float
        Simulated time (s) from ``t = 0``.
    theta0, omega0, z0, zdot0 : float
        The state at ``t = 0`` (rad, rad/s, m, m/s).
    history : callable, optional
        ``zdot(t)`` for ``t < 0`` (vectorized), the heave velocity before the start: the
        radiation memory of a motion that was already going on (e.g. a periodic one to be
        continued). Default: at rest.
    dt : float, optional
        Time step (s); default ``pi / (10 w_max)`` (20 steps per period of the highest
        data frequency), made smaller to divide ``t_end`` evenly.
    memory : float, optional
        Length of the radiation memory (s); default: where ``|K|`` has stayed below
        ``1e-4 K(0)`` for a while, at most 60 s.
    a_inf : float, optional
        Infinite-frequency added mass (kg); default the median of :func:`a_infinity`.
    match_omega : float, optional
        Without ``a_inf``: take ``A_inf`` from the estimate at this frequency (rad/s), so
        that the model's added mass equals the data's there (use the wave's frequency for a
        regular wave; the data's ``A`` and ``B`` are causal only to the BEM's accuracy).
    g : float, optional
        Gravity (m/s^2); default ``hydro.g``.

    Returns
    -------
    dict
        ``t, theta, omega, z, zdot, tau, power`` (arrays at the step points; ``power`` the
        instantaneous harvested power ``-tau theta'``, W), and ``a_inf``, ``a_inf_spread``
        (max - min of the estimates, kg), ``dt``, ``memory``.
    """
    m = check_nonnegative("mass", mass)
    ell = check_nonnegative("length", length)
    inertia = check_positive("inertia", inertia)
    c = check_nonnegative("damping-coefficient", damping_coefficient)
    if inertia < m * ell**2 * (1 - 1e-12):
        raise ParameterError(f"inertia: expected at least m l^2 = {m * ell**2:g} kg m^2, got "
                             f"{inertia!r}")
    if m > hydro.mass:
        raise ParameterError(f"mass: expected at most the floating mass {hydro.mass:g} kg, "
                             f"got {mass!r}")
    t_end = check_positive("t_end", t_end)
    grav = hydro.g if g is None else check_positive("g", g)
    if dt is None:
        dt = math.pi / (10.0 * float(hydro.omega[-1]))
    dt = check_positive("dt", dt)
    n = max(1, math.ceil(t_end / dt - 1e-9))
    dt = t_end / n

    weights, nk = _memory_weights(hydro, dt, memory)
    est = a_infinity(hydro)
    ainf = _a_inf(hydro, a_inf, match_omega, est)
    mtot = hydro.mass + ainf
    cst = hydro.hydrostatic_stiffness
    ml = m * ell
    tau_f = torque if torque is not None else (lambda t, th, om: 0.0)
    fex = wave if wave is not None else (lambda t: 0.0)

    # velocity buffer: vel[j] = zdot at t = (j - nk) dt, j = 0..nk + n
    vel = np.zeros(nk + n + 1)
    if history is not None:
        past = -np.arange(nk, 0, -1) * dt
        vel[:nk] = np.asarray(history(past), dtype=float)
    vel[nk] = zdot0

    def mu_at(i):
        # trapezoid: sum_j w_j zdot(t_i - j dt), i the step index
        seg = vel[i: i + nk + 1][::-1]
        return float(weights @ seg)

    def rhs(t, y, mu):
        z, zd, th, om = y
        s, co = math.sin(th), math.cos(th)
        tau = float(tau_f(t, th, om))
        f1 = -cst * z - mu + float(fex(t)) + ml * co * om * om
        f2 = tau - c * om + ml * grav * s
        a11, a12, a22 = mtot, -ml * s, inertia
        det = a11 * a22 - a12 * a12
        zdd = (a22 * f1 - a12 * f2) / det
        thdd = (a11 * f2 - a12 * f1) / det
        return np.array([zd, zdd, om, thdd])

    ts = np.arange(n + 1) * dt
    ys = np.empty((n + 1, 4))
    ys[0] = (z0, zdot0, theta0, omega0)
    mus = np.empty(n + 1)
    mus[0] = mu_at(0)
    for i in range(n):
        y = ys[i]
        m0 = mus[i]
        m1 = mus[i - 1] if i >= 1 else m0
        m2 = mus[i - 2] if i >= 2 else m1
        d1 = 0.5 * (3 * m0 - 4 * m1 + m2)
        d2 = 0.5 * (m0 - 2 * m1 + m2)

        def mu_ex(theta, m0=m0, d1=d1, d2=d2):
            return m0 + theta * d1 + theta * theta * d2
        t = ts[i]
        k1 = rhs(t, y, m0)
        k2 = rhs(t + 0.5 * dt, y + 0.5 * dt * k1, mu_ex(0.5))
        k3 = rhs(t + 0.5 * dt, y + 0.5 * dt * k2, mu_ex(0.5))
        k4 = rhs(t + dt, y + dt * k3, mu_ex(1.0))
        ys[i + 1] = y + (dt / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)
        vel[nk + i + 1] = ys[i + 1, 1]
        mus[i + 1] = mu_at(i + 1)
    tau = np.array([float(tau_f(t, th, om)) for t, th, om in zip(ts, ys[:, 2], ys[:, 3])])
    return {"t": ts, "theta": ys[:, 2], "omega": ys[:, 3], "z": ys[:, 0], "zdot": ys[:, 1],
            "tau": tau, "power": -tau * ys[:, 3], "a_inf": ainf,
            "a_inf_spread": float(np.ptp(est)), "dt": dt, "memory": nk * dt}
