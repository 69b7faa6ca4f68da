r"""Compiled kernel of ``parapend persistence``: many realizations of the pendulum on a sea
record at once, fixed-step classical RK4, the accumulations done as it goes (no trajectory
is stored).

The equation (SI, theta from the upright)::

    theta'' = a (g + z''(t)) sin(theta) - b theta',   a = m l / I,   b = (c + c_g) / I

``z''`` is given on the grid of half steps ``t_j = j h / 2`` over one repeat period (``2 M``
values for ``M`` steps, periodic): the stages of step ``j`` use ``z''`` at ``t_{2j}``,
``t_{2j+1}`` (twice) and ``t_{2j+2}``. Over the window (from step ``k0`` to ``M``) the kernel
integrates, with the same four stages (so the quadratures are those of the augmented ODE),

    S2 = int theta'^2 dt            (harvested c_g S2, dissipated c S2)
    QW = int z'' sin(theta) theta' dt   (the base's work m l QW)

and the angle at the boundaries of the consecutive ``2 Tp`` windows (cubic Hermite
interpolation between steps, from theta and theta' at both ends: fourth order, as the
step): ``throughout`` is 1 when every full window advances at least pi.

``LANES`` realizations advance in lockstep (stage by stage, loops over the lanes), groups
of lanes run in parallel (threads: the kernel releases the GIL); each lane's arithmetic is
the same whichever group or thread computes it (no ``fastmath``), so a realization gives
the same bits in any batch. The sine is :func:`parapend.dynamics._kernel._sin` (the
package's fast sine).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles
from ._kernel import _sin

announce_compiles()

LANES = 8
_PI = math.pi


@nb.njit(inline="always", cache=True)
def _steps(zdd, grp, j, n2, a, g, bb, h, acc, th, om, tho, omo, tt, vv, ath, av, q, w2, s2,
           qw):
    """One classical RK4 step of the ``LANES`` states ``th, om`` of group ``grp`` (``z''``
    at the step's start, middle and end), stage by stage over the lanes (loops without
    branches, which the compiler vectorizes: 1.3 times faster than lane by lane, the same
    bits), with the increments of ``int theta'^2`` (``s2``) and ``int z'' sin(theta)
    theta'`` (``qw``) by the same stages, times ``acc`` (1 inside the window, else 0).
    ``tho, omo`` receive the state before the step; the others are scratch."""
    i1 = 2 * j
    i2 = i1 + 1
    i3 = (i1 + 2) % n2
    h2 = 0.5 * h
    h6 = h / 6.0
    for ln in range(LANES):
        z = zdd[grp, i1, ln]
        sn = _sin(th[ln])
        w = om[ln]
        kk = a * (g + z) * sn - bb[ln] * w
        tho[ln] = th[ln]
        omo[ln] = w
        ath[ln] = w
        av[ln] = kk
        q[ln] = z * sn * w
        w2[ln] = w * w
        tt[ln] = th[ln] + h2 * w
        vv[ln] = w + h2 * kk
    for stage in range(2):  # the two middle stages: the second's step is h / 2, the third's h
        hs = h2 if stage == 0 else h
        for ln in range(LANES):
            z = zdd[grp, i2, ln]
            sn = _sin(tt[ln])
            w = vv[ln]
            kk = a * (g + z) * sn - bb[ln] * w
            ath[ln] += 2.0 * w
            av[ln] += 2.0 * kk
            q[ln] += 2.0 * z * sn * w
            w2[ln] += 2.0 * w * w
            tt[ln] = th[ln] + hs * w
            vv[ln] = om[ln] + hs * kk
    for ln in range(LANES):
        z = zdd[grp, i3, ln]
        sn = _sin(tt[ln])
        w = vv[ln]
        kk = a * (g + z) * sn - bb[ln] * w
        th[ln] += h6 * (ath[ln] + w)
        om[ln] += h6 * (av[ln] + kk)
        s2[ln] += acc * (h6 * (w2[ln] + w * w))
        qw[ln] += acc * (h6 * (q[ln] + z * sn * w))


@nb.njit(cache=True, nogil=True)
def persist_batch(zdd, bdamp, a, g, th0, om0, h, k0, twin, nwin, out, flags, lo, hi):
    """Integrate the groups ``lo`` to ``hi - 1`` of ``zdd`` (without the GIL: threads run
    other groups at the same time).

    Parameters
    ----------
    zdd : float64 (B / LANES, 2M, LANES)
        Base acceleration z'' (m/s^2) at the half steps of one repeat period, lane ``l`` of
        group ``k`` in ``zdd[k, :, l]`` (the lanes' values of one half step side by side).
    bdamp : float64 (B,)
        ``(c + c_g) / I`` of each lane (1/s).
    a, g : float
        ``m l / I`` (1/m) and gravity (m/s^2).
    th0, om0 : float
        The start (rad, rad/s).
    h : float
        The step (s), ``M h = T_r``.
    k0 : int
        The step at which the window starts (``t_w = k0 h``).
    twin : float
        The length of the windows of "rotating throughout" (s, ``2 Tp``).
    nwin : int
        The number of full windows in ``[t_w, T_r]``.
    out : float64 (B, 6)
        Written: theta and theta' at ``t_w``, theta and theta' at ``T_r``, ``S2``, ``QW``.
    flags : int8 (B,)
        Written: 1 rotating throughout, 0 not, -1 non-finite state.
    """
    n2 = zdd.shape[1]
    m = n2 // 2
    for grp in range(lo, hi):
        base = grp * LANES
        th = np.empty(LANES)
        om = np.empty(LANES)
        bb = np.empty(LANES)
        s2 = np.zeros(LANES)
        qw = np.zeros(LANES)
        prev = np.empty(LANES)   # theta at the last window boundary
        ok = np.ones(LANES, dtype=np.int8)
        tho = np.empty(LANES)
        omo = np.empty(LANES)
        tt = np.empty(LANES)
        vv = np.empty(LANES)
        ath = np.empty(LANES)
        av = np.empty(LANES)
        q = np.empty(LANES)
        w2 = np.empty(LANES)
        for ln in range(LANES):
            th[ln] = th0
            om[ln] = om0
            bb[ln] = bdamp[base + ln]
        if k0 == 0:
            for ln in range(LANES):
                out[base + ln, 0] = th0
                out[base + ln, 1] = om0
                prev[ln] = th0
        bound = 1          # index of the next window boundary
        tw = k0 * h
        for j in range(m):
            inside = j >= k0
            _steps(zdd, grp, j, n2, a, g, bb, h, 1.0 if inside else 0.0, th, om, tho, omo,
                   tt, vv, ath, av, q, w2, s2, qw)
            if j + 1 == k0:
                for ln in range(LANES):
                    out[base + ln, 0] = th[ln]
                    out[base + ln, 1] = om[ln]
                    prev[ln] = th[ln]
            elif inside and bound <= nwin:
                t_new = (j + 1) * h
                tb = tw + bound * twin
                while bound <= nwin and tb <= t_new * (1.0 + 1e-15):
                    s = (tb - j * h) / h
                    s = min(max(s, 0.0), 1.0)
                    # cubic Hermite basis on [0, 1]
                    p0 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s)
                    m0 = s * (1.0 - s) * (1.0 - s) * h
                    p1 = s * s * (3.0 - 2.0 * s)
                    m1 = s * s * (s - 1.0) * h
                    for ln in range(LANES):
                        tb_th = p0 * tho[ln] + m0 * omo[ln] + p1 * th[ln] + m1 * om[ln]
                        if tb_th - prev[ln] < _PI:
                            ok[ln] = 0
                        prev[ln] = tb_th
                    bound += 1
                    tb = tw + bound * twin
        for ln in range(LANES):
            r = base + ln
            out[r, 2] = th[ln]
            out[r, 3] = om[ln]
            out[r, 4] = s2[ln]
            out[r, 5] = qw[ln]
            fin = (math.isfinite(th[ln]) and math.isfinite(om[ln])
                   and math.isfinite(s2[ln]) and math.isfinite(qw[ln]))
            flags[r] = ok[ln] if fin else -1


def group(zdd: np.ndarray) -> np.ndarray:
    """Records one a row ``(B, 2M)`` in the kernel's layout ``(G, 2M, LANES)``, the last
    group padded by repeating the last record."""
    pad = (-zdd.shape[0]) % LANES
    if pad:
        zdd = np.concatenate([zdd, np.repeat(zdd[-1:], pad, axis=0)])
    return np.ascontiguousarray(
        np.asarray(zdd, dtype=np.float64).reshape(-1, LANES, zdd.shape[1]).transpose(0, 2, 1))


def run_batch(zdd: np.ndarray, bdamp, *, a: float, g: float, th0: float, om0: float,
              h: float, k0: int, twin: float, nwin: int, lanes: int | None = None):
    """:func:`persist_batch` on the records ``zdd``: one per row, shape ``(B, 2M)``, or
    already grouped (:func:`group`) with ``lanes`` records; each with damping ``bdamp`` (a
    number, or one per record). The padding's results are dropped. Returns
    ``(out, flags)``."""
    grouped = zdd if lanes is not None else group(zdd)
    b = lanes if lanes is not None else zdd.shape[0]
    total = grouped.shape[0] * LANES
    bdamp = np.broadcast_to(np.asarray(bdamp, dtype=np.float64), (b,))
    bdamp = np.ascontiguousarray(np.concatenate([bdamp, np.repeat(bdamp[-1:], total - b)]))
    out = np.empty((total, 6))
    flags = np.empty(total, dtype=np.int8)
    args = (grouped, bdamp, float(a), float(g), float(th0), float(om0), float(h), int(k0),
            float(twin), int(nwin), out, flags)
    groups = grouped.shape[0]
    workers = min(threads(), groups)
    if workers <= 1:
        persist_batch(*args, 0, groups)
    else:  # the groups cut into one contiguous run per thread
        from concurrent.futures import ThreadPoolExecutor

        cuts = np.linspace(0, groups, workers + 1).astype(int)
        with ThreadPoolExecutor(workers) as ex:
            for f in [ex.submit(persist_batch, *args, int(cuts[i]), int(cuts[i + 1]))
                      for i in range(workers)]:
                f.result()
    return out[:b], flags[:b]


def threads() -> int:
    """Threads of :func:`run_batch`: ``numba.get_num_threads()`` (``NUMBA_NUM_THREADS``,
    default the CPUs) in the main process, one in a worker process (``--workers``: the
    processes share the cores)."""
    import multiprocessing

    if multiprocessing.parent_process() is not None:
        return 1
    return int(nb.get_num_threads())
