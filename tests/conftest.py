"""Shared fixtures and hypothesis settings (derandomized: reproducible bit for bit)."""

import matplotlib
import pytest
from hypothesis import HealthCheck, settings

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
