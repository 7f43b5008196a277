"""The Examples sections of the analysis docstrings run and give the printed answers."""
import doctest
import importlib

import pytest

MODULES = ["_spectral", "_speed", "_faults", "_impulse", "_metrics", "pipeline", "accessor", "_cyclo", "_tacho"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    mod = importlib.import_module(f"bearing_lab.analysis.{name}")
    res = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0
    assert res.attempted > 0
