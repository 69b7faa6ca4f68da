"""Compiled (numba) kernel of the buoy's closed loop (:mod:`.control`): the coupled heave and
pendulum of :mod:`.timedomain` (Cummins' equation with the radiation memory), advanced by
the same scheme (RK4 on a fixed step ``h``, the memory a trapezoidal sum over the stored
heave velocity, extrapolated quadratically inside a step), the torque held over each sample
of ``steps`` steps.

State ``y = (z, z', theta, theta')`` in SI units. ``vel[k0 + j]``, ``j = 0..nk``, is the heave
velocity at ``t - (nk - j) h`` (``t`` the current time); :func:`advance` appends the new
velocities after it. ``mus = (mu(t), mu(t - h), mu(t - 2 h))`` (updated in place).
``p = (M + A_inf, C, m l, I, c, g)``.
"""

from __future__ import annotations

import math

import numba as nb

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)


@nb.njit(cache=True)
def _rhs(z, zd, th, om, mu, f, tau, p):
    """``(z'', theta'')`` from the 2x2 mass matrix (module docstring of :mod:`.timedomain`)."""
    mtot, cst, ml, inertia, c, g = p[0], p[1], p[2], p[3], p[4], p[5]
    s = math.sin(th)
    co = math.cos(th)
    f1 = -cst * z - mu + f + ml * co * om * om
    f2 = tau - c * om + ml * g * s
    a12 = -ml * s
    det = mtot * inertia - a12 * a12
    return (inertia * f1 - a12 * f2) / det, (mtot * f2 - a12 * f1) / det


@nb.njit(cache=True)
def advance(y, vel, k0, mus, u, steps, fn, h, w, p, ys, zdd, acc, mun):
    """Advance ``y`` over ``len(u)`` held torques (N m) of ``steps`` RK4 steps of ``h``.

    ``fn``: the excitation force (N) at the half-step nodes (``2 len(u) steps + 1``).
    On exit ``ys[k]`` is the state after ``k`` samples (``ys[0]`` the start), ``zdd`` the
    heave acceleration at the half-step nodes (the step's start: the exact ``z''`` there with
    the step's torque; the midpoint: the mean of the two middle stages; the last node: the
    end state with the last torque), and ``acc`` accumulates the RK4 quadratures of the
    power the buoy absorbs, ``(F - mu) z'`` (``acc[0]``), of the damping ``c theta'^2``
    (``acc[1]``) and the exact work of the held torque ``-tau (theta_1 - theta_0)``
    (``acc[2]``), all in J; ``mun`` the memory force (N) the step used at the nodes (the
    extrapolated value at the midpoints). Returns False if the state left ``|theta'| < 1e6``.
    """
    nk = w.size - 1
    z, zd, th, om = y[0], y[1], y[2], y[3]
    m0, m1, m2 = mus[0], mus[1], mus[2]
    c = p[4]
    ys[0, 0], ys[0, 1], ys[0, 2], ys[0, 3] = z, zd, th, om
    n = u.size
    ok = True
    for j in range(n):
        tau = u[j]
        for s in range(steps):
            i = j * steps + s
            d1 = 0.5 * (3.0 * m0 - 4.0 * m1 + m2)
            d2 = 0.5 * (m0 - 2.0 * m1 + m2)
            mh = m0 + 0.5 * d1 + 0.25 * d2
            me = m0 + d1 + d2
            f0 = fn[2 * i]
            fm = fn[2 * i + 1]
            f1 = fn[2 * i + 2]
            a1, b1 = _rhs(z, zd, th, om, m0, f0, tau, p)
            z2 = z + 0.5 * h * zd
            zd2 = zd + 0.5 * h * a1
            th2 = th + 0.5 * h * om
            om2 = om + 0.5 * h * b1
            a2, b2 = _rhs(z2, zd2, th2, om2, mh, fm, tau, p)
            z3 = z + 0.5 * h * zd2
            zd3 = zd + 0.5 * h * a2
            th3 = th + 0.5 * h * om2
            om3 = om + 0.5 * h * b2
            a3, b3 = _rhs(z3, zd3, th3, om3, mh, fm, tau, p)
            z4 = z + h * zd3
            zd4 = zd + h * a3
            th4 = th + h * om3
            om4 = om + h * b3
            a4, b4 = _rhs(z4, zd4, th4, om4, me, f1, tau, p)
            zdd[2 * i] = a1
            mun[2 * i] = m0
            mun[2 * i + 1] = mh
            zdd[2 * i + 1] = 0.5 * (a2 + a3)
            acc[0] += h / 6.0 * ((f0 - m0) * zd + 2.0 * (fm - mh) * (zd2 + zd3)
                                 + (f1 - me) * zd4)
            acc[1] += h / 6.0 * c * (om * om + 2.0 * om2 * om2 + 2.0 * om3 * om3
                                     + om4 * om4)
            thn = th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4)
            acc[2] -= tau * (thn - th)
            z = z + h / 6.0 * (zd + 2.0 * zd2 + 2.0 * zd3 + zd4)
            zd = zd + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
            om = om + h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
            th = thn
            # the memory at the new step point: trapezoid over the stored velocity
            e = k0 + nk + i + 1
            vel[e] = zd
            mu = 0.0
            for q in range(nk + 1):
                mu += w[q] * vel[e - q]
            m2 = m1
            m1 = m0
            m0 = mu
        ys[j + 1, 0], ys[j + 1, 1], ys[j + 1, 2], ys[j + 1, 3] = z, zd, th, om
        if not abs(om) < 1e6:
            ok = False
            break
    if ok and n > 0:
        a_end, _ = _rhs(z, zd, th, om, m0, fn[2 * n * steps], u[n - 1], p)
        zdd[2 * n * steps] = a_end
        mun[2 * n * steps] = m0
    y[0], y[1], y[2], y[3] = z, zd, th, om
    mus[0], mus[1], mus[2] = m0, m1, m2
    return ok


@nb.njit(cache=True)
def _rhs_jac(z, th, om, fnet, tau, p):
    """``z''``, ``theta''`` of the planning model (the memory frozen in ``fnet = F - mu``) and
    their derivatives with respect to ``z, theta, theta', tau`` (none on ``z'``)."""
    mtot, cst, ml, inertia, c, g = p[0], p[1], p[2], p[3], p[4], p[5]
    s = math.sin(th)
    co = math.cos(th)
    f1 = -cst * z + fnet + ml * co * om * om
    f2 = tau - c * om + ml * g * s
    a = -ml * s
    det = mtot * inertia - a * a
    zdd = (inertia * f1 - a * f2) / det
    thdd = (mtot * f2 - a * f1) / det
    zdd_z = -inertia * cst / det
    thdd_z = a * cst / det
    f1_om = 2.0 * ml * co * om
    zdd_om = (inertia * f1_om + a * c) / det
    thdd_om = (-mtot * c - a * f1_om) / det
    zdd_tau = -a / det
    thdd_tau = mtot / det
    f1_th = -ml * s * om * om
    f2_th = ml * g * co
    a_th = -ml * co
    det_th = -2.0 * a * a_th
    zdd_th = (inertia * f1_th - a_th * f2 - a * f2_th - zdd * det_th) / det
    thdd_th = (mtot * f2_th - a_th * f1 - a * f1_th - thdd * det_th) / det
    return (zdd, thdd, zdd_z, zdd_th, zdd_om, zdd_tau, thdd_z, thdd_th, thdd_om, thdd_tau)


@nb.njit(cache=True)
def _stage_adjoint(z, th, om, fnet, tau, p, g0, g1, g2, g3):
    """``J^T g`` of the state derivative ``(z', z'', theta', theta'')`` at a stage, and its
    derivative with respect to ``tau``."""
    r = _rhs_jac(z, th, om, fnet, tau, p)
    rz = g1 * r[2] + g3 * r[6]
    rzd = g0
    rth = g1 * r[3] + g3 * r[7]
    rom = g2 + g1 * r[4] + g3 * r[8]
    rtau = g1 * r[5] + g3 * r[9]
    return rz, rzd, rth, rom, rtau


@nb.njit(cache=True)
def _stages(z, zd, th, om, f0, fm, tau, p, h):
    """The first three RK4 stages of one step from ``(z, z', theta, theta')`` (the forcing
    ``f0`` at its start, ``fm`` at its middle): each stage's derivatives (``_rhs_jac``) and
    the states of stages 2 to 4, shared by the forward pass and the adjoint's recomputation."""
    r1 = _rhs_jac(z, th, om, f0, tau, p)
    z2 = z + 0.5 * h * zd
    zd2 = zd + 0.5 * h * r1[0]
    th2 = th + 0.5 * h * om
    om2 = om + 0.5 * h * r1[1]
    r2 = _rhs_jac(z2, th2, om2, fm, tau, p)
    z3 = z + 0.5 * h * zd2
    zd3 = zd + 0.5 * h * r2[0]
    th3 = th + 0.5 * h * om2
    om3 = om + 0.5 * h * r2[1]
    r3 = _rhs_jac(z3, th3, om3, fm, tau, p)
    z4 = z + h * zd3
    zd4 = zd + h * r3[0]
    th4 = th + h * om3
    om4 = om + h * r3[1]
    return r1, z2, zd2, th2, om2, r2, z3, zd3, th3, om3, r3, z4, zd4, th4, om4


@nb.njit(cache=True)
def _gather(a, k, c, gz, gzd, gth, gom, gt):
    """One stage adjoint ``a`` added to the gradient sums, and ``c a`` to the previous stage's
    adjoint ``k`` (in place); returns the sums."""
    k[0] += c * a[0]
    k[1] += c * a[1]
    k[2] += c * a[2]
    k[3] += c * a[3]
    return gz + a[0], gzd + a[1], gth + a[2], gom + a[3], gt + a[4]


@nb.njit(cache=True)
def plan_objective(u, y0, fnet, h, steps, p, tu, eta_g, eta_m, kappa, ref, total, grad, ys):
    """The coupled horizon problem: minus the harvested work of the held torques ``u tu``
    (N m) over ``steps`` RK4 steps each (through the efficiency weights), minus ``kappa``
    times the mechanical energy of buoy and pendulum at the end (``E`` of
    :meth:`parapend.hydro.control._Plant.energy`), in units of ``tu = m g l``; the heave and
    the pendulum coupled, the memory force frozen in ``fnet`` (``F - mu`` at the half-step
    nodes); the buoy's energy counted from the end state ``ref = (z, z')`` of a reference
    plan (a constant, for precision); ``total = 0``: the pendulum's energy
    ``I theta'^2 / 2 + m g l cos(theta)`` alone. Exact gradient by the adjoint of the RK4
    steps; ``ys`` (``len(u) steps + 1`` x 4) the step states."""
    n = u.size
    ml, inertia, g = p[2], p[3], p[5]
    ys[0, 0], ys[0, 1], ys[0, 2], ys[0, 3] = y0[0], y0[1], y0[2], y0[3]
    f = 0.0
    for j in range(n):
        tau = u[j] * tu
        for s in range(steps):
            i = j * steps + s
            z, zd, th, om = ys[i, 0], ys[i, 1], ys[i, 2], ys[i, 3]
            f0 = fnet[2 * i]
            fm = fnet[2 * i + 1]
            f1 = fnet[2 * i + 2]
            (r1, z2, zd2, th2, om2, r2, z3, zd3, th3, om3, r3,
             z4, zd4, th4, om4) = _stages(z, zd, th, om, f0, fm, tau, p, h)
            r4 = _rhs_jac(z4, th4, om4, f1, tau, p)
            ys[i + 1, 0] = z + h / 6.0 * (zd + 2.0 * zd2 + 2.0 * zd3 + zd4)
            ys[i + 1, 1] = zd + h / 6.0 * (r1[0] + 2.0 * r2[0] + 2.0 * r3[0] + r4[0])
            ys[i + 1, 2] = th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4)
            ys[i + 1, 3] = om + h / 6.0 * (r1[1] + 2.0 * r2[1] + 2.0 * r3[1] + r4[1])
            pw = -u[j] * (ys[i + 1, 2] - th)
            f -= eta_g * pw if pw > 0.0 else pw / eta_m
    m = n * steps
    mtot, cst = p[0], p[1]
    zm, zdm, thm, omm = ys[m, 0], ys[m, 1], ys[m, 2], ys[m, 3]
    sm, cm = math.sin(thm), math.cos(thm)
    # the buoy's part relative to the reference end state ``ref = (z, z')`` (a constant),
    # as differences of squares: its dependence on u is O(m / M) of its size
    zr, zdr = ref[0], ref[1]
    f -= kappa * (total * (0.5 * mtot * (zdm - zdr) * (zdm + zdr) - ml * sm * zdm * omm
                           + 0.5 * cst * (zm - zr) * (zm + zr))
                  + 0.5 * inertia * omm * omm + ml * g * cm) / tu
    lz = -kappa * total * cst * zm / tu
    lzd = -kappa * total * (mtot * zdm - ml * sm * omm) / tu
    lth = -kappa * (-total * ml * cm * zdm * omm - ml * g * sm) / tu
    lom = -kappa * (-total * ml * sm * zdm + inertia * omm) / tu
    for j in range(n - 1, -1, -1):
        tau = u[j] * tu
        gj = 0.0
        for s in range(steps - 1, -1, -1):
            i = j * steps + s
            z, zd, th, om = ys[i, 0], ys[i, 1], ys[i, 2], ys[i, 3]
            dth = ys[i + 1, 2] - th
            pw = -u[j] * dth
            wgt = eta_g if pw > 0.0 else 1.0 / eta_m
            gj += wgt * dth
            lth += wgt * u[j]
            f0 = fnet[2 * i]
            fm = fnet[2 * i + 1]
            f1 = fnet[2 * i + 2]
            # recompute the stages
            (r1, z2, zd2, th2, om2, r2, z3, zd3, th3, om3, r3,
             z4, _, th4, om4) = _stages(z, zd, th, om, f0, fm, tau, p, h)
            # adjoints of the stage derivatives k1..k4
            c6 = h / 6.0
            c3 = h / 3.0
            k4 = (c6 * lz, c6 * lzd, c6 * lth, c6 * lom)
            k3 = [c3 * lz, c3 * lzd, c3 * lth, c3 * lom]
            k2 = [c3 * lz, c3 * lzd, c3 * lth, c3 * lom]
            k1 = [c6 * lz, c6 * lzd, c6 * lth, c6 * lom]
            gz, gzd, gth, gom = lz, lzd, lth, lom
            gt = 0.0
            # each stage's adjoint into the state's gradient, and back into the stage before
            # (k3 += h a, k2 += h/2 a, k1 += h/2 a: the RK4 stage weights)
            a = _stage_adjoint(z4, th4, om4, f1, tau, p, k4[0], k4[1], k4[2], k4[3])
            gz, gzd, gth, gom, gt = _gather(a, k3, h, gz, gzd, gth, gom, gt)
            a = _stage_adjoint(z3, th3, om3, fm, tau, p, k3[0], k3[1], k3[2], k3[3])
            gz, gzd, gth, gom, gt = _gather(a, k2, 0.5 * h, gz, gzd, gth, gom, gt)
            a = _stage_adjoint(z2, th2, om2, fm, tau, p, k2[0], k2[1], k2[2], k2[3])
            gz, gzd, gth, gom, gt = _gather(a, k1, 0.5 * h, gz, gzd, gth, gom, gt)
            a = _stage_adjoint(z, th, om, f0, tau, p, k1[0], k1[1], k1[2], k1[3])
            gz, gzd, gth, gom, gt = gz + a[0], gzd + a[1], gth + a[2], gom + a[3], gt + a[4]
            lz, lzd, lom = gz, gzd, gom
            lth = gth - wgt * u[j]
            gj += gt * tu
        grad[j] = gj
    return f
