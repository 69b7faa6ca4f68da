"""Shared fixtures and hypothesis settings (derandomized: reproducible bit for bit)."""

import matplotlib
import pytest
from hypothesis import HealthCheck, settings

matplotlib.use("Agg")

settings.register_profile(
    "parapend", derandomize=True, deadline=None, max_examples=25,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("parapend")


@pytest.fixture(scope="session")
def paper():
    import parapend

    return parapend.harmonic(-0.3, 1.8)
