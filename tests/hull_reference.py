r"""Independent reference of the hull model: CasADi + IPOPT on the spec's grid.

The model and its discretization are those of /work/notes/hull_spec.md (a surge, heave and
pitch hull ``xi = (x, z, beta)`` carrying a pendulum; equations (P) and (H)). This module
shares nothing with parapend's solvers: the decision variables are the pendulum's Fourier
coefficients ``x`` (``phi(s) = K s + x0 + sum x_n sin(ns) + x_{N+n} cos(ns)``, ``s = w t``)
AND the hull's harmonics (``Xi_0`` of the DOFs with ``C'[i, i] > 0``, ``Re``, ``Im`` of
``Xi_k``, ``k = 1..Nh``); the Galerkin hull equations ``Z_k Xi_k = Fa_k + R_k`` are
equality constraints (each row divided by its largest coefficient), and the power

    P = -(1/M) sum_j tau_j (phi'_j - beta'_j),
    tau = I phi'' + c (phi' - beta') - m l [ (g + p_z'') sin(phi) - p_x'' cos(phi) ]

is maximized on the M-point grid, with exact first and second derivatives from CasADi's
automatic differentiation (MX graphs of the grid's sine/cosine matrices and elementwise
``sin``/``cos`` of ``phi``; SX on request). The harmonics ``x_n`` (n >= 1) are bounded by
2 pi by default: on the grid the power is unbounded (aliasing), and IPOPT went there from
some starts. Every converged start is re-checked by NumPy (the hull solved again, and the
power on an 8 times finer grid).

:func:`hull_power` is the same ``P`` at given ``x`` with the hull solved from (H) by one
real linear solve in NumPy (no optimization): a point check of any kernel's answer.

Used by tests/test_hull_reference.py and the hull benchmark.
"""

from __future__ import annotations

import math
import time

import numpy as np

STATUS_OK = "Solve_Succeeded"
ACCEPT = 1e-8  # a converged start's power re-evaluated by NumPy (hull solved again), relative
ALIAS_FACTOR = 8  # the power re-evaluated on ALIAS_FACTOR * M points (same N, Nh) ...
ALIAS_TOL = 1e-6  # ... must agree to this (relative), else the start climbed into aliasing
RCOND = 1e-10  # the radiation bound's pseudo-inverse cut (relative to B_k's largest eigenvalue)


# ------------------------------------------------------------------------------------------
# the discretization, shared by the NumPy and CasADi forms
class _Grid:
    """Constant matrices of the spec's discretization and the problem's data."""

    def __init__(self, *, omega, amplitudes, winding, harmonics, hull_harmonics, points,
                 A, B, F, C, Mh, m, l, I, c, g, pivot):  # noqa: E741 (the spec's names)
        w = float(omega)
        n, nh, mm, kk = int(harmonics), int(hull_harmonics), int(points), int(winding)
        if not (w > 0 and math.isfinite(w)):
            raise ValueError(f"omega: expected a positive frequency, got {omega!r}")
        if n < 1 or nh < 1:
            raise ValueError("harmonics, hull_harmonics: expected >= 1")
        # K < 0: turns against the sense of a positive pitch (the same formulas)
        if mm & (mm - 1) or mm <= 2 * (nh + n + abs(kk)):
            raise ValueError(f"points: expected a power of two above 2 (Nh + N + |K|) = "
                             f"{2 * (nh + n + abs(kk))}, got {points!r}")
        A = np.asarray(A, dtype=float)
        B = np.asarray(B, dtype=float)
        F = np.asarray(F, dtype=complex)
        if A.shape != (nh + 1, 3, 3) or B.shape != (nh + 1, 3, 3) or F.shape != (nh + 1, 3):
            raise ValueError("A, B: expected (Nh+1, 3, 3); F: (Nh+1, 3)")
        self.A = 0.5 * (A + A.transpose(0, 2, 1))
        self.B = 0.5 * (B + B.transpose(0, 2, 1))
        self.w, self.n, self.nh, self.M, self.K = w, n, nh, mm, kk
        self.m, self.l, self.I, self.c, self.g = float(m), float(l), float(I), float(c), float(g)
        self.dp, self.hp = (float(v) for v in pivot)
        self.G = np.array([[1.0, 0.0, self.hp], [0.0, 1.0, -self.dp]])
        Cp = np.array(C, dtype=float).copy()
        Cp[2, 2] -= self.m * self.g * self.hp
        self.Cp = Cp
        self.Mh = np.asarray(Mh, dtype=float)
        a = np.atleast_1d(np.asarray(amplitudes, dtype=complex))
        self.Fa = np.zeros((nh + 1, 3), dtype=complex)
        for k in range(1, min(a.size, nh) + 1):
            self.Fa[k] = F[k] * a[k - 1]
        # impedances
        mg = self.m * self.G.T @ self.G
        self.Z = np.empty((nh + 1, 3, 3), dtype=complex)
        for k in range(nh + 1):
            kw = k * w
            self.Z[k] = (-(kw**2) * (self.Mh + self.A[k] + mg) + 1j * kw * self.B[k] + Cp)
        self.Z[0] = Cp  # k = 0: the stiffness alone
        self.dofs0 = [i for i in range(3) if Cp[i, i] > 0]
        # the pendulum's grid
        s = 2 * math.pi * np.arange(mm) / mm
        self.s = s
        ns = np.arange(1, n + 1)[None, :] * s[:, None]
        sn, cs = np.sin(ns), np.cos(ns)
        nn = np.arange(1, n + 1)[None, :]
        one = np.ones((mm, 1))
        zero = np.zeros((mm, 1))
        self.P0 = np.hstack((one, sn, cs))                       # phi - K s
        self.P1 = w * np.hstack((zero, nn * cs, -nn * sn))       # phi' - K w
        self.P2 = w**2 * np.hstack((zero, -nn**2 * sn, -nn**2 * cs))  # phi''
        # the hull's unknowns y = [Xi_0 (dofs0), (Re Xi_k (3), Im Xi_k (3)) k = 1..Nh]
        n0 = len(self.dofs0)
        self.ny = n0 + 6 * nh
        ks = np.arange(1, nh + 1)[None, :] * s[:, None]
        hc, hs = np.cos(ks), np.sin(ks)
        kw = w * np.arange(1, nh + 1)[None, :]
        E0 = np.zeros((3, mm, self.ny))
        E1 = np.zeros((3, mm, self.ny))
        E2 = np.zeros((3, mm, self.ny))
        for j, d in enumerate(self.dofs0):
            E0[d, :, j] = 1.0
        for d in range(3):
            re = n0 + 6 * np.arange(nh) + d
            im = re + 3
            E0[d][:, re], E0[d][:, im] = hc, -hs
            E1[d][:, re], E1[d][:, im] = -kw * hs, -kw * hc
            E2[d][:, re], E2[d][:, im] = -kw**2 * hc, kw**2 * hs
        self.E0, self.E1, self.E2 = E0, E1, E2
        # projection of grid values onto the harmonics' rows: R = Pr[d] @ r_d (ny rows)
        Pr = np.zeros((3, self.ny, mm))
        for j, d in enumerate(self.dofs0):
            Pr[d, j, :] = 1.0 / mm
        for d in range(3):
            re = n0 + 6 * np.arange(nh) + d
            Pr[d][re, :] = (2.0 / mm) * hc.T
            Pr[d][re + 3, :] = -(2.0 / mm) * hs.T
        self.Pr = Pr
        # the impedance part: L0 y = (Z_k Xi_k) in the same row layout, and its rhs Fa
        L0 = np.zeros((self.ny, self.ny))
        rhs = np.zeros(self.ny)
        d0 = np.array(self.dofs0, dtype=int)
        L0[:n0, :n0] = Cp[np.ix_(d0, d0)]
        for k in range(1, nh + 1):
            r = n0 + 6 * (k - 1)
            Zr, Zi = self.Z[k].real, self.Z[k].imag
            L0[r:r + 3, r:r + 3] = Zr
            L0[r:r + 3, r + 3:r + 6] = -Zi
            L0[r + 3:r + 6, r:r + 3] = Zi
            L0[r + 3:r + 6, r + 3:r + 6] = Zr
            rhs[r:r + 3] = self.Fa[k].real
            rhs[r + 3:r + 6] = self.Fa[k].imag
        self.L0, self.rhs = L0, rhs
        # row scales of the constraints: the largest coefficient of each row
        self.row_scale = np.maximum(np.max(np.abs(L0), axis=1), 1e-300)

    # --------------------------------------------------------------------------------------
    def phi_grid(self, x):
        x = np.asarray(x, dtype=float)
        ph = self.K * self.s + self.P0 @ x
        return ph, self.K * self.w + self.P1 @ x, self.P2 @ x

    def solve_hull(self, x):
        """The hull's unknowns ``y`` from (H) at the pendulum's ``x``: one linear solve."""
        ph, d1, d2 = self.phi_grid(x)
        sp, cp = np.sin(ph), np.cos(ph)
        ml = self.m * self.l
        ssd = cp * d2 - sp * d1**2
        csd = -sp * d2 - cp * d1**2
        G = self.G
        rx = -ml * ssd
        rz = -ml * csd
        rb = -ml * (G[0, 2] * ssd + G[1, 2] * csd) - self.I * d2 + ml * self.g * sp
        const = self.Pr[0] @ rx + self.Pr[1] @ rz + self.Pr[2] @ rb
        # r_beta's part linear in y: m l (p_z'' sin(phi) - p_x'' cos(phi))
        pz2 = self.E2[1] - self.dp * self.E2[2]
        px2 = self.E2[0] + self.hp * self.E2[2]
        lin = ml * (sp[:, None] * pz2 - cp[:, None] * px2)
        L = self.L0 - self.Pr[2] @ lin
        return np.linalg.solve(L, self.rhs + const)

    def Xi(self, y):
        n0 = len(self.dofs0)
        out = np.zeros((self.nh + 1, 3), dtype=complex)
        out[0, self.dofs0] = y[:n0]
        blk = y[n0:].reshape(self.nh, 2, 3)
        out[1:] = blk[:, 0, :] + 1j * blk[:, 1, :]
        return out

    def y_of(self, Xi):
        n0 = len(self.dofs0)
        y = np.empty(self.ny)
        y[:n0] = Xi[0, self.dofs0].real
        blk = np.stack((Xi[1:].real, Xi[1:].imag), axis=1)
        y[n0:] = blk.ravel()
        return y

    def power_np(self, x, y):
        """``(P, c <(phi' - beta')^2>)`` on the grid."""
        tau, rel = self.torque_np(x, y)
        return -float(np.mean(tau * rel)), self.c * float(np.mean(rel * rel))

    def torque_np(self, x, y):
        """``(tau, phi' - beta')`` on the grid."""
        ph, d1, d2 = self.phi_grid(x)
        sp, cp = np.sin(ph), np.cos(ph)
        bd = self.E1[2] @ y
        pz2 = (self.E2[1] - self.dp * self.E2[2]) @ y
        px2 = (self.E2[0] + self.hp * self.E2[2]) @ y
        rel = d1 - bd
        tau = (self.I * d2 + self.c * rel
               - self.m * self.l * ((self.g + pz2) * sp - px2 * cp))
        return tau, rel

    def balance(self, x, y):
        """Relative residual of ``P + c<(phi'-beta')^2> = sum_k [Re(Fa^H U)/2 - U^H B U/2]``
        (divided by the largest of the wave's gross input, the radiated power, |P|)."""
        p, loss = self.power_np(x, y)
        Xi = self.Xi(y)
        inp = rad = 0.0
        for k in range(1, self.nh + 1):
            U = 1j * k * self.w * Xi[k]
            inp += 0.5 * float(np.real(np.vdot(self.Fa[k], U)))
            rad += 0.5 * float(np.real(np.vdot(U, self.B[k] @ U)))
        scale = max(abs(inp), abs(rad), abs(p), 1e-300)
        return abs(p + loss - (inp - rad)) / scale

    def bound(self):
        """``sum_k Fa_k^H B_k^+ Fa_k / 8`` (W), eigenvalues below ``RCOND`` times the largest
        taken as zero."""
        tot = 0.0
        for k in range(1, self.nh + 1):
            if not np.any(self.Fa[k]):
                continue
            lam, V = np.linalg.eigh(self.B[k])
            keep = lam > RCOND * max(float(np.max(np.abs(lam))), 1e-300)
            q = V[:, keep].conj().T @ self.Fa[k]
            tot += float(np.sum(np.abs(q) ** 2 / lam[keep])) / 8
        return tot

    def one_way_y(self):
        """The free hull's response (the pendulum's mass lumped at the pivot)."""
        n0 = len(self.dofs0)
        y = np.zeros(self.ny)
        y[n0:] = np.linalg.solve(self.L0[n0:, n0:], self.rhs[n0:])
        return y


def _grid(kw) -> _Grid:
    keys = ("omega", "amplitudes", "winding", "harmonics", "hull_harmonics", "points", "A",
            "B", "F", "C", "Mh", "m", "l", "I", "c", "g", "pivot")
    return _Grid(**{k: kw[k] for k in keys})


def hull_power(x, **kw) -> float:
    """The spec's ``P`` (W) at the pendulum's coefficients ``x``, the hull solved from (H).

    Keyword arguments: those of :func:`hull_reference` (``omega`` .. ``pivot``).
    """
    gr = _grid(kw)
    return gr.power_np(x, gr.solve_hull(x))[0]


def hull_state(x, **kw) -> dict:
    """``power``, ``Xi``, ``energy_balance_residual`` at ``x`` (hull from (H)); with
    ``one_way=True`` the hull is fixed at its free response instead."""
    one_way = kw.pop("one_way", False)
    gr = _grid(kw)
    y = gr.one_way_y() if one_way else gr.solve_hull(x)
    out = {"power": gr.power_np(x, y)[0], "Xi": gr.Xi(y)}
    if not one_way:
        out["energy_balance_residual"] = gr.balance(x, y)
    return out


# ------------------------------------------------------------------------------------------
def _starts(gr: _Grid, starts: int, seed: int):
    """Deterministic starts: K = 0 mean angles around hanging and elsewhere, amplitudes and
    phases of the first harmonic; K >= 1 phase offsets of a uniform rotation."""
    rng = np.random.default_rng(seed)
    n = gr.n
    out = []
    means = (math.pi, math.pi + 0.7, math.pi - 0.7, 0.5 * math.pi, 1.5 * math.pi, 0.0)
    amps = (0.4, 1.2, 2.0)
    for i in range(starts):
        x = np.zeros(2 * n + 1)
        ph = 2 * math.pi * i / max(starts, 1) + 0.3 * i
        if gr.K == 0:
            x[0] = means[i % len(means)]
            a = amps[(i // 2) % len(amps)]
            x[1], x[n + 1] = a * math.cos(ph), a * math.sin(ph)
        else:
            x[0] = ph
        x[1:] += 0.05 * rng.standard_normal(2 * n) / np.tile(np.arange(1, n + 1), 2) ** 2
        out.append(x)
    return out


def _build(gr: _Grid, tol: float, max_iter: int, graph: str = "MX", one_way: bool = False,
           pto: dict | None = None):
    """The NLP. ``pto``: ``torque_limit`` (``-T <= tau_j <= T`` at every grid point, as
    constraints), ``copper_loss`` (``- r <tau^2>`` in the objective) and ``efficiency``
    ``(eta_g, eta_m)``: the power split into non-negative parts, ``p_j = p+_j - p-_j`` as
    constraints, objective ``<eta_g p+ - p- / eta_m>`` (exact and smooth: at an optimum one
    part of each pair is zero, as ``eta_g < 1 / eta_m``). The variables are then ``(x, y,
    p+, p-)``."""
    import casadi as ca

    pto = pto or {}
    n, ny = 2 * gr.n + 1, gr.ny
    sym = getattr(ca, graph).sym
    xs = sym("x", n)
    ys = sym("y", ny)
    eta = pto.get("efficiency")
    pp = sym("pp", gr.M) if eta is not None else None
    pm = sym("pm", gr.M) if eta is not None else None
    def DM(a):  # constant matrices as sparse: the zeros stay out of the graphs
        a = np.asarray(a, dtype=float)
        if a.ndim == 1:
            return ca.DM(a)
        from scipy.sparse import csc_matrix
        return ca.DM(csc_matrix(a))
    ph = DM(gr.K * gr.s) + ca.mtimes(DM(gr.P0), xs)
    d1 = gr.K * gr.w + ca.mtimes(DM(gr.P1), xs)
    d2 = ca.mtimes(DM(gr.P2), xs)
    sp, cp = ca.sin(ph), ca.cos(ph)
    ml = gr.m * gr.l
    ssd = cp * d2 - sp * d1**2
    csd = -sp * d2 - cp * d1**2
    bd = ca.mtimes(DM(gr.E1[2]), ys)
    xi2 = [ca.mtimes(DM(gr.E2[d]), ys) for d in range(3)]
    pz2 = xi2[1] - gr.dp * xi2[2]
    px2 = xi2[0] + gr.hp * xi2[2]
    rx = -ml * ssd
    rz = -ml * csd
    rb = (-ml * (gr.hp * ssd - gr.dp * csd) - gr.I * d2 + ml * gr.g * sp
          + ml * (pz2 * sp - px2 * cp))
    R = ca.mtimes(DM(gr.Pr[0]), rx) + ca.mtimes(DM(gr.Pr[1]), rz) + ca.mtimes(DM(gr.Pr[2]), rb)
    cons = (ca.mtimes(DM(gr.L0), ys) - DM(gr.rhs) - R) / DM(gr.row_scale)
    if one_way:  # the hull held at its free response: the pendulum's reaction left out
        cons = ys - DM(gr.one_way_y())
    rel = d1 - bd
    tau = gr.I * d2 + gr.c * rel - ml * ((gr.g + pz2) * sp - px2 * cp)
    power = -ca.sum1(tau * rel) / gr.M
    pscale = max(ml * gr.g * gr.w, 1e-300)
    objective = power
    variables = [xs, ys]
    if eta is not None:
        objective = (eta[0] * ca.sum1(pp) - ca.sum1(pm) / eta[1]) / gr.M
        cons = ca.vertcat(cons, (pp - pm + tau * rel) / pscale)
        variables += [pp, pm]
    if pto.get("copper_loss"):
        objective = objective - pto["copper_loss"] * ca.sum1(tau * tau) / gr.M
    if pto.get("torque_limit") is not None:
        cons = ca.vertcat(cons, tau / pto["torque_limit"])
    nlp = {"x": ca.vertcat(*variables), "f": -objective / pscale, "g": cons}
    opts = {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes", "tol": tol,
                                           "max_iter": max_iter}}
    if pto.get("torque_limit") is not None or eta is not None:
        # inequalities: start from the given point, not pushed far into the interior
        opts["ipopt"].update({"mu_init": 1e-6, "bound_push": 1e-9, "bound_frac": 1e-9,
                              "warm_start_init_point": "yes"})
    solver = ca.nlpsol("hull", "ipopt", nlp, opts)
    return solver, ca.Function("power", [xs, ys], [power]), ca.Function(
        "objective", variables, [objective])


def hull_reference(*, omega, amplitudes, winding, harmonics, hull_harmonics, points, A, B, F,
                   C, Mh, m, l, I, c, g, pivot, x0=None, starts=8, seed=0, tol=1e-12,  # noqa: E741
                   max_iter=1000, one_way=False, graph="MX",
                   coefficient_bound=2 * math.pi, pto=None) -> dict:
    """Maximize the spec's power over the pendulum's and the hull's harmonics (IPOPT).

    Parameters
    ----------
    omega : float
        Fundamental (rad/s).
    amplitudes : array of complex
        Wave amplitudes ``a_k``, k = 1..Kw (m), elevation at O ``Re sum a_k exp(i k w t)``.
    winding, harmonics, hull_harmonics, points : int
        K, N, Nh, M (a power of two above ``2 (Nh + N + K)``).
    A, B : ndarray (Nh+1, 3, 3)
        Added mass and radiation damping at ``k w``, k = 0..Nh (symmetrised here).
    F : ndarray (Nh+1, 3), complex
        Excitation per metre of amplitude at ``k w``, convention ``exp(+i w t)``.
    C : ndarray (3, 3)
        The dataset's stiffness WITHOUT the pendulum's correction (``C[2,2] -= m g h_p``
        is applied here).
    Mh : ndarray (3, 3)
        The hull without the pendulum, about O.
    m, l, I, c, g : float
        The pendulum (kg, m, kg m^2 about the pivot, N m s/rad) and gravity.
    pivot : (d_p, h_p)
        The pivot from O (m).
    x0 : array (2N+1) or None
        One start for the pendulum's coefficients (the hull from (H) there); None: ``starts``
        deterministic starts (``seed`` for their small random part).
    tol : float
        IPOPT's ``tol`` (objective divided by ``m g l w``, constraint rows by their largest
        coefficient).
    max_iter : int
        IPOPT's ``max_iter``.
    one_way : bool
        Hold the hull at its free response ``Z_k^{-1} Fa_k`` (the pendulum's reaction left
        out) and maximize over the pendulum alone: the one-way optimum.
    coefficient_bound : float or None
        Simple bounds ``|x_n| <= coefficient_bound`` (n >= 1; not the mean ``x_0``), rad:
        they keep IPOPT out of the aliased region where the grid's power is unbounded (see
        below); a start ending on a bound does not count as converged. None: no bounds.
    graph : "MX" or "SX"
        CasADi's graph of the NLP (MX: matrix operations, builds in a fraction of a second;
        SX: scalar graph, builds in seconds, and solves somewhat slower here).

    A start counts as converged when IPOPT returns ``Solve_Succeeded``, the NumPy
    re-evaluation (hull solved again from (H)) agrees with IPOPT's power to ``ACCEPT``
    relative, and the power on ``ALIAS_FACTOR * M`` points agrees to ``ALIAS_TOL``: on the
    M-point grid the power is unbounded (a phi with large coefficients has harmonics of
    ``sin(phi)`` far above M/2, and the grid's mean of them is aliasing), and some starts
    climb there (seen at K = 1..3 on the heave-only case: 1e8 to 1e9 W "optima", energy
    balance broken, IPOPT ending at its iteration limit or "acceptable").

    Returns
    -------
    dict with ``power`` (W), ``x``, ``Xi`` ((Nh+1, 3) complex), ``status`` (IPOPT's return
    status of the best), ``success``, ``time_s`` (IPOPT's solves only, summed),
    ``time_per_solve_s``, ``energy_balance_residual`` (relative), ``starts_converged``,
    ``powers`` (every start's power, status and seconds), ``power_check``
    (:func:`hull_power`-style NumPy re-evaluation at the optimum, the hull from (H) solved
    again; one-way: held), ``radiation_bound`` (W, pseudo-inverse of ``B_k`` with the cut
    ``RCOND`` relative to its largest eigenvalue), ``points``, ``alias_change`` (relative
    change of the best's power on ``ALIAS_FACTOR * M`` points).
    """
    gr = _Grid(omega=omega, amplitudes=amplitudes, winding=winding, harmonics=harmonics,
               hull_harmonics=hull_harmonics, points=points, A=A, B=B, F=F, C=C, Mh=Mh, m=m,
               l=l, I=I, c=c, g=g, pivot=pivot)
    solver, pfun, _ = _build(gr, tol, max_iter, graph, one_way)
    nx = 2 * gr.n + 1
    zero = np.zeros(gr.ny)
    if x0 is not None:
        seeds = [np.asarray(x0, dtype=float).ravel()]
        if seeds[0].size != nx:
            raise ValueError(f"x0: expected 2 N + 1 = {nx} coefficients, got {seeds[0].size}")
    else:
        seeds = _starts(gr, starts, seed)

    ub = np.full(nx + gr.ny, np.inf)
    if coefficient_bound is not None:
        ub[1:nx] = float(coefficient_bound)
        for xs in seeds:  # the starts inside the bounds
            np.clip(xs[1:], -0.999 * ub[1:nx], 0.999 * ub[1:nx], out=xs[1:])

    def hull(x):
        return gr.one_way_y() if one_way else gr.solve_hull(x)

    total = 0.0
    runs = []
    for xs in seeds:
        ys = hull(xs)
        t = time.perf_counter()
        sol = solver(x0=np.concatenate((xs, ys)), lbg=zero, ubg=zero, lbx=-ub, ubx=ub)
        total += time.perf_counter() - t
        st = solver.stats()["return_status"]
        z = np.asarray(sol["x"]).ravel()
        runs.append((float(pfun(z[:nx], z[nx:])), st, z, time.perf_counter() - t))

    fine = _Grid(omega=omega, amplitudes=amplitudes, winding=winding, harmonics=harmonics,
                 hull_harmonics=hull_harmonics, points=ALIAS_FACTOR * gr.M, A=A, B=B, F=F, C=C,
                 Mh=Mh, m=m, l=l, I=I, c=c, g=g, pivot=pivot)

    def fine_power(x):
        return fine.power_np(x, fine.one_way_y() if one_way else fine.solve_hull(x))[0]

    def ok(r):
        if r[1] != STATUS_OK or np.any(np.abs(r[2][1:nx]) >= (1 - 1e-6) * ub[1:nx]):
            return False
        x, tol_p = r[2][:nx], ACCEPT * max(abs(r[0]), 1e-300)
        if abs(gr.power_np(x, hull(x))[0] - r[0]) > tol_p:
            return False
        return one_way or abs(fine_power(x) - r[0]) <= ALIAS_TOL * max(abs(r[0]), 1e-300)

    conv = [r for r in runs if ok(r)]
    best = max(conv if conv else runs, key=lambda r: r[0])
    p, st, z = best[:3]
    x, y = z[:nx], z[nx:]
    return {"power": p, "x": x, "Xi": gr.Xi(y), "status": st, "success": bool(conv),
            "time_s": total, "time_per_solve_s": total / len(seeds),
            "energy_balance_residual": gr.balance(x, y), "starts_converged": len(conv),
            "powers": [(r[0], r[1], r[3]) for r in runs],
            "power_check": gr.power_np(x, hull(x))[0], "radiation_bound": gr.bound(),
            "points": gr.M,
            "alias_change": abs(fine_power(x) - p) / max(abs(p), 1e-300)}


# ------------------------------------------------------------------------------------------
def box_coefficients(w):
    """Synthetic, smooth coefficients of rough 10 m x 4 m x 1 m box-barge magnitudes at
    ``w`` (rad/s): ``A`` (..., 3, 3) symmetric, ``B`` positive semidefinite (surge-pitch
    coupled, vanishing at 0), ``F`` (..., 3) with ``F(0) = C[:, 1]`` (exp(+i w t))."""
    w = np.asarray(w, dtype=float)
    rv = 1025.0 * 40.0
    c33 = 1025.0 * 9.81 * 40.0
    A = np.zeros(w.shape + (3, 3))
    B = np.zeros_like(A)
    F = np.zeros(w.shape + (3,), dtype=complex)
    A[..., 0, 0] = 0.1 * rv
    A[..., 1, 1] = rv * (1 + 0.3 / (1 + w**2))
    A[..., 2, 2] = 3e5
    A[..., 0, 2] = A[..., 2, 0] = -2000.0
    b = np.stack([0.05 * rv * w**2 * np.exp(-0.3 * w**2), 0.4 * rv * w**2 * np.exp(-0.5 * w**2),
                  3e5 * w**2 * np.exp(-0.4 * w**2)], -1)
    for i in range(3):
        B[..., i, i] = b[..., i]
    B[..., 0, 2] = B[..., 2, 0] = 0.5 * np.sqrt(b[..., 0] * b[..., 2])
    F[..., 0] = 1j * 0.3 * c33 * w * np.exp(-0.3 * w**2)
    F[..., 1] = c33 * np.exp(-0.1 * w**2) * np.exp(-0.2j * w)
    F[..., 2] = -1j * 2e5 * w * np.exp(-0.4 * w**2)
    return A, B, F


def box_case(*, winding, harmonics, hull_harmonics=6, points=None, period=6.0, height=1.0,
             m=2000.0, l=1.0, I=2500.0, c=500.0, pivot=(0.0, 1.0), g=9.81) -> dict:  # noqa: E741
    """Keyword arguments of :func:`hull_reference` for the synthetic box in a regular wave
    (``points`` default: the power of two at or above ``8 (N + Nh + K)``)."""
    w = 2 * math.pi / period
    A, B, F = box_coefficients(w * np.arange(hull_harmonics + 1))
    c33 = 1025.0 * 9.81 * 40.0
    if points is None:
        points = 1 << int(math.ceil(math.log2(8 * (harmonics + hull_harmonics
                                                   + abs(winding)))))
    return dict(omega=w, amplitudes=[0.5 * height], winding=winding, harmonics=harmonics,
                hull_harmonics=hull_harmonics, points=points, A=A, B=B, F=F,
                C=np.diag([0.0, c33, 3.15e6]), Mh=np.diag([41000.0 - m, 41000.0 - m, 3.45e5]),
                m=m, l=l, I=I, c=c, g=g, pivot=pivot)


def hull_reference_pto(*, x0, pto, tol=1e-10, max_iter=3000, **case) -> dict:
    """The optimum of the hull problem through a real power take-off (``pto``: see
    :func:`_build`) by IPOPT from ``x0`` (the hull from (H) there, the power's parts from
    its sign). Returns ``objective`` (W: the electrical power, the grid's mean of
    ``eta_g p+ - p- / eta_m``, less the copper loss), ``power`` (mechanical), ``x``,
    ``tau`` (the grid's torque), ``status``."""

    gr = _Grid(**case)
    solver, pfun, ofun = _build(gr, tol, max_iter, "MX", False, pto)
    nx = 2 * gr.n + 1
    x0 = np.asarray(x0, dtype=float)
    y0 = gr.solve_hull(x0)
    tau0, rel0 = gr.torque_np(x0, y0)
    p = -tau0 * rel0
    z0 = [x0, y0]
    nc = gr.ny
    lbx = [np.full(nx + gr.ny, -np.inf)]
    if pto.get("efficiency") is not None:
        z0 += [np.maximum(p, 0), np.maximum(-p, 0)]
        lbx.append(np.zeros(2 * gr.M))
        nc += gr.M
    lbg, ubg = np.zeros(nc), np.zeros(nc)
    if pto.get("torque_limit") is not None:
        lbg = np.concatenate((lbg, -np.ones(gr.M)))
        ubg = np.concatenate((ubg, np.ones(gr.M)))
    sol = solver(x0=np.concatenate(z0), lbg=lbg, ubg=ubg, lbx=np.concatenate(lbx))
    z = np.asarray(sol["x"]).ravel()
    x, y = z[:nx], z[nx:nx + gr.ny]
    parts = [x, y] + ([z[nx + gr.ny:nx + gr.ny + gr.M], z[nx + gr.ny + gr.M:]]
                      if pto.get("efficiency") is not None else [])
    tau, rel = gr.torque_np(x, y)
    return {"objective": float(ofun(*parts)), "power": float(pfun(x, y)), "x": x,
            "tau": tau, "p": -tau * rel, "status": solver.stats()["return_status"]}
