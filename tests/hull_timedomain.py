"""An independent check of the hull model (surge, heave, pitch with a pendulum):
Cummins' equation in the time domain against the spec's frequency-domain Galerkin equations.

Written from /work/notes/hull_spec.md only (it imports nothing of the package's hull kernel).

The pendulum's angle ``phi(t)`` is prescribed (the generator enforces it), so the pendulum's
equation (P) only gives the torque, and the hull's equation (H), with (P) substituted, is linear
in ``xi = (x, z, beta)`` with a mass matrix that varies with ``phi``::

    M(t) xi'' + int_0^inf K(s) xi'(t - s) ds + C' xi = F_exc(t) + r0(t)
    M(t) = M_h + A_inf + m G^T G - m l e_beta (G^T v(t))^T,    v = (-cos phi, sin phi)
    r0   = -m l G^T ((sin phi)'', (cos phi)'') + e_beta (-I phi'' + m l g sin phi)
    K(t) = (2/pi) int_0^inf B(w) cos(w t) dw           (3 x 3)

Hydrodynamics between and beyond the data as the spec says: linear in ``w`` between data
frequencies; above them ``A`` held, ``B = F = 0``; below them ``A`` held, ``B`` and ``F`` linear
towards ``B(0) = 0``, ``F(0) = C[:, 1]``. ``A`` and ``B`` are symmetrised first.

Radiation kernel and ``A_inf`` (:func:`replay`)
----------------------------------------------
``K(t)`` is the *exact* cosine transform of that piecewise-linear, band-limited ``B`` (closed form
per segment), sampled at the time step ``dt`` and truncated at a memory length ``T_m``; the
memory force is the trapezoidal sum ``mu_n = sum_{j=0..nk} w_j K(j dt) xi'_{n-j}``. Because
``B`` vanishes above ``w_max``, the trapezoidal cosine sum is exact by Poisson summation as long
as ``dt < pi / (w_max + k w)``: the model's damping ``B_td(kw)`` equals the data's up to the
memory truncation alone. Its added mass ``A_td(w) = A_inf - (1/w) sum_j w_j K_j sin(w j dt)``
carries the quadrature's ``+ dt^2 K(0) / 12`` (Euler-Maclaurin: the odd integrand has a kink at
0) and the Kramers-Kronig shift of the band limit; both are nearly constant in ``w``, so
``A_inf`` is chosen to make the *discrete* model exact at the fundamental:
``A_inf = A(w) + (1/w) sum_j w_j K_j sin(w j dt)``. The remaining model error at the other
harmonics is reported (``model_error``) and the model's own coefficients are returned
(``model_coefficients``), so that :func:`harmonic_response` can separate the model's error from
the integrator's. The continuous Kramers-Kronig estimates of ``A_inf`` at every data frequency
(:func:`a_infinity_estimates`) are there for comparison.

Integrator
----------
Newmark's average-acceleration (trapezoidal) rule on the step points, implicit in the current
acceleration (a 3 x 3 solve per step; the current velocity's memory weight ``w_0`` is implicit
too): unconditionally stable, no numerical damping, second order (the steady response of
harmonic ``k`` is off by ``~ (k w dt)^2 / 12``). The excitation and ``r0`` are switched on with a
smooth ramp (``ramp_periods``) so that the surge, which has no stiffness and no damping at zero
frequency, drifts only very slowly; the harmonics are taken from the last period after
removing that drift's linear trend.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["a_infinity_estimates", "harmonic_response", "interpolator", "kernel",
           "phi_fourier", "replay", "synthetic_hull"]

E_BETA = np.array([0.0, 0.0, 1.0])


def _sym(x):
    x = np.asarray(x, dtype=float)
    return 0.5 * (x + np.swapaxes(x, -1, -2))


def _pivot_matrix(pivot):
    d_p, h_p = (float(v) for v in pivot)
    return np.array([[1.0, 0.0, h_p], [0.0, 1.0, -d_p]])


def _corrected_stiffness(C, m, g, pivot):
    cp = np.array(C, dtype=float)
    cp[2, 2] -= m * g * float(pivot[1])
    return cp


def interpolator(omega_data, A, B, F, C):
    """The spec's coefficients at any frequency: ``coef(w) -> (A (3,3), B (3,3), F (3,))``.

    ``A``, ``B`` are symmetrised; linear in ``w`` between data frequencies; above the data
    ``A`` held, ``B = F = 0``; below, ``A`` held and ``B``, ``F`` linear towards ``B(0) = 0``,
    ``F(0) = C[:, 1]``.
    """
    om = np.asarray(omega_data, dtype=float)
    a = _sym(A)
    b = _sym(B)
    f = np.asarray(F, dtype=complex)
    f0 = np.asarray(C, dtype=float)[:, 1].astype(complex)
    wn = np.concatenate(([0.0], om))
    bn = np.concatenate((np.zeros((1, 3, 3)), b))
    fn = np.concatenate((f0[None, :], f))
    an = np.concatenate((a[:1], a))

    def lin(nodes, w):
        i = int(np.clip(np.searchsorted(wn, w, side="right") - 1, 0, wn.size - 2))
        lam = (w - wn[i]) / (wn[i + 1] - wn[i])
        return (1 - lam) * nodes[i] + lam * nodes[i + 1]

    def coef(w):
        w = float(w)
        if w > om[-1]:
            return a[-1].copy(), np.zeros((3, 3)), np.zeros(3, dtype=complex)
        if w == om[-1]:
            return a[-1].copy(), b[-1].copy(), f[-1].copy()
        return lin(an, w), lin(bn, w), lin(fn, w)
    return coef


def kernel(omega_data, B, t):
    """``K(t) = (2/pi) int_0^inf B(w) cos(w t) dw``, shape ``(len(t), 3, 3)``, exact for the
    spec's ``B``: piecewise linear from ``B(0) = 0`` through the (symmetrised) data, zero above.

    Per segment ``int (b0 + s (v - w0)) cos(v t) dv = [b(v) sin(v t) / t + s cos(v t) / t^2]``;
    the ``b sin / t`` terms telescope (``B`` is continuous) but for the jump at ``w_max``.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    wn = np.concatenate(([0.0], np.asarray(omega_data, dtype=float)))
    bn = np.concatenate((np.zeros((1, 3, 3)), _sym(B)))
    slope = (bn[1:] - bn[:-1]) / (wn[1:] - wn[:-1])[:, None, None]
    out = np.empty((t.size, 3, 3))
    zero = t == 0.0
    if np.any(zero):
        out[zero] = np.einsum("i,iab->ab", wn[1:] - wn[:-1], 0.5 * (bn[1:] + bn[:-1]))
    tp = t[~zero]
    if tp.size:
        cosd = (np.cos(np.multiply.outer(tp, wn[1:])) - np.cos(np.multiply.outer(tp, wn[:-1])))
        cosd /= (tp**2)[:, None]
        out[~zero] = (np.einsum("ti,iab->tab", cosd, slope)
                      + (np.sin(wn[-1] * tp) / tp)[:, None, None] * bn[-1])
    return (2.0 / math.pi) * out


def a_infinity_estimates(omega_data, A, B):
    """The continuous Kramers-Kronig estimates ``A(w_i) + (2/pi) PV int B(v) / (w_i^2 - v^2) dv``
    of ``A_inf`` at every data frequency but the last (where the jump of ``B`` makes the
    principal value diverge), exact for the piecewise-linear ``B``; shape ``(n - 1, 3, 3)``."""
    om = np.asarray(omega_data, dtype=float)
    a = _sym(A)
    wn = np.concatenate(([0.0], om))
    bn = np.concatenate((np.zeros((1, 3, 3)), _sym(B)))
    v0, v1 = wn[:-1], wn[1:]
    s = (bn[1:] - bn[:-1]) / (v1 - v0)[:, None, None]
    alpha = bn[:-1] - s * v0[:, None, None]  # b(v) = alpha + s v on each segment
    est = np.empty((om.size - 1, 3, 3))
    for i, w in enumerate(om[:-1]):
        def prim(v, w=w):
            d = np.abs(w - v)
            lm = np.log(d, where=d > 1e-12 * w, out=np.zeros_like(v))
            lp = np.log(w + v)
            return (lp - lm) / (2 * w), -0.5 * (lm + lp)
        p1a, p1s = prim(v1)
        p0a, p0s = prim(v0)
        pv = (np.einsum("i,iab->ab", p1a - p0a, alpha) + np.einsum("i,iab->ab", p1s - p0s, s))
        est[i] = a[i] + (2.0 / math.pi) * pv
    return est


def phi_fourier(x, winding, omega):
    """The spec's pendulum motion ``phi(s) = K s + x[0] + sum_n x[n] sin(n s) + x[N+n] cos(n s)``,
    ``s = omega t``, as a callable ``phi(t) -> (phi, phi', phi'')`` (derivatives in ``t``)."""
    x = np.asarray(x, dtype=float)
    n = (x.size - 1) // 2
    ks = np.arange(1, n + 1)
    a, b = x[1:n + 1], x[n + 1:]

    def phi(t):
        s = omega * np.asarray(t, dtype=float)
        ns = np.multiply.outer(s, ks)
        sn, cs = np.sin(ns), np.cos(ns)
        p = winding * s + x[0] + sn @ a + cs @ b
        d1 = omega * (winding + cs @ (ks * a) - sn @ (ks * b))
        d2 = omega**2 * (-(sn @ (ks**2 * a)) - cs @ (ks**2 * b))
        return p, d1, d2
    return phi


def _pendulum_terms(ph, d1, d2, m, l, I, g, G):  # noqa: E741
    """``r0`` (3, n), the phi-only right-hand side, and ``q = G^T (-cos phi, sin phi)`` (3, n):
    the coupling ``m l e_beta q . xi''`` that (P) puts on the pitch row."""
    sn, cs = np.sin(ph), np.cos(ph)
    sin2 = cs * d2 - sn * d1**2
    cos2 = -sn * d2 - cs * d1**2
    r0 = -m * l * (G.T @ np.vstack([sin2, cos2]))
    r0 = r0 + np.outer(E_BETA, -I * d2 + m * l * g * sn)
    q = G.T @ np.vstack([-cs, sn])
    return r0, q


def harmonic_response(*, C, Mh, m, l, I, c, g, pivot, wave_omega, amplitudes, phi,  # noqa: E741
                      harmonics=12, grid=128, omega_data=None, A=None, B=None, F=None,
                      coefficients=None):
    """The spec's frequency-domain hull response to a prescribed pendulum motion.

    Solves ``Z_k Xi_k = Fa_k + R_k``, k = 0..Nh, on the grid of ``M`` points, all harmonics
    together as one dense real linear system (the pitch row's ``m l (G xi'') . (-cos, sin)``
    couples them); k = 0 only for the DOFs with ``C'[i, i] > 0``.

    Parameters
    ----------
    C : (3, 3) array
        Hydrostatic stiffness *without* the pendulum's correction (``C'[2,2] = C[2,2] - m g h_p``
        is applied here).
    Mh : (3, 3) array
        The hull's mass matrix about O, pendulum excluded.
    m, l, I, c, g : float
        Pendulum mass, centre-of-mass distance, inertia about the pivot, bearing damping; gravity.
    pivot : (d_p, h_p)
    wave_omega : float
        The fundamental ``w`` (rad/s).
    amplitudes : sequence of complex
        ``a_k``, k = 1..Kw: elevation at O ``Re sum a_k exp(i k w t)`` (m).
    phi : callable
        ``phi(t) -> (phi, phi', phi'')`` (arrays), periodic up to ``2 pi K``.
    harmonics, grid : int
        ``Nh`` and ``M``.
    omega_data, A, B, F : arrays
        Frequency data ``(n,)``, ``(n, 3, 3)``, ``(n, 3, 3)``, ``(n, 3)`` complex per metre,
        ``exp(+i w t)``; interpolated as the spec says. Not needed with ``coefficients``.
    coefficients : callable, optional
        ``coefficients(w) -> (A, B, F)`` instead of the data (e.g. a time-domain model's own,
        ``replay(...)["model_coefficients"]``).

    Returns
    -------
    dict
        ``Xi`` (Nh+1, 3) complex, ``power`` (W), ``t``, ``xi``, ``xi_dot``, ``xi_ddot`` (3, M),
        ``tau`` (M,) on the grid, ``energy_residual`` (the spec's balance, absolute, W) and
        ``energy_scale`` (the largest term, W).
    """
    w = float(wave_omega)
    Mh = np.asarray(Mh, dtype=float)
    G = _pivot_matrix(pivot)
    cp = _corrected_stiffness(C, m, g, pivot)
    coef = coefficients if coefficients is not None else interpolator(omega_data, A, B, F, C)
    amps = np.atleast_1d(np.asarray(amplitudes, dtype=complex))
    nh, M = int(harmonics), int(grid)
    s = 2 * math.pi * np.arange(M) / M
    t = s / w
    ph, d1, d2 = (np.asarray(v, dtype=float) for v in phi(t))
    r0, q = _pendulum_terms(ph, d1, d2, m, l, I, g, G)
    ks = np.arange(nh + 1)
    ex = np.exp(1j * np.outer(ks, s))  # (Nh+1, M)
    mass = Mh + m * G.T @ G
    Z, Fa, Bk = [cp.astype(complex)], [np.zeros(3, dtype=complex)], [np.zeros((3, 3))]
    for k in range(1, nh + 1):
        ak, bk, fk = coef(k * w)
        Z.append(-(k * w) ** 2 * (mass + ak) + 1j * k * w * bk + cp)
        Fa.append(fk * amps[k - 1] if k <= amps.size else np.zeros(3, dtype=complex))
        Bk.append(bk)
    sel0 = [i for i in range(3) if cp[i, i] > 0]

    def unpack(u):
        xi = np.zeros((nh + 1, 3), dtype=complex)
        xi[0, sel0] = u[:len(sel0)]
        rest = u[len(sel0):].reshape(nh, 2, 3)
        xi[1:] = rest[:, 0] + 1j * rest[:, 1]
        return xi

    def accel(xi):
        return np.real(((-(ks * w) ** 2)[:, None] * xi).T @ ex)  # (3, M)

    def residual(u):
        xi = unpack(u)
        r = r0 + np.outer(E_BETA, m * l * np.sum(q * accel(xi), axis=0))
        rk = (2.0 / M) * (r @ np.conj(ex).T)  # (3, Nh+1)
        rk[:, 0] = np.mean(r, axis=1)
        out = [(Z[0] @ xi[0] - rk[:, 0])[sel0].real]
        for k in range(1, nh + 1):
            e = Z[k] @ xi[k] - Fa[k] - rk[:, k]
            out += [e.real, e.imag]
        return np.concatenate(out)

    nu = len(sel0) + 6 * nh
    res0 = residual(np.zeros(nu))
    jac = np.empty((nu, nu))
    for i in range(nu):
        e = np.zeros(nu)
        e[i] = 1.0
        jac[:, i] = residual(e) - res0
    xi_k = unpack(np.linalg.solve(jac, -res0))

    xi = np.real(xi_k.T @ ex)
    xid = np.real((1j * (ks * w)[:, None] * xi_k).T @ ex)
    xidd = accel(xi_k)
    pdd = G @ xidd
    rel = d1 - xid[2]
    tau = I * d2 + c * rel - m * l * ((g + pdd[1]) * np.sin(ph) - pdd[0] * np.cos(ph))
    power = float(-np.mean(tau * rel))
    terms = []
    for k in range(1, nh + 1):
        u = 1j * k * w * xi_k[k]
        terms += [np.real(np.vdot(Fa[k], u)) / 2, -np.real(np.vdot(u, Bk[k] @ u)) / 2]
    lhs = power + c * float(np.mean(rel**2))
    scale = max(abs(power), c * float(np.mean(rel**2)), *(abs(v) for v in terms))
    return {"Xi": xi_k, "power": power, "t": t, "xi": xi, "xi_dot": xid, "xi_ddot": xidd,
            "tau": tau, "energy_residual": float(lhs - sum(terms)), "energy_scale": scale}


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (10 - 15 * x + 6 * x * x)


def replay(*, omega_data, A, B, F, C, Mh, m, l, I, c, g, pivot, wave_omega, amplitudes, phi,  # noqa: E741
           periods=60, steps_per_period=200, ramp_periods=10, memory=None, a_inf=None,
           harmonics=6, kernel_tol=1e-4, max_memory=60.0, match_omega=None):
    """Integrate the hull (H) with the prescribed ``phi`` from rest (Cummins) until periodic.

    Parameters
    ----------
    omega_data, A, B, F, C, Mh, m, l, I, c, g, pivot, wave_omega, amplitudes, phi
        As :func:`harmonic_response` (``C`` without the pendulum's correction).
    periods : int
        Simulated wave periods (from rest; the excitation is ramped in over ``ramp_periods``).
    steps_per_period : int
        Time steps per wave period: ``dt = 2 pi / (w steps_per_period)``. Must keep
        ``dt < pi / (w_max + harmonics w)`` for the band-limited kernel to be sampled exactly.
    ramp_periods : float
        Length of the smooth (C^2) ramp on the excitation and the pendulum's forcing.
    memory : float, optional
        Length of the radiation memory (s). Default: up to where every entry of ``|K|`` has
        stayed below ``kernel_tol * max|K(0)|``, times 1.2, at most ``max_memory``.
    a_inf : (3, 3) array, optional
        Infinite-frequency added mass. Default: the value that makes the discrete model's
        added mass equal the data's at ``match_omega`` (see the module's docstring).
    harmonics : int
        How many harmonics of the last period to return.
    match_omega : float, optional
        Where the model's added mass is made the data's (rad/s; default the fundamental
        ``wave_omega``; an irregular record's peak frequency, where its energy is).

    Returns
    -------
    dict
        ``t`` (n,), ``xi``, ``xi_dot``, ``xi_ddot`` (n, 3), ``tau`` (n,): the last period,
        one sample per step (``n = steps_per_period``; a mean is a plain mean);
        ``Xi`` (harmonics+1, 3) complex, the last period's harmonics (surge's mean set to 0,
        as in the spec, and every DOF's linear drift removed first); ``power`` (W), the
        mean of ``-tau (phi' - beta')`` over the last period; ``surge_drift`` (m/s), the mean
        surge velocity; ``periodicity``, ``max |xi'(last period) - xi'(period before)| /
        max |xi'|``; ``dt``, ``memory`` (s), ``a_inf`` (3, 3), ``model_coefficients``
        (``w -> (A_td, B_td, F)``, the discrete model's own hydrodynamics) and
        ``model_error`` (the largest ``|A_td - A| w^2 + |B_td - B| w`` relative to
        ``|Z(w)|`` over the returned harmonics inside the data).
    """
    w = float(wave_omega)
    period = 2 * math.pi / w
    spp = int(steps_per_period)
    dt = period / spp
    nsteps = int(periods) * spp
    if int(periods) < 2:
        raise ValueError(f"periods: expected at least 2, got {periods!r}")
    Mh = np.asarray(Mh, dtype=float)
    G = _pivot_matrix(pivot)
    cp = _corrected_stiffness(C, m, g, pivot)
    coef = interpolator(omega_data, A, B, F, C)
    om = np.asarray(omega_data, dtype=float)
    if dt >= math.pi / (om[-1] + harmonics * w):
        raise ValueError(f"steps_per_period: expected dt < pi / (w_max + harmonics w), got "
                         f"dt = {dt:g} s")

    # radiation memory
    if memory is None:
        tk = np.arange(0.0, max_memory + dt / 2, dt)
        kk = kernel(om, B, tk)
        size = np.max(np.abs(kk), axis=(1, 2))
        big = np.nonzero(size > kernel_tol * size[0])[0]
        last = int(big[-1]) if big.size else 0
        nk = min(tk.size - 1, max(2, int(1.2 * last) + 2))
        kk = kk[:nk + 1]
    else:
        nk = max(2, math.ceil(float(memory) / dt))
        kk = kernel(om, B, np.arange(nk + 1) * dt)
    wts = dt * kk
    wts[0] *= 0.5
    wts[-1] *= 0.5
    lags = np.arange(nk + 1) * dt

    def transforms(wv):
        cs, sn = np.cos(wv * lags), np.sin(wv * lags)
        return np.einsum("j,jab->ab", cs, wts), np.einsum("j,jab->ab", sn, wts)

    if a_inf is None:
        wm = w if match_omega is None else float(match_omega)
        a1, _, _ = coef(wm)
        a_inf = a1 + transforms(wm)[1] / wm
    a_inf = np.asarray(a_inf, dtype=float)

    def model_coefficients(wv):
        kc, ks = transforms(float(wv))
        _, _, fk = coef(wv)
        return a_inf - ks / wv, kc, fk

    err = 0.0
    for k in range(1, harmonics + 1):
        if k * w > om[-1]:
            break
        ad, bd, _ = coef(k * w)
        am, bm, _ = model_coefficients(k * w)
        z = -(k * w) ** 2 * (Mh + ad + m * G.T @ G) + 1j * k * w * bd + cp
        diff = (k * w) ** 2 * np.linalg.norm(am - ad, 2) + k * w * np.linalg.norm(bm - bd, 2)
        err = max(err, diff / np.linalg.norm(z, 2))

    # forcing and mass matrices at every step point
    t = np.arange(nsteps + 1) * dt
    ph, d1, d2 = (np.asarray(v, dtype=float) for v in phi(t))
    r0, q = _pendulum_terms(ph, d1, d2, m, l, I, g, G)
    amps = np.atleast_1d(np.asarray(amplitudes, dtype=complex))
    fex = np.zeros((3, t.size))
    for k, ak in enumerate(amps, start=1):
        fk = coef(k * w)[2]
        fex += np.real(np.outer(fk * ak, np.exp(1j * k * w * t)))
    force = (_smoothstep(t / (ramp_periods * period)) * (fex + r0)).T  # (n+1, 3)
    mass = Mh + a_inf + m * G.T @ G
    mt = mass[None] - m * l * np.einsum("a,tb->tab", E_BETA, q.T)
    sinv = np.linalg.inv(mt + 0.5 * dt * wts[0] + 0.25 * dt * dt * cp)

    # Newmark average acceleration; vel[nk + n] = xi'_n (zero before t = 0)
    x = np.zeros((nsteps + 1, 3))
    vel = np.zeros((nk + nsteps + 1, 3))
    acc = np.zeros((nsteps + 1, 3))
    acc[0] = np.linalg.solve(mt[0], force[0])
    wflat = wts[nk:0:-1].transpose(1, 0, 2).reshape(3, 3 * nk)
    w0 = wts[0]
    # C' px + w_0 pv with the predictors px = x + dt v + dt^2/4 a, pv = v + dt/2 a
    qmat = np.hstack([cp, dt * cp + w0, 0.25 * dt * dt * cp + 0.5 * dt * w0])
    for n in range(nsteps):
        xn, vn, an = x[n], vel[nk + n], acc[n]
        hist = wflat @ vel[n + 1:n + 1 + nk].ravel()
        a_new = sinv[n + 1] @ (force[n + 1] - hist - qmat @ np.concatenate((xn, vn, an)))
        acc[n + 1] = a_new
        vel[nk + n + 1] = vn + (0.5 * dt) * (an + a_new)
        x[n + 1] = xn + dt * vn + (0.25 * dt * dt) * (an + a_new)
    v = vel[nk:]

    last = slice(nsteps - spp, nsteps)
    prev = slice(nsteps - 2 * spp, nsteps - spp)
    tl = t[last]
    drift = (x[nsteps] - x[nsteps - spp]) / period  # the mean velocity over the last period
    xd = x[last] - np.outer(tl - tl[0], drift)
    ex = np.exp(-1j * np.outer(np.arange(harmonics + 1) * w, tl))  # (H+1, n)
    xi_k = (2.0 / spp) * ex @ xd
    xi_k[0] = np.mean(x[last], axis=0)
    xi_k[0, 0] = 0.0
    pdd = acc[last] @ G.T
    rel = d1[last] - v[last, 2]
    tau = (I * d2[last] + c * rel
           - m * l * ((g + pdd[:, 1]) * np.sin(ph[last]) - pdd[:, 0] * np.cos(ph[last])))
    vscale = np.max(np.abs(v[last]))
    return {"t": tl, "xi": x[last], "xi_dot": v[last], "xi_ddot": acc[last], "tau": tau,
            "Xi": xi_k, "power": float(-np.mean(tau * rel)), "surge_drift": float(drift[0]),
            "periodicity": float(np.max(np.abs(v[last] - v[prev])) / vscale),
            "dt": dt, "memory": nk * dt, "a_inf": a_inf,
            "model_coefficients": model_coefficients, "model_error": err}


# --- a synthetic hull: exactly causal radiation, magnitudes of a 10 x 4 x 1 m box barge -----

RHO_V = 1025.0 * 40.0
# radiation transfer function H(s) = sum_r R_r k_r s / (s^2 + 2 zeta_r w_r s + w_r^2):
# B(w) = Re H(i w) >= 0 (PSD), A(w) = A_inf + Im H(i w) / w, K(t) in closed form
_MODES = (
    # (R_r, k_r, zeta_r, w_r): heave; surge-pitch coupled; pitch
    (np.diag([0.0, 1.0, 0.0]), 1.25e5, 0.5, 2.5),
    (np.outer([1.0, 0.0, -0.8], [1.0, 0.0, -0.8]), 1.6e4, 0.4, 2.0),
    (np.diag([0.0, 0.0, 1.0]), 7.5e5, 0.5, 2.5),
)
A_INF = np.array([[4.0e3, 0.0, -2.0e3], [0.0, 3.0e4, 0.0], [-2.0e3, 0.0, 2.0e5]])
C_HULL = np.array([[0.0, 0.0, 0.0], [0.0, 1025.0 * 9.81 * 40.0, 2.0e4],
                   [0.0, 2.0e4, 3.1e6]])


def synthetic_exact(w):
    """Exact ``A (n,3,3), B (n,3,3), F (n,3)`` of the synthetic hull at ``w`` (rad/s, > 0)."""
    w = np.atleast_1d(np.asarray(w, dtype=float))
    a = np.broadcast_to(A_INF, (w.size, 3, 3)).copy()
    b = np.zeros((w.size, 3, 3))
    for r, k, z, w0 in _MODES:
        h = k * 1j * w / (w0**2 - w**2 + 2j * z * w0 * w)
        a += np.multiply.outer(h.imag / w, r)
        b += np.multiply.outer(h.real, r)
    f = np.empty((w.size, 3), dtype=complex)
    f[:, 0] = 1j * 8.0e4 * w * np.exp(-0.15 * w * w)
    f[:, 1] = C_HULL[1, 1] * np.exp(-0.1 * w * w) * np.exp(-0.3j * w)
    f[:, 2] = C_HULL[2, 1] * np.exp(-0.1 * w * w) + 1.5e5j * w * np.exp(-0.1 * w * w)
    return a, b, f


def synthetic_kernel(t):
    """The exact (untruncated) ``K(t)`` of the synthetic hull, shape ``(len(t), 3, 3)``."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((t.size, 3, 3))
    for r, k, z, w0 in _MODES:
        wd = w0 * math.sqrt(1 - z * z)
        kt = k * np.exp(-z * w0 * t) * (np.cos(wd * t) - z * w0 / wd * np.sin(wd * t))
        out += np.multiply.outer(kt, r)
    return out


def synthetic_hull(n=300, w_min=0.1, w_max=25.0, m=4000.0, l=1.0, I=5000.0, c=50.0,  # noqa: E741
                   pivot=(1.0, 1.5)):
    """Keyword arguments for :func:`replay` / :func:`harmonic_response` (all but the wave and
    ``phi``): the synthetic hull sampled on ``n`` frequencies in ``[w_min, w_max]`` (its
    cut-off), with a 4 t pendulum on a pivot 1.5 m above and 1 m ahead of O."""
    om = np.linspace(w_min, w_max, n)
    a, b, f = synthetic_exact(om)
    mh = np.diag([RHO_V - m, RHO_V - m, 3.4e5])
    return {"omega_data": om, "A": a, "B": b, "F": f, "C": C_HULL.copy(), "Mh": mh, "m": m,
            "l": l, "I": I, "c": c, "g": 9.81, "pivot": pivot}


def synthetic_hull_netcdf(path) -> str:
    """:func:`synthetic_hull` as a Capytaine NetCDF dataset with surge, heave and pitch (the
    tests' hull ``--hydro`` file), written to ``path``; returns the path as text."""
    from capytaine.io.xarray import save_dataset_as_netcdf

    from parapend.hydro.bem import HullHydro

    h = synthetic_hull()
    hull = HullHydro(omega=h["omega_data"], added_mass=h["A"], radiation_damping=h["B"],
                     excitation=h["F"], hydrostatic_stiffness=h["C"], mass=RHO_V,
                     pitch_inertia=float(h["Mh"][2, 2]), description="synthetic hull")
    save_dataset_as_netcdf(path, hull.to_dataset())
    return str(path)
