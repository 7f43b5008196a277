"""Signal analysis (temporary stub during development)."""
from ._spectral import *  # noqa
from ._speed import *  # noqa
from ._faults import *  # noqa
from ._metrics import *  # noqa
from ._impulse import *  # noqa
from .pipeline import analyze, plot_analysis  # noqa
