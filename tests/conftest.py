"""Shared fixtures and hypothesis settings (derandomized: reproducible bit for bit)."""

import os

# One BLAS thread. The solvers work on small matrices (a Newton step at N = 24 is 49 x 49),
# where OpenBLAS threads only spin: on a loaded 2-core machine one property test took 300+ s
# with the default threads and 19 s with one. NumPy is already imported when pytest loads
# this file (a plugin imports it), so the environment variables alone come too late for the
# running process: threadpoolctl sets the loaded library's thread count; the variables are
# for subprocesses (CLI runs, Dask workers).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from threadpoolctl import threadpool_limits  # noqa: E402

threadpool_limits(1)

import matplotlib  # noqa: E402
import pytest  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402

matplotlib.use("Agg")

# Derandomized (the same examples on every run, no example database), no deadline (shared,
# loaded machines), and few examples: the default run stays fast; tests marked ``slow`` ask
# for more with ``@settings(max_examples=...)``.
settings.register_profile(
    "parapend", derandomize=True, database=None, deadline=None, max_examples=25,
    print_blob=True, suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("parapend")


@pytest.fixture(scope="session")
def paper():
    import parapend

    return parapend.harmonic(-0.3, 1.8)


@pytest.fixture(scope="session", autouse=True)
def _one_bem_cache_per_session():
    """The BEM cache (``PARAPEND_CACHE``, or ``~/.cache/parapend``) is shared by the whole
    session, so that each body the tests use is solved by Capytaine once. A test or fixture
    that needs a cold or a private cache sets its own with ``monkeypatch`` (restored after
    it); one that changed the variable for good would send every later test to an empty
    cache, to solve its bodies again: this fails the session at its end instead."""
    before = os.environ.get("PARAPEND_CACHE")
    yield
    assert os.environ.get("PARAPEND_CACHE") == before, (
        f"a test changed PARAPEND_CACHE from {before!r} to "
        f"{os.environ.get('PARAPEND_CACHE')!r} without restoring it")


@pytest.fixture(scope="session")
def sphere_nc(tmp_path_factory):
    """The coarse floating sphere of tests/test_buoy_cli.py solved by Capytaine once a
    session and written as a dataset (``--hydro``), for every module that runs a buoy on it."""
    from test_buoy_cli import _capytaine_dataset

    return _capytaine_dataset(tmp_path_factory.mktemp("hydro") / "sphere.nc")
