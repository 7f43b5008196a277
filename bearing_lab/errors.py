"""Error types of bearing_lab.

Every problem with a user's input (a scene, a recording, an analysis option) or a
solve that cannot continue raises a subclass of :class:`BearingLabError` whose
message names the input and the problem.  The CLI turns these into one line on
stderr and exit status 2; nothing else is allowed to escape as a traceback.
"""


class BearingLabError(Exception):
    """Base of all errors bearing_lab raises on purpose."""


class SceneError(BearingLabError, ValueError):
    """A scene (TOML file, dict or --set override) is invalid or unphysical."""


class RecordingError(BearingLabError, ValueError):
    """A recording file cannot be read, or its content is invalid."""


class AnalysisError(BearingLabError, ValueError):
    """An analysis was asked for something the signal cannot give."""


class SolverError(BearingLabError, RuntimeError):
    """The time integration failed (divergence, step-size underflow, non-finite state)."""


class ValidationCaseError(BearingLabError, ValueError):
    """A validation case file is invalid or names a missing recording."""
