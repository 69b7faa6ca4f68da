"""Independent time-domain checks of the hull (surge, heave, pitch) with its pendulum, for
irregular records and for saved torque series: test code of its own (it imports nothing of
the package's hull kernel nor of its time-domain plant).

Model (docs/hull.md; ``phi`` the pendulum's absolute angle from the upward vertical, its centre
of mass at ``p + l (sin phi, cos phi)``, the pivot at ``(d_p, h_p)`` from O moving by
``p = G xi``, ``G = [[1, 0, h_p], [0, 1, -d_p]]``, ``xi = (x, z, beta)``, ``exp(+i w t)``)::

    (P)  I phi'' + c (phi' - beta') - m l [(g + p_z'') sin phi - p_x'' cos phi] = tau
    (H)  (M_h + A_inf) xi'' + mu(t) + C' xi = F_exc(t) - G^T f + e_beta (-tau + c (phi' - beta'))
         f = m (p'' + l ((sin phi)'', (cos phi)'')),   mu(t) = int_0^L K(s) xi'(t - s) ds

``C' = C - m g h_p e_beta e_beta^T`` and ``K(t) = (2/pi) int_0^inf B(w) cos(w t) dw``, ``B``
piecewise linear from ``B(0) = 0`` through the (symmetrised) data and zero above it, in
closed form (:func:`hull_timedomain.kernel`). Written out, (P) and (H) are

    [[M_h + A_inf + m G^T G, m l u], [m l u^T, I]] (xi'', phi'')
        = (F_exc - mu - C' xi + m l G^T (sin phi, cos phi) phi'^2 + e_beta (-tau + c v),
           tau - c v + m l g sin phi),           u = G^T (cos phi, -sin phi),  v = phi' - beta'

a symmetric mass matrix: the mechanical energy ``E = 1/2 xi'^T (M_h + A_inf + m G^T G) xi' +
m l phi' u . xi' + 1/2 I phi'^2 + 1/2 xi^T C' xi + m g l cos phi`` changes by
``dE/dt = (F_exc - mu) . xi' + tau v - c v^2``: the generator harvests ``-tau v``.

Two checks:

- :func:`record_replay`: a record optimum's pendulum motion ``phi(t)`` prescribed, the hull
  integrated from rest by :func:`hull_timedomain.replay` (Newmark, the memory a trapezoidal
  sum of the exact kernel) over several repeats of the record until periodic, and the last
  repeat compared with the frequency domain's hull motion and mean power.
- :func:`reintegrate_hull`: a torque series ``tau(t)`` (held per sample, as a controller
  applies it, or a function of time) integrated with the nonlinear pendulum and the hull,
  sample by sample with scipy's DOP853; the memory a direct convolution (Gauss-Legendre on
  the integration's own past, exact truncation at ``L``; :class:`Memory`).
"""

from __future__ import annotations

import math

import numpy as np
from hull_timedomain import interpolator, kernel, phi_fourier, replay
from scipy.integrate import solve_ivp

__all__ = ["Memory", "chunked", "compare_motion", "hull_data", "matched_a_inf", "memory_length",
           "record_replay", "reintegrate_hull"]

E_BETA = np.array([0.0, 0.0, 1.0])


def _pivot_matrix(pivot):
    d_p, h_p = (float(v) for v in pivot)
    return np.array([[1.0, 0.0, h_p], [0.0, 1.0, -d_p]])


def _p(pendulum, name):
    return float(pendulum[name] if isinstance(pendulum, dict) else getattr(pendulum, name))


def hull_data(hull, pendulum_mass, pitch_inertia=None) -> dict:
    """The hydrodynamic data of a :class:`parapend.hydro.bem.HullHydro` as plain arrays:
    ``omega`` (n,), ``A``, ``B`` (n, 3, 3), ``F`` (n, 3) complex (``exp(+i w t)``, per metre),
    ``C`` (3, 3) without the pendulum's correction, ``Mh = diag(rho V - m, rho V - m, I_h)``
    (the hull without the pendulum: hull and pendulum float at the draft), ``g``."""
    ih = float(hull.pitch_inertia if pitch_inertia is None else pitch_inertia)
    mh = np.diag([float(hull.mass) - pendulum_mass, float(hull.mass) - pendulum_mass, ih])
    return {"omega": np.asarray(hull.omega, float), "A": np.asarray(hull.added_mass, float),
            "B": np.asarray(hull.radiation_damping, float),
            "F": np.asarray(hull.excitation, complex),
            "C": np.asarray(hull.hydrostatic_stiffness, float), "Mh": mh, "g": float(hull.g)}


# --- 1. a record optimum's phi prescribed: the hull's motion and the mean power ----------------

def record_replay(data, pendulum, pivot, omega, amplitudes, x, winding, *, repeats=None,
                  ramp=None, dt=0.01, match_omega=None, **kw) -> dict:
    """Cummins' equation driven by a periodic record's optimal ``phi`` from rest.

    Parameters
    ----------
    data : dict
        :func:`hull_data`'s arrays.
    pendulum : object or dict
        ``mass``, ``length``, ``inertia``, ``damping_coefficient`` (SI).
    pivot : (d_p, h_p)
    omega : float
        The record's fundamental ``2 pi / T_r`` (rad/s).
    amplitudes : (Kw,) complex
        The record's elevation at O, ``Re sum_k a_k exp(i k omega t)`` (m).
    x, winding : the optimum's ``phi`` coefficients (:func:`hull_timedomain.phi_fourier`)
        and its turns per record.
    repeats, ramp : int, float
        Repeats of the record integrated from rest, and the length (repeats) of the smooth
        ramp on the forcing. Default: enough for 100 s of ramp and 100 s of settling, at
        least 2 and 0.2.
    dt : float
        Time step (s), rounded to divide the record.
    match_omega : float
        Where the model's added mass is made the data's (default the record's peak).

    Returns
    -------
    dict
        :func:`hull_timedomain.replay`'s result over the last repeat (``t``, ``xi``,
        ``xi_dot``, ``power``, ``periodicity``, ``surge_drift``, ``model_error``...).
    """
    period = 2 * math.pi / omega
    if ramp is None:
        ramp = max(0.2, 100.0 / period)
    if repeats is None:
        repeats = max(2, math.ceil(ramp + 100.0 / period) + 1)
    amps = np.asarray(amplitudes, dtype=complex)
    if match_omega is None:
        match_omega = omega * (int(np.argmax(np.abs(amps))) + 1)
    spp = max(2, math.ceil(period / dt))
    return replay(omega_data=data["omega"], A=data["A"], B=data["B"], F=data["F"],
                  C=data["C"], Mh=data["Mh"], m=_p(pendulum, "mass"), l=_p(pendulum, "length"),
                  I=_p(pendulum, "inertia"), c=_p(pendulum, "damping_coefficient"),
                  g=data["g"], pivot=pivot, wave_omega=omega, amplitudes=amps,
                  phi=chunked(phi_fourier(x, winding, omega)), periods=int(repeats),
                  steps_per_period=spp, ramp_periods=ramp, match_omega=match_omega,
                  **{"harmonics": 2, **kw})


def chunked(fun, size=2048):
    """``fun(t)`` evaluated ``size`` times at a time (a long record's trigonometric sums
    would otherwise hold (times x harmonics) arrays); its outputs concatenated along their
    last axis (a tuple of arrays: each)."""
    def call(t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        parts = [fun(t[i:i + size]) for i in range(0, t.size, size)]
        if isinstance(parts[0], dict):
            return {k: np.concatenate([np.asarray(p[k]) for p in parts], axis=-1)
                    for k in parts[0]}
        if isinstance(parts[0], tuple):
            return tuple(np.concatenate([p[j] for p in parts], axis=-1)
                         for j in range(len(parts[0])))
        return np.concatenate(parts, axis=-1)
    return call


def compare_motion(td, fd_xi, fd_xi_dot) -> dict:
    """The largest differences of the hull's motion, per DOF relative to the frequency
    domain's largest value: ``xi`` and ``xi_dot`` (n, 3) of the replay's last repeat against
    ``fd_xi``, ``fd_xi_dot`` (n, 3) at the same times. Surge has no stiffness: its mean and
    its mean velocity (set by how the integration started) are taken out of both."""
    xi, v = np.array(td["xi"], float), np.array(td["xi_dot"], float)
    fx, fv = np.array(fd_xi, float), np.array(fd_xi_dot, float)
    t = np.asarray(td["t"], float)
    drift = float(np.mean(v[:, 0]))
    v[:, 0] -= drift
    xi[:, 0] -= drift * (t - t.mean())
    xi[:, 0] -= np.mean(xi[:, 0])
    fx[:, 0] -= np.mean(fx[:, 0])
    dx = np.max(np.abs(xi - fx), axis=0) / np.max(np.abs(fx), axis=0)
    dv = np.max(np.abs(v - fv), axis=0) / np.max(np.abs(fv), axis=0)
    return {"xi": dx, "xi_dot": dv}


# --- 2. a torque series re-integrated -------------------------------------------------------

#: Gauss-Legendre nodes on [0, 1] where a sample's velocity is kept (its past memory)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
GL = 0.5 * (_GL_X + 1.0)
#: Chebyshev points (with the ends) on [0, 1] where a sample's memory force, excitation and
#: torque are evaluated (a polynomial through them within the sample: barycentric weights)
CHEB = 0.5 * (1.0 - np.cos(np.pi * np.arange(16) / 15))
_BARY = (-1.0) ** np.arange(16)
_BARY[[0, -1]] *= 0.5
#: the quadrature of the memory's weights (per piece of a sample)
_Q_X, _Q_W = np.polynomial.legendre.leggauss(24)


def _lagrange(nodes, x):
    """The Lagrange basis of ``nodes`` at ``x``: (len(x), len(nodes))."""
    x = np.asarray(x, dtype=float)
    out = np.ones((x.size, nodes.size))
    for j, nj in enumerate(nodes):
        for i, ni in enumerate(nodes):
            if i != j:
                out[:, j] *= (x - ni) / (nj - ni)
    return out


def memory_length(omega, B, tol=1e-5, longest=120.0) -> float:
    """Where every entry of ``|K|`` has stayed below ``tol`` times its largest at ``t = 0``
    (on a 0.01 s grid), times 1.2, at most ``longest`` (s)."""
    t = np.arange(0.0, longest, 0.01)
    k = np.max(np.abs(kernel(omega, B, t)), axis=(1, 2))
    big = np.nonzero(k > tol * k[0])[0]
    return min(longest, 1.2 * float(t[big[-1] + 1]) if big.size else 0.1)


def matched_a_inf(omega_data, A, B, omega, memory) -> np.ndarray:
    """``A_inf = A(w) + (1/w) int_0^L K(s) sin(w s) ds``: the value that makes the model with
    the memory truncated at ``L`` have the data's added mass at ``w`` (rad/s)."""
    coef = interpolator(omega_data, A, B, np.zeros((len(omega_data), 3)), np.zeros((3, 3)))
    n = max(64, int(memory * (omega_data[-1] + omega) / 2) * 4)
    edges = np.linspace(0.0, memory, n + 1)
    s = (edges[:-1, None] + 0.5 * np.diff(edges)[:, None] * (_Q_X + 1)).ravel()
    wq = (0.5 * np.diff(edges)[:, None] * _Q_W).ravel()
    ks = np.einsum("t,tab->ab", wq * np.sin(omega * s), kernel(omega_data, B, s))
    return coef(omega)[0] + ks / omega


def _bohman(x):
    """Bohman's taper on ``x = s / L``: the normalized autocorrelation of ``cos(pi y)`` on
    ``|y| <= 1/2`` at lag ``x``, ``int_{x-1/2}^{1/2} cos(pi y) cos(pi (y - x)) dy / (1/2)``
    in closed form."""
    x = np.clip(np.asarray(x, float), 0.0, 1.0)
    return (1.0 - x) * np.cos(np.pi * x) + np.sin(np.pi * x) / np.pi


#: the tapers a run may name for its memory (``hydro_data["window"]``)
WINDOWS = {"bohman": _bohman}


class Memory:
    """The radiation memory ``mu(t) = int_0^L K(s) w(s / L) xi'(t - s) ds`` (``w`` a taper,
    1 without one) on a uniform sample grid
    of step ``dt``: each sample's velocity is kept at its 8 Gauss-Legendre nodes (a degree-7
    polynomial within the sample, smooth there: the torque changes only at the samples'
    edges), and ``mu`` at the 16 Chebyshev points of a sample is a fixed linear map of those
    values, ``mu_i = sum_lag sum_q W[i, lag, q] v[k - lag, q]`` (lag 0: the current sample,
    up to the point), with ``W`` the integrals of ``K`` against the Lagrange basis, by
    24-point Gauss-Legendre on each piece, the truncation at ``L`` exact. ``K`` there is a
    cubic spline of the exact kernel on a grid of ``pi / (20 w_max)`` (20 points per period
    of its fastest oscillation, the data's top frequency: relative error ~ 1e-7)."""

    def __init__(self, omega_data, B, dt, memory, window=None):
        from scipy.interpolate import CubicSpline

        self.dt, self.memory = float(dt), float(memory)
        h = math.pi / (20.0 * float(omega_data[-1]))
        grid = np.linspace(0.0, self.memory, int(math.ceil(self.memory / h)) + 1)
        taper = np.ones(grid.size) if window is None else WINDOWS[window](grid / self.memory)
        spline = CubicSpline(grid, kernel(omega_data, B, grid) * taper[:, None, None])
        lags = int(math.ceil(self.memory / self.dt)) + 1
        self.lags = lags
        # W[i, lag, q, a, b]
        w = np.zeros((CHEB.size, lags + 1, GL.size, 3, 3))
        pts, taus, idx = [], [], []
        for i, c in enumerate(CHEB):
            for lag in range(lags + 1):
                lo = max(0.0, lag + c - self.memory / self.dt)
                hi = c if lag == 0 else 1.0
                if hi <= lo:
                    continue
                tau = lo + 0.5 * (hi - lo) * (_Q_X + 1)
                pts.append(self.dt * (lag + c - tau))
                taus.append((tau, self.dt * 0.5 * (hi - lo)))
                idx.append((i, lag))
        kk = spline(np.concatenate(pts)).reshape(len(pts), _Q_X.size, 3, 3)
        basis = _lagrange(GL, np.concatenate([tq for tq, _ in taus])).reshape(
            len(pts), _Q_X.size, GL.size)
        scale = np.array([f for _, f in taus])[:, None, None] * _Q_W[None, :, None] * basis
        vals = np.einsum("ptq,ptab->pqab", scale, kk)
        for (i, lag), val in zip(idx, vals):
            w[i, lag] = val
        self.w = w

    def history(self, k, v):
        """The past samples' part of ``mu`` at sample ``k``'s Chebyshev points (16, 3): ``v``
        (k0 + k, 8, 3) the nodes' velocities of every sample before it (the oldest first,
        ``k0`` of them before the run)."""
        n = v.shape[0]
        lag = min(self.lags, n)
        past = v[n - lag:][::-1]  # lag 1, 2, ...
        return np.einsum("ilqab,lqb->ia", self.w[:, 1:lag + 1], past)

    def current(self, vk):
        """The current sample's part (16, 3) from its nodes' velocities ``vk`` (8, 3)."""
        return np.einsum("iqab,qb->ia", self.w[:, 0], vk)


def _state_of(s):
    if isinstance(s, dict):
        return np.concatenate((np.asarray(s["xi"], float), [float(s["phi"])],
                               np.asarray(s["xidot"], float), [float(s["phidot"])]))
    return np.asarray(s, dtype=float)


def reintegrate_hull(hydro_data, pendulum, pivot, sea_excitation, t, tau, *, state0,
                     history=None, dofs=(0, 1, 2), a_inf=None, memory=None, restart=None,
                     rtol=1e-12, relax_tol=1e-13) -> dict:
    """Integrate the pendulum (P) and the hull (H) under a given torque: the plant again.

    The nonlinear pendulum and the linear hull with Cummins' radiation memory and the wave's
    excitation (the equations of this module's docstring), sample by sample with scipy's
    DOP853 (``rtol``), the memory a direct convolution of the exact kernel with the
    integration's own past velocity (:class:`Memory`); within a sample the memory force, the
    excitation and the torque are polynomials through their values at 16 Chebyshev points,
    the memory force found by a waveform relaxation
    (``mu`` from the last iterate's velocity, integrate, again) until it changes by at most
    ``relax_tol`` of its size.

    Parameters
    ----------
    hydro_data : dict
        ``omega`` (n,) rad/s, ``B`` (n, 3, 3) radiation damping (symmetrised here), ``C``
        (3, 3) hydrostatic stiffness with the floating system's weight at O (the pendulum's
        correction ``- m g h_p`` on pitch is applied here), ``Mh`` (3, 3) the hull's mass
        matrix without the pendulum, ``g``; optionally ``a_inf`` (3, 3), ``memory`` (s)
        (:func:`hull_data`) and ``window``, the taper of the kernel over the memory (a name
        in :data:`WINDOWS`). ``A`` is needed only for the default ``a_inf``.
    pendulum : object or dict
        ``mass`` (kg), ``length`` (m, pivot to centre of mass), ``inertia`` (kg m^2, about
        the pivot), ``damping_coefficient`` (N m s, on ``phi' - beta'``).
    pivot : (d_p, h_p)
        The pivot from O (m).
    sea_excitation : callable
        ``F_exc(t)`` (N, N, N m): ``t`` (m,) -> (m, 3).
    t : (n + 1,) array
        The samples' edges (s), uniformly spaced.
    tau : (n,) array or callable
        The generator's torque on the pendulum (N m), held over ``[t_k, t_k+1)``, or a
        function ``tau(t)`` (vectorized).
    state0 : dict or (8,) array
        The state at ``t[0]``: ``xi``, ``phi``, ``xidot``, ``phidot``, or the array
        ``(xi, phi, xidot, phidot)``.
    history : callable, optional
        ``xi'(s)`` (m/s, rad/s) for ``s < t[0]``: (m,) -> (m, 3) (default: at rest).
    dofs : tuple of int
        The hull's free degrees of freedom (0 surge, 1 heave, 2 pitch); the others are held
        at 0: ``(1,)`` with the pivot at O is the heaving buoy.
    a_inf : (3, 3) array, optional
        Infinite-frequency added mass (default ``hydro_data["a_inf"]``).
    memory : float, optional
        The memory's length ``L`` (s) (default ``hydro_data["memory"]``, else
        :func:`memory_length`).
    restart : tuple (every, states), optional
        Reset the state to ``states[k]`` ((n + 1, 8), as ``state0``) at every sample ``k``
        that is a multiple of ``every``: a closed loop re-measures its state, and a rotating
        pendulum amplifies any difference exponentially; the memory keeps the
        re-integration's own past.

    Returns
    -------
    dict
        At the samples' edges (n + 1): ``t``, ``phi``, ``phidot``, ``xi``, ``xidot`` (n + 1,
        3); ``energy``: the harvested energy ``-int tau (phi' - beta') dt`` from ``t[0]``
        (J; over a restart the sample's own integration); ``work`` (n,) each sample's;
        ``stored`` (n + 1,): the mechanical energy ``E`` (J); ``start`` (n, 8): the state
        each sample was integrated from; ``a_inf``, ``memory``.
    """
    t = np.asarray(t, dtype=float)
    n = t.size - 1
    dt = float(t[1] - t[0])
    if not np.allclose(np.diff(t), dt, rtol=1e-9, atol=0):
        raise ValueError("t: expected uniformly spaced samples")
    m, ell = _p(pendulum, "mass"), _p(pendulum, "length")
    inertia, c = _p(pendulum, "inertia"), _p(pendulum, "damping_coefficient")
    g = float(hydro_data["g"])
    gm = _pivot_matrix(pivot)
    free = np.array(sorted(dofs), dtype=int)
    nf = free.size
    om = np.asarray(hydro_data["omega"], float)
    b = np.asarray(hydro_data["B"], float)
    b = 0.5 * (b + np.swapaxes(b, 1, 2))
    if memory is None:
        memory = hydro_data.get("memory") or memory_length(om, b)
    if a_inf is None:
        a_inf = hydro_data["a_inf"]
    cp = np.array(hydro_data["C"], dtype=float)
    cp = 0.5 * (cp + cp.T)
    cp[2, 2] -= m * g * float(pivot[1])
    mass = np.asarray(hydro_data["Mh"], float) + np.asarray(a_inf, float) + m * gm.T @ gm
    mem = Memory(om, b, dt, memory, hydro_data.get("window"))
    held = None if callable(tau) else np.asarray(tau, dtype=float)
    if held is not None and held.shape != (n,):
        raise ValueError(f"tau: expected {n} held torques, got shape {held.shape}")
    ml = m * ell
    sel = np.ix_(free, free)
    mf = mass[sel]

    def parts(y):
        xi = np.zeros(3)
        xd = np.zeros(3)
        xi[free], xd[free] = y[:nf], y[nf + 1:2 * nf + 1]
        return xi, y[nf], xd, y[2 * nf + 1]

    def energy(y):
        xi, ph, xd, pd = parts(y)
        u = gm.T @ np.array([math.cos(ph), -math.sin(ph)])
        return float(0.5 * xd @ mass @ xd + ml * pd * (u @ xd) + 0.5 * inertia * pd * pd
                     + 0.5 * xi @ cp @ xi + ml * g * math.cos(ph))

    def pick(s):
        s = _state_of(s)
        return np.concatenate((s[:3][free], [s[3]], s[4:7][free], [s[7]]))

    # the past: velocity at the nodes of the samples before t[0]
    k0 = mem.lags
    v = np.zeros((k0 + n, GL.size, 3))
    if history is not None:
        for j in range(k0):
            a = t[0] - (k0 - j) * dt
            v[j] = np.asarray(history(a + dt * GL), float)
        v[:k0][:, :, [d for d in range(3) if d not in free]] = 0.0
    y = pick(state0)
    ends = np.empty((n + 1, y.size))
    ends[0] = y
    starts = np.empty((n, y.size))
    work = np.empty(n)
    every, states = restart if restart is not None else (0, None)
    ifree = list(free)
    pitch = ifree.index(2) if 2 in free else None
    cpf = cp[sel]
    gtf = gm.T[free]
    mm = np.zeros((nf + 1, nf + 1))
    mm[:nf, :nf] = mf
    mm[nf, nf] = inertia
    for k in range(n):
        a, bnd = t[k], t[k + 1]
        if every and k and k % every == 0:
            y = pick(states[k])
        starts[k] = y
        hist = mem.history(k, v[:k0 + k])
        nodes = a + dt * CHEB
        fx = np.asarray(sea_excitation(nodes), float).reshape(CHEB.size, 3)[:, free]
        tq = (np.full(CHEB.size, held[k]) if held is not None
              else np.asarray(tau(nodes), float).reshape(CHEB.size))
        vk = np.tile(parts(y)[2], (GL.size, 1))
        old = None
        for _ in range(40):
            mu = hist + mem.current(vk)
            size = max(float(np.max(np.abs(mu))), 1e-300)
            if old is not None and float(np.max(np.abs(mu - old))) <= relax_tol * size:
                break
            old = mu
            table = np.column_stack((fx - mu[:, free], tq))

            def rhs(s, yy, table=table, nodes=nodes):
                d = s - nodes
                hit = np.nonzero(d == 0.0)[0]
                if hit.size:
                    val = table[hit[0]]
                else:
                    r = _BARY / d
                    val = (r @ table) / r.sum()
                xi = yy[:nf]
                ph, xd, pd = yy[nf], yy[nf + 1:2 * nf + 1], yy[2 * nf + 1]
                sn, cs = math.sin(ph), math.cos(ph)
                rel = pd - (xd[pitch] if pitch is not None else 0.0)
                q = val[nf]
                fh = val[:nf] - cpf @ xi + (ml * pd * pd) * (gtf @ (sn, cs))
                if pitch is not None:
                    fh[pitch] += -q + c * rel
                fp = q - c * rel + ml * g * sn
                mm[:nf, nf] = mm[nf, :nf] = ml * (gtf @ (cs, -sn))
                acc = np.linalg.solve(mm, np.append(fh, fp))
                return np.concatenate((xd, [pd], acc))
            sol = solve_ivp(rhs, (a, bnd), y, method="DOP853", rtol=rtol,
                            atol=rtol * 1e-3, dense_output=True)
            if not sol.success:
                raise RuntimeError(f"DOP853 failed in sample {k}: {sol.message}")
            vn = sol.sol(a + dt * GL)[nf + 1:2 * nf + 1].T
            vk = np.zeros((GL.size, 3))
            vk[:, free] = vn
        else:
            raise RuntimeError(f"the memory's relaxation did not converge in sample {k}")
        v[k0 + k] = vk
        y1 = sol.y[:, -1]
        if held is not None:
            def theta(yy):
                return yy[nf] - (yy[pitch] if pitch is not None else 0.0)
            work[k] = -held[k] * (theta(y1) - theta(y))
        else:
            ss = a + dt * GL
            yy = sol.sol(ss)
            bd = yy[nf + 1 + pitch] if pitch is not None else 0.0
            work[k] = -dt * float(np.sum(_GL_W * 0.5 * tau(ss) * (yy[2 * nf + 1] - bd)))
        y = ends[k + 1] = y1
    xi = np.zeros((n + 1, 3))
    xd = np.zeros((n + 1, 3))
    xi[:, free] = ends[:, :nf]
    xd[:, free] = ends[:, nf + 1:2 * nf + 1]
    return {"t": t, "phi": ends[:, nf], "phidot": ends[:, 2 * nf + 1], "xi": xi, "xidot": xd,
            "energy": np.concatenate(([0.0], np.cumsum(work))), "work": work,
            "stored": np.array([energy(e) for e in ends]), "start": starts,
            "a_inf": np.asarray(a_inf, float), "memory": float(memory)}
