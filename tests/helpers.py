"""Test helpers shared across test folders (import as ``from tests.helpers import ...``)."""
import importlib
import os

import pytest

IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")


def require(module: str):
    """Import ``module``; outside CI skip the test when it is missing, in CI fail: every
    dependency of the test extras is installed there, so a missing one is a broken install."""
    if IN_CI:
        try:
            return importlib.import_module(module)
        except ImportError as exc:
            pytest.fail(f"{module} is not importable in CI: {exc}")
    return pytest.importorskip(module)
