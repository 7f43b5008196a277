"""JSON that every parser accepts: no NaN/Infinity tokens, numpy types as Python.

Why: ``json.dumps`` writes ``NaN`` and ``Infinity`` for non-finite floats, which
strict parsers (JavaScript's ``JSON.parse``, ``jq``) reject.  Output meant for other
programs (``analyze --json``, ``info --json``, summary files) goes through
:func:`dumps`: a non-finite number becomes ``null`` (the contract's "f|null").
"""
from __future__ import annotations

import json
import math
import sys

__all__ = ["clean", "dumps"]


def clean(v):
    """Return ``v`` with NaN/inf -> None, numpy scalars and arrays -> Python values."""
    if isinstance(v, dict):
        return {str(k): clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [clean(x) for x in v]
    if isinstance(v, bool):
        return v
    np = sys.modules.get("numpy")  # a numpy value exists only once numpy is imported: the CLI's
    if np is not None:             # parsers import this module without numpy
        if isinstance(v, np.bool_):
            return bool(v)
        if isinstance(v, np.integer):
            return int(v)
        if isinstance(v, np.ndarray):
            return clean(v.tolist())
    if isinstance(v, float) or (np is not None and isinstance(v, np.floating)):
        return float(v) if math.isfinite(v) else None
    return v


def dumps(obj, **kwargs) -> str:
    """``json.dumps`` of :func:`clean` (``obj``); refuses to write NaN/Infinity.

    Examples
    --------
    >>> import numpy as np
    >>> dumps({"a": float("nan"), "b": np.float64(2.5)})
    '{"a": null, "b": 2.5}'
    """
    kwargs.setdefault("default", str)
    return json.dumps(clean(obj), allow_nan=False, **kwargs)
