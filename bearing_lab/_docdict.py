"""Shared parameter descriptions for numpydoc docstrings (the MNE ``docdict`` / ``fill_doc`` pattern).

A parameter described the same way in many functions is written once here, and a docstring holds
the placeholder on a line of its own, indented like the other parameters::

    @fill_doc
    def envelope(x, fs):
        '''...

        Parameters
        ----------
        x : array_like
            Signal.
        %(fs)s
        '''

:func:`fill_doc` replaces the line with the entry, every line of it indented like the placeholder.
An unknown key raises ``KeyError`` naming the function and the key when the module is imported (the
docs build and the tests import every public module).  Only placeholder lines are touched: a ``%``
elsewhere in a docstring stays as written.  No third-party import (``bearing-lab --help`` imports
modules that use it).
"""
from __future__ import annotations

import re

__all__ = ["docdict", "fill_doc"]

#: key -> numpydoc parameter entry (first line ``name : type``, then the description, 4-space indent)
docdict: dict[str, str] = {}

# ---- signals
docdict["fs"] = """fs : float
    Sampling rate, Hz."""
docdict["duration"] = """duration : float, optional
    Simulated record length, s (``output.duration_s``; default: the scene's)."""

# ---- scenes
docdict["scene"] = """scene : str, path, dict or Scene
    A built-in scene name (:func:`~bearing_lab.sim.list_scenes`), a scene TOML file, a mapping
    of the same keys, or a :class:`~bearing_lab.sim.Scene`."""
docdict["overrides"] = """**overrides
    Scene keys as ``bearing-lab simulate --set`` takes them (``speed_rpm``, ``load.radial_n``,
    ``defect.offset_mm``, ``fidelity`` ...; ``docs/scene-keys.md``), e.g.
    ``**{"load.radial_n": 480}``."""

# ---- validation
docdict["case"] = """case : ValidationCase
    A checked case (:func:`~bearing_lab.validation.load_case`)."""
docdict["mirror"] = """mirror : str or Path, optional
    Directory holding the public recordings (default: the ``BEARING_LAB_MIRROR`` environment
    variable)."""
docdict["progress"] = """progress : bool
    Show progress bars (on standard error)."""
docdict["out_dir"] = """out_dir : str or Path
    Folder the report is written into (created when missing)."""

# ---- report
docdict["rows"] = """rows : list of dict
    Validation rows as :func:`~bearing_lab.validation.make_row` makes them."""

_PLACEHOLDER = re.compile(r"^([ \t]*)%\((\w+)\)s[ \t]*$", re.MULTILINE)


def fill_doc(obj):
    """Replace each ``%(key)s`` line of ``obj.__doc__`` by ``docdict[key]``; return ``obj``.

    Parameters
    ----------
    obj : function or class
        Its docstring is rewritten in place (nothing happens when it has none, e.g. under
        ``python -OO``).

    Returns
    -------
    obj
        The same object, so that ``fill_doc`` works as a decorator.

    Raises
    ------
    KeyError
        A placeholder names a key that ``docdict`` does not hold.

    Examples
    --------
    >>> @fill_doc
    ... def f(x, fs):
    ...     '''Parameters
    ...     ----------
    ...     %(fs)s
    ...     '''
    >>> print(f.__doc__.splitlines()[2:4])
    ['    fs : float', '        Sampling rate, Hz.']
    """
    doc = obj.__doc__
    if not doc:
        return obj

    def entry(m):
        indent, key = m.group(1), m.group(2)
        if key not in docdict:
            raise KeyError(f"{getattr(obj, '__qualname__', obj)!r}: the docstring placeholder %({key})s "
                           f"is not in bearing_lab._docdict.docdict")
        return "\n".join(indent + line if line else line for line in docdict[key].splitlines())

    obj.__doc__ = _PLACEHOLDER.sub(entry, doc)
    return obj
