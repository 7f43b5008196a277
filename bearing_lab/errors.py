"""Error types of bearing_lab.

Every problem with a user's input (a scene, a recording, an analysis option) or a
solve that cannot continue raises a subclass of :class:`BearingLabError` whose
message names the input and the problem.  The CLI turns these into one line on
stderr and exit status 2; nothing else is allowed to escape as a traceback.
"""


class BearingLabError(Exception):
    """Base of all errors bearing_lab raises on purpose.

    See Also
    --------
    SceneError, RecordingError, AnalysisError, SolverError, ValidationCaseError
    """


class SceneError(BearingLabError, ValueError):
    """A scene (TOML file, dict or --set override) is invalid or unphysical."""


class RecordingError(BearingLabError, ValueError):
    """A recording file cannot be read, or its content is invalid."""


class RecordingOptionError(RecordingError):
    """A reader was given options it does not take.

    ``unknown`` holds those names, ``accepted`` the reader's own; a caller that can do without
    an option (the command line's ``--fs``, applied after reading when the reader has none)
    checks ``unknown`` instead of the message.
    """

    def __init__(self, message: str, *, unknown=(), accepted=()):
        super().__init__(message)
        self.unknown = tuple(unknown)
        self.accepted = tuple(accepted)


class AnalysisError(BearingLabError, ValueError):
    """An analysis was asked for something the signal cannot give."""


class SolverError(BearingLabError, RuntimeError):
    """The time integration failed (divergence, step-size underflow, non-finite state)."""


class ValidationCaseError(BearingLabError, ValueError):
    """A validation case file is invalid or names a missing recording."""


def check_choice(value, allowed, where: str, error: type = BearingLabError):
    """Return ``value`` if it is one of ``allowed``, else raise ``error`` with the one wording used
    for every option that takes one of a few values::

        <where>: invalid value 'x'; allowed values are 'a', 'b' and 'c'

    ``where`` names the input (a scene key, a parameter, a command-line option); ``error`` is
    an exception type, or any callable taking the message and returning the exception.

    Examples
    --------
    >>> check_choice("hann", ("hann", "boxcar"), "window")
    'hann'
    >>> check_choice("flat", ("hann", "boxcar"), "window", AnalysisError)
    Traceback (most recent call last):
    ...
    bearing_lab.errors.AnalysisError: window: invalid value 'flat'; allowed values are 'hann' and 'boxcar'
    """
    allowed = tuple(allowed)
    try:
        ok = value in allowed
    except TypeError:          # an unhashable value against a set or dict
        ok = False
    if ok:
        return value
    names = [repr(a) for a in allowed]
    listed = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]
    raise error(f"{where}: invalid value {value!r}; allowed values are {listed}")
