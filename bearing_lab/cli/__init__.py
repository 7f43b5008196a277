"""The ``bearing-lab`` command line.

Each sub-command lives in its own module in this package and exposes
``register(subparsers)``; that function adds its parser and sets ``func`` to a
callable taking the parsed ``args`` and returning an exit status.  Errors that
bearing_lab raises on purpose (:class:`bearing_lab.errors.BearingLabError`) are
printed as one line on stderr with exit status 2.

Conventions every command follows (docs/cli.md): ``-q/--quiet`` prints nothing but errors and
warnings; ``--json`` (where a command prints results) prints them as strict JSON on stdout; an
``-o`` file that exists is not overwritten without ``--force``; output cut short by a closed pipe
(``bearing-lab data list | head``) ends quietly.
"""
from __future__ import annotations

import argparse
import gc
import importlib
import io
import os
import sys
from pathlib import Path
import warnings

from .._version import __version__
from ..errors import BearingLabError

# one line per command module; a module registers one or more sub-commands
COMMAND_MODULES = [
    "simulate",   # scenes, simulate
    "recording",  # import, info, data
    "analyze",    # analyze
    "study",      # study
    "validate",   # validate
    "case",       # case new, case standin
    "identify",   # identify (defect geometry from a recording)
    "bench",      # bench
    "sweep",      # sweep (bearing_lab.run_sweep on Dask)
]
#: the module that registers each sub-command: a command's own run builds only that module's
#: parsers (importing the other command modules costs 0.04 s); tests/test_cli_conventions.py
#: checks this table against the whole parser
COMMANDS = {"scenes": "simulate", "simulate": "simulate", "import": "recording", "info": "recording",
            "data": "recording", "analyze": "analyze", "study": "study", "validate": "validate",
            "case": "case", "identify": "identify", "bench": "bench", "sweep": "sweep"}


class _Parser(argparse.ArgumentParser):
    """argparse with the project's error form: one line on stderr, exit status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def check_output_path(text: str, *, force: bool = False, suffixes=(".nc", ".nc4"), flag: str = "-o") -> Path:
    """The CLI's ``-o FILE`` (or another output option, ``flag``): refuse a wrong suffix, a missing
    directory or (without ``force``) an existing file before any work."""
    out = Path(text)
    if out.suffix not in suffixes:
        what = "a netCDF file ending in .nc" if ".nc" in suffixes else "a file ending in " + " or ".join(suffixes)
        raise BearingLabError(f"{flag} {text}: the output must be {what}")
    if not out.parent.exists():
        raise BearingLabError(f"{flag} {text}: directory {out.parent} does not exist")
    size = len(os.fsencode(out.name))
    if size > 255:
        raise BearingLabError(f"{flag} {text}: the file name has {size} bytes; a file name has at most "
                              "255")
    if out.is_dir():
        raise BearingLabError(f"{flag} {text}: is a directory; give a file name ending in {suffixes[0]}")
    if out.exists() and not force:
        raise BearingLabError(f"{flag} {text}: exists; pass --force to overwrite it")
    return out


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The whole command line; with ``command`` (a sub-command's name, see :data:`COMMANDS`) only the
    parsers of the module that registers it (any other name: the whole command line)."""
    parser = _Parser(
        prog="bearing-lab",
        description="Rolling-bearing toolkit: import, simulate, analyse, validate.",
        epilog="Every command: -q/--quiet prints nothing but errors and warnings; --json (where a command "
               "prints results) prints them as JSON; an existing -o file is kept unless --force. Exit status: "
               "0 done; 1 a result that fails (validate: a row fails unexplained; see its --help); 2 bad "
               "input, said in one line on stderr.")
    parser.add_argument("--version", action="version", version=f"bearing_lab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in [COMMANDS[command]] if command in COMMANDS else COMMAND_MODULES:
        importlib.import_module(f".{name}", __name__).register(sub)
    return parser


_WARNED: set = set()


def _warning_line(message, category, filename, lineno, file=None, line=None):
    """Warnings as one line on stderr (no source file and line, no code), each text once per command
    (a study or a validation simulates one scene several times and would repeat it)."""
    text = str(message)
    if text in _WARNED:
        return
    _WARNED.add(text)
    print(f"bearing-lab: warning: {text}", file=sys.stderr if file is None else file)


#: True while main() runs the process's own command line (argv None: the console script, python -m)
_OWN_PROCESS = [False]


def imports_loaded() -> None:
    """A command's handler calls this once its libraries are imported.  In the process's own run
    of the command line, the objects made so far (modules, classes, the registries of numba,
    pandas and xarray: about a million) leave the cyclic garbage collector's sight
    (``gc.freeze``): they live as long as the process, and every later collection, up to the last
    one at exit, would traverse them all again (0.05 s of a 1 s ``simulate``).  A call of
    ``main(argv)`` inside another program (a test, a notebook) changes nothing."""
    if _OWN_PROCESS[0]:
        gc.freeze()


def main(argv=None) -> int:
    _OWN_PROCESS[0] = argv is None
    try:
        return _main(argv)
    finally:
        if _OWN_PROCESS[0]:
            # the process ends with this command: Python's last collection would traverse every
            # object still alive only to free memory the process returns anyway (0.13 s of a 1 s
            # simulate); files are closed by then (every writer closes its own), atexit still runs
            gc.freeze()
        _OWN_PROCESS[0] = False


def _main(argv) -> int:
    warnings.showwarning = _warning_line
    _WARNED.clear()
    for stream in (sys.stdout, sys.stderr):  # a file name in another locale's bytes is printed
        try:                                 # with escapes, never a UnicodeEncodeError
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, io.UnsupportedOperation):
            pass
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(argv[0] if argv else None)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except BrokenPipeError:  # the reader of our stdout went away (`| head`): stop quietly, as `cat` does
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so the interpreter's final flush does not fail again
        return 141  # 128 + SIGPIPE, what the shell reports for a tool killed by the closed pipe
    except BearingLabError as exc:
        print(f"bearing-lab {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # an output path that cannot be written, a file that vanished
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        print(f"bearing-lab {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("bearing-lab: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
