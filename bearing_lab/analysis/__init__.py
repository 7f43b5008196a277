"""Signal analysis (temporary stub during development)."""
from ._spectral import *  # noqa
from ._speed import *  # noqa
