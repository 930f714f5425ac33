import sys
from pathlib import Path

# tests/helpers.py is imported as a plain module
sys.path.insert(0, str(Path(__file__).resolve().parent))

from chi2 import alpha  # noqa: E402, F401  (the Šidák-corrected significance fixture, for every test)


def _hypothesis_profiles():
    """Hypothesis budgets of the fuzz tests (tests marked ``fuzz``): a small fixed one in the
    default run (derandomised: the same examples every run), a larger random one when the run
    selects the marker (``python -m pytest -m fuzz``)."""
    from hypothesis import HealthCheck, settings

    common = dict(deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow,
                                                                       HealthCheck.data_too_large])
    settings.register_profile("ci", max_examples=20, derandomize=True, **common)
    settings.register_profile("fuzz", max_examples=600, **common)


def pytest_configure(config):
    from hypothesis import settings

    _hypothesis_profiles()
    expr = (config.getoption("markexpr", "") or "").replace(" ", "")
    settings.load_profile("fuzz" if "fuzz" in expr and "notfuzz" not in expr else "ci")
