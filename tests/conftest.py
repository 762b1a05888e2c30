"""Shared fixtures: floating-point errors raise, and a seeded random generator."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from threadpoolctl import threadpool_limits

# The suite's matrices are small: on one BLAS thread it runs about a fifth faster here
# (17.9 s against 22.8 s on four of its numeric files) and its timings stay steady.
# numpy is already loaded when this runs (a pytest plugin imports it), so the limit is
# set through threadpoolctl for this process, and through the environment for the
# command lines the tests start; a value the caller exported wins.
if "OPENBLAS_NUM_THREADS" not in os.environ:
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    _ONE_BLAS_THREAD = threadpool_limits(limits=1, user_api="blas")

# CI runs a bounded budget; set HYPOTHESIS_PROFILE=nightly for the long fuzzing run.
settings.register_profile(
    "ci", max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile(
    "nightly", max_examples=10_000, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile(__import__("os").environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture(autouse=True)
def _raise_on_floating_point_errors():
    """Turn silent NaN/overflow into errors, as py-pde does; underflow stays quiet."""
    old = np.seterr(all="raise", under="ignore")
    yield
    np.seterr(**old)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator, so failures reproduce."""
    return np.random.default_rng(20230503)


def pytest_terminal_summary(terminalreporter):
    """Print the bad-input table's size and pass count in every run's summary (issue 7)."""
    counts = {}
    for outcome in ("passed", "failed"):
        counts[outcome] = sum(
            1
            for report in terminalreporter.stats.get(outcome, [])
            if "test_bad_input_table.py::test_bad_input[" in report.nodeid
            and report.when == "call"
        )
    total = counts["passed"] + counts["failed"]
    if total:
        terminalreporter.write_line(
            f"bad-input table: {total} rows run, {counts['passed']} passed, "
            f"{counts['failed']} failed"
        )
