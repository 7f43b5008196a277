"""``bearing-lab case new RECORDING [-o CASE.toml]`` and ``bearing-lab case standin SCENE -o FILE``.

``case new`` writes a commented starting validation case from what the recording tells
(channels, units, rate, duration, stored speed); ``case standin`` writes a recording a
user can validate against: a simulated hidden defect with speed jitter, a housing
resonance, machine tones and noise, as UFF 58b (``.uff``) or a Testlab MATLAB export
(``.mat``).  The case format: ``docs/case-format.md``.
"""
from __future__ import annotations

import sys
from pathlib import Path

from . import check_output_path
from ..errors import ValidationCaseError
from ..utils._json import dumps


def _cmd_new(args) -> int:
    from ..utils._files import atomic_open  # the command's imports load when it runs
    from ..validation.newcase import new_case_text
    out = Path(args.output) if args.output else Path(args.recording).with_suffix(".toml")
    if out.suffix != ".toml":
        raise ValidationCaseError(f"-o {args.output}: a case file ends in .toml")
    if out.exists() and not args.force:
        raise ValidationCaseError(f"-o {out}: exists; pass --force to overwrite it")
    if not out.parent.exists():
        raise ValidationCaseError(f"-o {out}: directory {out.parent} does not exist")
    text = new_case_text(args.recording, name=args.name, bearing=args.bearing, speed=args.speed,
                         channel=args.channel, fmt=args.format, sensitivity=args.sensitivity,
                         case_dir=out.parent)
    with atomic_open(out, "w", encoding="utf-8") as fh:
        fh.write(text)
    notes = [line[len("# NOTE: "):] for line in text.splitlines() if line.startswith("# NOTE: ")]
    if args.json:
        print(dumps({"case": str(out), "recording": args.recording, "notes": notes}, indent=1))
        return 0
    for note in notes:
        print(f"bearing-lab case new: note: {note} (see {out})", file=sys.stderr)
    if not args.quiet:
        print(f"{out}: starting case for {args.recording}; give the bearing, load and defect (see the comments), "
              f"then run `bearing-lab validate {out}`")
    return 0


def _cmd_standin(args) -> int:
    from ..sim.scene import parse_set  # the command's imports load when it runs
    from ..validation.standin import make_standin_recording
    check_output_path(args.output, force=args.force, suffixes=(".uff", ".mat"))
    s = make_standin_recording(args.output, scene=args.scene, overrides=parse_set(args.set), rpm=args.rpm,
                               duration=args.duration, fs=args.fs, jitter=args.jitter,
                               resonance_hz=args.resonance_hz, noise_g=args.noise_g, seed=args.seed)
    h = s.hidden
    if args.json:
        print(dumps({"file": str(s.path), "hidden": h}, indent=1))
        return 0
    if args.quiet:
        return 0
    print(f"{s.path}: {h['format']}, {h['duration_s']:g} s at {h['fs']:g} Hz; hidden: scene {h['scene']} "
          f"{' '.join(f'{k}={v}' for k, v in h['overrides'].items())}, {h['rpm']:g} r/min "
          f"(jitter {100 * h['jitter']:g} %), resonance {h['resonance_hz']:g} Hz, noise {h['noise_g']:g} g",
          file=sys.stdout)
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("case", help="validation cases: a starting case for a recording; stand-in recordings",
                              epilog="Exit status: 0 the file is written; 2 bad input (one line on stderr), nothing "
                                     "written. A case's verdict comes from `bearing-lab validate CASE.toml` (see its "
                                     "--help: PASS, KNOWN LIMITATIONS, FAIL).",
                              description="Write a commented starting validation case from a recording (case new), "
                                          "or a stand-in recording with a hidden defect (case standin).")
    sub = p.add_subparsers(dest="case_command", metavar="ACTION")
    n = sub.add_parser("new", help="a commented starting case from what the recording tells")
    n.add_argument("recording", help="the recording (any supported format, or a .nc from bearing-lab import)")
    n.add_argument("-o", "--output", default=None, help="case file to write (default: RECORDING with .toml)")
    n.add_argument("--name", default=None, help="case name (default: the recording's file name)")
    n.add_argument("--bearing", default=None, help="catalog bearing, e.g. 6308 (else left for you to fill in)")
    n.add_argument("--speed", type=float, default=None, help="shaft speed, r/min (else the stored one, or 'estimate')")
    n.add_argument("--channel", default=None, help="channel to compare (default: the file's default channel)")
    n.add_argument("--format", default=None, help="reader name (default: sniffed)")
    n.add_argument("--sensitivity", default=None,
                   help="sensor sensitivity for channels stored in volts, e.g. 9.91mV/g (written to the case)")
    n.add_argument("--force", action="store_true", help="overwrite an existing case file")
    n.add_argument("--json", action="store_true", help="print the case file written and the notes as JSON")
    n.add_argument("-q", "--quiet", action="store_true", help="print nothing but the notes and errors")
    n.set_defaults(func=_cmd_new)
    s = sub.add_parser("standin", help="a recording with a hidden defect, jitter, a resonance, tones and noise")
    s.add_argument("scene", help="built-in scene or scene TOML with the hidden bearing, load and defect")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="scene key (repeatable)")
    s.add_argument("--rpm", type=float, default=1793.0, help="mean shaft speed, r/min (default 1793)")
    s.add_argument("--duration", type=float, default=2.0, help="seconds (default 2)")
    s.add_argument("--fs", type=float, default=20000.0, help="sampling rate, Hz (default 20000)")
    s.add_argument("--jitter", type=float, default=0.005, help="relative speed random walk (default 0.005)")
    s.add_argument("--resonance-hz", type=float, default=4300.0, help="housing/sensor resonance (default 4300)")
    s.add_argument("--noise-g", type=float, default=0.05, help="white sensor noise RMS, g (default 0.05)")
    s.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    s.add_argument("-o", "--output", required=True, help="output file: .uff (UFF 58b) or .mat (Testlab export)")
    s.add_argument("--force", action="store_true", help="overwrite an existing output file")
    s.add_argument("--json", action="store_true", help="print the file and the hidden truth as JSON")
    s.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    s.set_defaults(func=_cmd_standin)
    p.set_defaults(func=lambda a: (p.print_help(), 2)[1])
