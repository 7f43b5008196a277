"""``da.bearing.<name>(...)``: registered by :mod:`bearing_lab._accessor` (also when a
recording is opened or a scene simulated, without importing this package first)."""
from .._accessor import BearingAccessor  # noqa: F401
