"""The Examples sections of the analysis (and shared helpers') docstrings run and give the printed answers."""
import doctest
import importlib

import pytest

MODULES = ["analysis._spectral", "analysis._speed", "analysis._faults", "analysis._impulse", "analysis._metrics",
           "analysis.pipeline", "_accessor", "analysis._cyclo", "analysis._tacho", "analysis.inputs", "errors",
           "utils.figures"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    mod = importlib.import_module(f"bearing_lab.{name}")
    res = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0
    assert res.attempted > 0
