"""Stand-in recordings of one rig for the identification tests: a calibration recording with a
known defect (the rig's structural path is identified on it) and recordings of hidden defects."""
from pathlib import Path

from bearing_lab.validation import make_standin_recording

RPM, LOAD_N = 1793.0, 320.0
SIZES = {"paper-O1": (1.0, 1.0), "paper-O2": (3.0, 1.0)}     # along-track length, width B (mm)


def case_text(name, recording, *, length_mm, width_mm, offset_mm=0.0, skew_deg=0.0, path_from=None,
              duration_s=1.0):
    sp = (f'[structural_path]\nfrom_case = "{path_from}"\n' if path_from else "")
    return f'''name = "{name}"
bearing = "6308"
speed = {RPM}

[recording]
file = "{Path(recording).name}"
channel = "Acc"
duration_s = {duration_s}

[load]
radial_n = {LOAD_N}
on = "inner"

[[defect]]
race = "outer"
length_mm = {length_mm}
width_mm = {width_mm}
offset_mm = {offset_mm}
skew_deg = {skew_deg}

{sp}
[tolerances]
bpfo = {{}}
'''


def calibration(d: Path) -> Path:
    """The rig's calibration recording: paper O2 (1 x 3 mm) at H = 0, theta = 0, declared as it is."""
    rec = d / "calib.uff"
    if not rec.exists():
        make_standin_recording(rec, scene="paper-O2", rpm=RPM, duration=2.0, seed=0,
                               overrides={"load.radial_n": LOAD_N})
    case = d / "calib.toml"
    case.write_text(case_text("calib", rec, length_mm=3.0, width_mm=1.0))
    return case


def hidden(d: Path, scene, offset_mm, skew_deg, *, seed, calib: Path, name=None, declared_length_mm=None,
           **case_kw) -> Path:
    """A recording of a hidden defect; its case declares the nominal size (or ``declared_length_mm``) at
    H = 0, theta = 0 and takes the structural path from the calibration case."""
    name = name or f"{scene[-2:]}_H{offset_mm:g}_t{skew_deg:g}"
    rec = d / f"{name}.uff"
    make_standin_recording(rec, scene=scene, rpm=RPM, duration=2.0, seed=seed,
                           overrides={"load.radial_n": LOAD_N, "defect.offset_mm": offset_mm,
                                      "defect.skew_deg": skew_deg})
    length, width = SIZES[scene]
    length = length if declared_length_mm is None else declared_length_mm
    case = d / f"{name}.toml"
    case.write_text(case_text(name, rec, length_mm=length, width_mm=width, path_from=calib, **case_kw))
    return case
