"""The hull's Gram matrices from one half-spectrum FFT of the weight (``hydro/_trig.py``)
against the product ``A^T diag(w) B`` of the columns sampled on the grid (a second method),
and the kernel's loop product against NumPy's.
The compiled pointwise weights (``hydro/_hull_kernel.py``) are checked through the
gradient and Hessian they make, against central differences (tests/test_hull_kernel.py,
tests/test_hull_pto.py)."""

import numpy as np
import pytest

from parapend.hydro._trig import FusedGram, GramPlan, TrigColumns, spectra


@pytest.mark.parametrize("m", [64, 63, 128])
def test_gram_plans_equal_the_sampled_products(m):
    rng = np.random.default_rng(m)
    # frequencies past M/2 and past M: the grid's aliasing, which the product also has
    a = TrigColumns(rng.integers(0, m + 9, 7), rng.integers(0, 2, 7), rng.normal(size=7))
    b = TrigColumns(rng.integers(0, m + 9, 5), rng.integers(0, 2, 5), rng.normal(size=5))
    w = rng.normal(size=(2, m))
    am, bm = a.matrix(m), b.matrix(m)
    g0, g1 = (am.T @ (wk[:, None] * bm) for wk in w)
    v = spectra(w)
    scale = np.abs(am).max() * np.abs(bm).max() * np.abs(w).sum()
    assert np.abs(GramPlan(a, b, m)(v[0]) - g0).max() < 1e-14 * scale
    fused = FusedGram([(GramPlan(a, b, m), 0, False), (GramPlan(b, a, m), 1, True)], m)
    assert np.abs(fused(v) - (g0 + g1)).max() < 1e-14 * scale


def test_symmetric_fused_gram_gathers_half_and_mirrors():
    m = 64
    rng = np.random.default_rng(7)
    a = TrigColumns(rng.integers(0, 40, 6), rng.integers(0, 2, 6), rng.normal(size=6))
    b = TrigColumns(rng.integers(0, 40, 6), rng.integers(0, 2, 6), rng.normal(size=6))
    w = rng.normal(size=(2, m))
    am, bm = a.matrix(m), b.matrix(m)
    ab = am.T @ (w[1][:, None] * bm)
    want = am.T @ (w[0][:, None] * am) + ab + ab.T
    terms = [(GramPlan(a, a, m), 0, False), (GramPlan(a, b, m), 1, False),
             (GramPlan(a, b, m), 1, True)]
    v = spectra(w)
    got = FusedGram(terms, m, symmetric=True)(v)
    assert np.abs(got - want).max() < 1e-13 * np.abs(want).max()
    assert np.array_equal(got, got.T)


def test_kernel_transposed_product_equals_numpy():
    """The compiled kernel's loop product ``a^T x`` (a loop, so that it does not compile
    apart) against NumPy's, zeros in the skipped operand included."""
    from parapend.hydro._hull_kernel import _tx

    rng = np.random.default_rng(7)
    a = rng.normal(size=(6, 4)) * (rng.random((6, 4)) > 0.3)
    x = rng.normal(size=6) * (rng.random(6) > 0.3)
    assert np.allclose(_tx(a, x), a.T @ x, rtol=1e-14, atol=1e-14)
