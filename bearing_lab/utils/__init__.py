"""Helpers every part of the package uses; none of them knows about bearings.

_files.py   -- atomic writes (a reader sees the old file or the new one), checksums, the cache folder
_json.py    -- one JSON rule for every output (NaN and inf as null, numpy scalars and arrays)
figures.py  -- new_figure(): figures as objects, shown inline in Jupyter, no backend switching;
               figure_png(): a figure as base64 PNG for a self-contained page
"""
