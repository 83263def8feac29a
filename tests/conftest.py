"""Hypothesis profiles: ``ci`` (the default: small, so the suite stays within its time budget)
and ``thorough`` for local runs (``python -m pytest tests/test_properties.py
--hypothesis-profile=thorough``)."""

from hypothesis import HealthCheck, settings

_COMMON = dict(deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                      HealthCheck.filter_too_much])
settings.register_profile("ci", max_examples=4, derandomize=True, database=None, **_COMMON)
settings.register_profile("thorough", max_examples=100, **_COMMON)


def pytest_configure(config):
    """``ci`` unless ``--hypothesis-profile`` names another."""
    if config.getoption("hypothesis_profile", None) is None:
        settings.load_profile("ci")
