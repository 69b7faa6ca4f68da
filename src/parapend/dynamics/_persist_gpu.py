r"""The GPU path of ``parapend persistence`` (``--gpu``): the kernel of
:mod:`._persist_kernel`, one CUDA thread per lane (numba.cuda), the same equation, stages,
quadratures and window bookkeeping. Imported only when asked for; never needed otherwise.

A launch takes a whole ``Tp`` column (:func:`run_column_gpu`): one unit record ``z''`` per
realization and step size among the column's cells (``Hs = 1``, laid out half step by half
step so that the threads of a warp, neighbouring realizations, read neighbouring values)
and per lane a cell's scale (its ``Hs``), damping and step, so every ``Hs`` x generator
damping x realization of the column runs at once; the state, the accumulations and the
window bookkeeping stay in registers, and the results come back in one transfer. ``z''``
is made on the GPU by CuPy's inverse FFT when CuPy is installed (else on the CPU and
copied).

The GPU's sine and its fused multiply-adds give other bits than the CPU kernel: the same
statistics within their intervals, not the same numbers (a GPU map is another map in a
store: ``gpu`` is part of its identity).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["THREADS", "available", "run_batch_gpu", "run_column_gpu"]

#: CUDA threads per block
THREADS = 128
_KERNEL = None
#: numba.cuda, set on first use (a module global: the kernel reads ``cuda.grid`` from here,
#: as numba's CUDA simulator expects)
cuda = None


def available() -> str:
    """Why the GPU path cannot run here ("" when it can)."""
    try:
        from numba import cuda
    except ImportError:
        return "needs numba's CUDA support (python -m pip install numba-cuda)"
    try:
        if not cuda.is_available():
            return "no CUDA GPU found (drop --gpu)"
    except Exception as err:  # noqa: BLE001 - a driver that does not load
        return f"the CUDA driver did not load ({type(err).__name__}); drop --gpu"
    return ""


def _kernel():
    global _KERNEL, cuda
    if _KERNEL is not None:
        return _KERNEL
    from numba import cuda as numba_cuda

    cuda = numba_cuda

    @numba_cuda.jit
    def persist_gpu(zf, nrec, off, steps, hstep, start, wins, scale, bdamp, a, g, th0, om0,
                    twin, out, flags):
        lane = cuda.grid(1)
        if lane >= scale.size * nrec:
            return
        cell = lane // nrec
        rec = lane - cell * nrec
        base = off[cell] + rec  # z'' at half step i: zf[base + i nrec]
        hs = scale[cell]
        b = bdamp[cell]
        m = steps[cell]
        n2 = 2 * m
        h = hstep[cell]
        k0 = start[cell]
        nwin = wins[cell]
        th = th0
        om = om0
        s2 = 0.0
        qw = 0.0
        ok = 1
        prev = th0
        if k0 == 0:
            out[lane, 0] = th0
            out[lane, 1] = om0
        bound = 1
        tw = k0 * h
        h2 = 0.5 * h
        h6 = h / 6.0
        z3 = hs * zf[base]
        for j in range(m):
            z1 = z3
            z2 = hs * zf[base + (2 * j + 1) * nrec]
            z3 = hs * zf[base + ((2 * j + 2) % n2) * nrec]
            t1 = th
            w1 = om
            sn1 = math.sin(t1)
            f1 = a * (g + z1) * sn1 - b * w1
            t2 = t1 + h2 * w1
            w2 = w1 + h2 * f1
            sn2 = math.sin(t2)
            f2 = a * (g + z2) * sn2 - b * w2
            t3 = t1 + h2 * w2
            w3 = w1 + h2 * f2
            sn3 = math.sin(t3)
            f3 = a * (g + z2) * sn3 - b * w3
            t4 = t1 + h * w3
            w4 = w1 + h * f3
            sn4 = math.sin(t4)
            f4 = a * (g + z3) * sn4 - b * w4
            th = t1 + h6 * (w1 + 2.0 * w2 + 2.0 * w3 + w4)
            om = w1 + h6 * (f1 + 2.0 * f2 + 2.0 * f3 + f4)
            if j >= k0:
                s2 += h6 * (w1 * w1 + 2.0 * w2 * w2 + 2.0 * w3 * w3 + w4 * w4)
                qw += h6 * (z1 * sn1 * w1 + 2.0 * z2 * sn2 * w2 + 2.0 * z2 * sn3 * w3
                            + z3 * sn4 * w4)
            if j + 1 == k0:
                out[lane, 0] = th
                out[lane, 1] = om
                prev = th
            elif j >= k0 and bound <= nwin:
                t_new = (j + 1) * h
                tb = tw + bound * twin
                while bound <= nwin and tb <= t_new * (1.0 + 1e-15):
                    s = (tb - j * h) / h
                    s = min(max(s, 0.0), 1.0)
                    p0 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s)
                    m0 = s * (1.0 - s) * (1.0 - s) * h
                    p1 = s * s * (3.0 - 2.0 * s)
                    m1 = s * s * (s - 1.0) * h
                    tb_th = p0 * t1 + m0 * w1 + p1 * th + m1 * om
                    if tb_th - prev < math.pi:
                        ok = 0
                    prev = tb_th
                    bound += 1
                    tb = tw + bound * twin
        out[lane, 2] = th
        out[lane, 3] = om
        out[lane, 4] = s2
        out[lane, 5] = qw
        fin = (math.isfinite(th) and math.isfinite(om) and math.isfinite(s2)
               and math.isfinite(qw))
        flags[lane] = ok if fin else -1

    _KERNEL = persist_gpu
    return _KERNEL


def _device_records(zus):
    """The records ``zus`` (a list of (B, 2M_g) arrays, NumPy or CuPy, the same B) on the
    GPU as one flat array, each laid out ``(2M_g, B)``; and the offset of each."""
    from numba import cuda

    sizes = [z.shape[0] * z.shape[1] for z in zus]
    off = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    if all(hasattr(z, "__cuda_array_interface__") for z in zus):
        import cupy as cp

        flat = cp.concatenate([cp.ascontiguousarray(z.T).ravel() for z in zus])
        return cuda.as_cuda_array(flat), off
    flat = np.concatenate([np.ascontiguousarray(np.asarray(z, dtype=np.float64).T).ravel()
                           for z in zus])
    return cuda.to_device(flat), off


def run_column_gpu(zus, cells: dict, *, a: float, g: float, th0: float, om0: float,
                   twin: float):
    """One launch over ``C x B`` lanes (``C`` cells, ``B`` records): the unit records
    ``zus`` (a list of (B, 2M_g) arrays, NumPy or CuPy: one per step size ``g``), record
    ``r`` of group ``cells["group"][c]`` times ``cells["scale"][c]`` with damping
    ``cells["bdamp"][c]`` (``(c + c_g) / I``, 1/s), step ``cells["h"][c]``, window start
    ``cells["k0"][c]`` and ``cells["nwin"][c]`` windows in lane ``c B + r``. Returns ``(out,
    flags)`` as NumPy arrays of ``C B`` rows (:func:`._persist_kernel.persist_batch`'s
    columns), copied back at once."""
    from numba import cuda

    nrec = int(zus[0].shape[0])
    d_z, off = _device_records(zus)
    grp = np.asarray(cells["group"], dtype=np.int64)
    m = np.array([z.shape[1] // 2 for z in zus], dtype=np.int64)[grp]
    args = [off[grp], m] + [np.asarray(cells[k], dtype=t) for k, t in (
        ("h", np.float64), ("k0", np.int64), ("nwin", np.int64), ("scale", np.float64),
        ("bdamp", np.float64))]
    lanes = grp.size * nrec
    d_out = cuda.device_array((lanes, 6), dtype=np.float64)
    d_flags = cuda.device_array(lanes, dtype=np.int8)
    _kernel()[(lanes + THREADS - 1) // THREADS, THREADS](
        d_z, nrec, *(cuda.to_device(np.ascontiguousarray(x)) for x in args), float(a),
        float(g), float(th0), float(om0), float(twin), d_out, d_flags)
    return d_out.copy_to_host(), d_flags.copy_to_host()


def run_batch_gpu(zdd, bdamp, *, a: float, g: float, th0: float, om0: float, h: float,
                  k0: int, twin: float, nwin: int):
    """:func:`._persist_kernel.run_batch` on the GPU: the records ``zdd`` (B, 2M, NumPy or
    CuPy) as they are, one damping ``bdamp`` (a number) for all; ``(out, flags)`` as NumPy
    arrays."""
    bd = np.asarray(bdamp, dtype=np.float64)
    if bd.size != 1:
        raise ValueError("run_batch_gpu: one damping for all the records")
    cells = {"group": [0], "scale": [1.0], "bdamp": bd.reshape(1), "h": [h], "k0": [k0],
             "nwin": [nwin]}
    return run_column_gpu([zdd], cells, a=a, g=g, th0=th0, om0=om0, twin=twin)


def acceleration_gpu(heave_rows, n: int, duration: float):
    """``z''`` on ``n`` points per record on the GPU (CuPy): ``heave_rows`` (K, kmax + 1)
    complex heave spectra, one inverse real FFT per row. None without CuPy."""
    try:
        import cupy as cp
    except ImportError:
        return None
    z = cp.asarray(heave_rows)
    w2 = (2 * math.pi * cp.arange(z.shape[1]) / duration) ** 2
    spec = cp.zeros((z.shape[0], n // 2 + 1), dtype=cp.complex128)
    spec[:, :z.shape[1]] = -w2 * z * (n / 2)
    return cp.fft.irfft(spec, n, axis=1)
