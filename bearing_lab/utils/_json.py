"""JSON that every parser accepts: no NaN/Infinity tokens, numpy types as Python.

Why: ``json.dumps`` writes ``NaN`` and ``Infinity`` for non-finite floats, which
strict parsers (JavaScript's ``JSON.parse``, ``jq``) reject.  Output meant for other
programs (``analyze --json``, ``info --json``, summary files) goes through
:func:`dumps`: a non-finite number becomes ``null`` (the contract's "f|null").
"""
from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["clean", "dumps"]


def clean(v):
    """Return ``v`` with NaN/inf -> None, numpy scalars and arrays -> Python values."""
    if isinstance(v, dict):
        return {str(k): clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [clean(x) for x in v]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.ndarray):
        return clean(v.tolist())
    return v


def dumps(obj, **kwargs) -> str:
    """``json.dumps`` of :func:`clean` (``obj``); refuses to write NaN/Infinity.

    Examples
    --------
    >>> dumps({"a": float("nan"), "b": np.float64(2.5)})
    '{"a": null, "b": 2.5}'
    """
    kwargs.setdefault("default", str)
    return json.dumps(clean(obj), allow_nan=False, **kwargs)
