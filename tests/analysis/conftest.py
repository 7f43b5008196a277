"""Make the analysis test helpers (analysis_synth, analysis_recordings) importable.

The suite runs with ``--import-mode=importlib``, which does not put test
directories on sys.path.
"""
import sys
from pathlib import Path

_here = str(Path(__file__).resolve().parent)
if _here not in sys.path:
    sys.path.insert(0, _here)
