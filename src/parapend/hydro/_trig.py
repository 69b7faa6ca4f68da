"""Weighted Gram matrices of trigonometric columns from one FFT of the weight.

A map whose columns are ``f_i(s) = scale_i cos(freq_i s)`` or ``scale_i sin(freq_i s)``
on the uniform grid ``s_j = 2 pi j / M`` (the pendulum's motion and its derivatives, the
hull's harmonics and the Galerkin projection are all such maps) has
``sum_j w_j f_i(s_j) g_l(s_j)`` read off the DFT ``W`` of ``w`` by the product formulas
(``cos a cos b = (cos(a-b) + cos(a+b)) / 2`` and so on): two gathers per entry instead of
``M`` multiply-adds, exact on the grid (indices taken modulo ``M``: the grid's own
aliasing). :class:`parapend.hydro.hull.HullProblem` assembles its Hessian, its sensitivity
and its hull matrix this way.
"""

from __future__ import annotations

import numpy as np
import scipy.fft

from ._hull_kernel import fused_gram

__all__ = ["FusedGram", "GramPlan", "TrigColumns"]


class TrigColumns:
    """Columns ``scale_i * (cos if kind_i == 0 else sin)(freq_i s)``."""

    def __init__(self, freq, kind, scale):
        self.freq = np.asarray(freq, dtype=np.int64)
        self.kind = np.asarray(kind, dtype=np.int64)
        self.scale = np.asarray(scale, dtype=float)

    def __len__(self) -> int:
        return self.freq.size

    def matrix(self, m: int) -> np.ndarray:
        """The (M, n) matrix of the columns on the grid."""
        s = 2 * np.pi * np.arange(m) / m
        arg = np.outer(s, self.freq)
        return np.where(self.kind == 0, np.cos(arg), np.sin(arg)) * self.scale


def _half(i, c, m: int):
    """Indices ``i`` into ``[Re W, Im W]`` (2M) of a real weight's DFT moved to its half
    spectrum ``[Re R, Im R]`` (``R = W_0..W_{M/2}``, 2 (M/2 + 1)), with the signs: ``W_k =
    conj(W_{M-k})``."""
    k, im = i % m, i >= m
    kk = np.minimum(k, m - k)
    sign = np.where(im & (k > m // 2), -1.0, 1.0)
    return np.where(im, m // 2 + 1 + kk, kk), c * sign


class GramPlan:
    """``G(w) = sum_j w_j a_i(s_j) b_l(s_j)`` for two :class:`TrigColumns`, as
    ``G = c1 * V[i1] + c2 * V[i2]`` with ``V = [Re R, Im R]``, ``R = rfft(w)``
    (:func:`spectra`)."""

    def __init__(self, a: TrigColumns, b: TrigColumns, m: int):
        fa, fb = a.freq[:, None], b.freq[None, :]
        minus, plus = (fa - fb) % m, (fa + fb) % m
        ka, kb = a.kind[:, None], b.kind[None, :]
        half = 0.5 * np.outer(a.scale, b.scale)
        cos_part = ka == kb  # cos cos, sin sin: the real parts (C_k = Re W_k)
        # C_{a-b} +- C_{a+b} (cos cos: +, sin sin: -); S_{a+b} +- S_{a-b} with S_k = -Im W_k
        # (sin cos: S_P + S_D; cos sin: S_P - S_D)
        self.i1, self.c1 = _half(np.where(cos_part, minus, m + minus),
                                 np.where(cos_part, half, np.where(ka == 1, -half, half)), m)
        self.i2, self.c2 = _half(np.where(cos_part, plus, m + plus),
                                 np.where(cos_part, np.where(ka == 0, half, -half), -half), m)

    def __call__(self, v: np.ndarray) -> np.ndarray:
        return self.c1 * v[self.i1] + self.c2 * v[self.i2]


class FusedGram:
    """A sum of Gram matrices ``sum_p G_p(w_{k_p})`` (each :class:`GramPlan` ``p`` on the
    weight ``k_p``, transposed where asked) in one gather from the stacked spectra, the
    gathers of each entry stored compressed (row pointers ``ptr`` over the entries in row
    order, then their spectrum indices ``idx`` and coefficients ``coef``): the zero
    coefficients (a hull column of one DOF in a map of another, half of them and more)
    are left out, and a symmetric sum keeps the entries on and above the diagonal only."""

    def __init__(self, terms, m: int, symmetric: bool = False):
        """``terms``: ``(plan, k, transposed)`` of one shape (after the transposition);
        ``symmetric``: the sum is symmetric (each term's transpose among the terms, or
        square with symmetric columns)."""
        self.symmetric = bool(symmetric)
        idx, coef = [], []
        for plan, k, tr in terms:
            for i, c in ((plan.i1, plan.c1), (plan.i2, plan.c2)):
                idx.append((i.T if tr else i) + 2 * (m // 2 + 1) * k)
                coef.append(c.T if tr else c)
        idx, coef = np.stack(idx, axis=-1), np.stack(coef, axis=-1)  # (n1, n2, P)
        n1, n2, _ = idx.shape
        keep = coef != 0.0
        if symmetric:
            keep &= (np.arange(n2)[None, :] >= np.arange(n1)[:, None])[:, :, None]
        self.shape = (n1, n2)
        self.ptr = np.zeros(n1 * n2 + 1, dtype=np.int32)
        np.cumsum(keep.reshape(n1 * n2, -1).sum(axis=1), out=self.ptr[1:])
        self.idx = np.ascontiguousarray(idx[keep], dtype=np.int32)
        self.coef = np.ascontiguousarray(coef[keep], dtype=float)

    @classmethod
    def empty(cls) -> FusedGram:
        """No terms (an absent block: gathers nothing)."""
        g = cls.__new__(cls)
        g.symmetric, g.shape = False, (0, 0)
        g.ptr = np.zeros(1, dtype=np.int32)
        g.idx = np.zeros(0, dtype=np.int32)
        g.coef = np.zeros(0)
        return g

    def arrays(self) -> tuple:
        """``(ptr, idx, coef, n1, n2, symmetric)``: the compiled gather's arguments."""
        return self.ptr, self.idx, self.coef, self.shape[0], self.shape[1], self.symmetric

    def __call__(self, v: np.ndarray) -> np.ndarray:
        """``v`` the stacked spectra of :func:`spectra` (the gathers compiled:
        :func:`parapend.hydro._hull_kernel.fused_gram`)."""
        return fused_gram(np.ascontiguousarray(v).ravel(), *self.arrays())


def spectra(weights) -> np.ndarray:
    """``[Re R, Im R]`` (K, 2 (M/2 + 1)) of the K real weights (K, M), ``R`` the half
    spectrum (``scipy.fft.rfft``: for these short rows its call costs less than NumPy's)."""
    w = scipy.fft.rfft(np.asarray(weights, dtype=float), axis=-1)
    return np.concatenate((w.real, w.imag), axis=-1)
