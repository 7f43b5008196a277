"""Case Western Reserve University bearing data (``.mat`` with ``X###_DE_time`` ...).

Why the registry: CWRU files store neither the sampling rate nor units.  The
rate comes from ``bearing_lab/data/recordings.csv`` through :mod:`bearing_lab.datasets`
(record 97 is 48 kHz, the drive-end 12k set 12 kHz); an unregistered record is
refused with a request for ``fs=``.  Values are in g (the Bearing Data Center's
description), converted to m s-2.

Channels are chosen by the variable-name pattern ``X<record>_<DE|FE|BA>_time``,
never by the file's number alone: some files carry another record's variable
names, and some hold two records (then the file name's number, or ``record=``,
picks one).  Channel names: ``DE`` (drive end, the default channel), ``FE`` (fan
end), ``BA`` (base).  The motor speed comes from ``X<record>RPM`` (else the
registry).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..utils._files import sha256_file
from ._base import ENGINES, RecordingBuilder, RecordingReader
from ._matlab import load_mat, mat_variables, mat_version, require_matlab, signal_vector

_CHAN = re.compile(r"^X(\d+)_(DE|FE|BA)_time$")
_RPM = re.compile(r"^X(\d+)RPM$")


class CwruReader(RecordingReader):
    """Read CWRU Bearing Data Center ``.mat`` files."""

    name = "cwru"
    description = "CWRU Bearing Data Center .mat (X###_DE_time, X###_FE_time, X###_BA_time, X###RPM)"
    extensions = (".mat",)
    libraries = ("scipy",)

    def guess_can_open(self, path, head):
        return mat_version(head) is not None and any(_CHAN.match(n) for n in mat_variables(path))

    @staticmethod
    def _check_unclaimed(b, m, found, rec, rpm_var):
        """Refuse signals the CWRU names do not claim: a damaged name would drop a channel.

        A variable as long as the record's channels that is not one of them (another
        record's channel, or a name that lost a letter) is never dropped in silence; the
        user can still read the named channels with ``channels=`` or pick ``record=``.
        """
        lengths = {np.size(m[v]) for v in found[rec].values() if v in m}
        if len(lengths) != 1:
            return
        n = lengths.pop()
        claimed = set(found[rec].values()) | {rpm_var}
        for name, value in m.items():
            if name in claimed or not isinstance(value, np.ndarray) or value.dtype.kind not in "iuf":
                continue
            if value.size == n:
                b.fail(f"variable {name!r} holds {n} samples, as many as record {rec}'s channels "
                       f"({', '.join(found[rec])}), but is not one of them: a damaged variable "
                       "name or a second record; read the named channels with channels=[...] "
                       "or pick record=<number>")

    def open_dataset(self, path, *, channels=None, fs=None, record=None, units="g",
                     checksum=True):
        """Read the drive-end, fan-end and base channels of one CWRU record.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
            Subset of ``"DE"``, ``"FE"``, ``"BA"``.
        fs : float, optional
            Sampling rate, Hz (default: the registry's rate for the record).
        record : int, optional
            Which record's variables to read when the file holds several.
        units : str
            Unit of the stored values (the data centre's: ``"g"``).
        checksum : bool
            Compute ``source_sha256``.

        Returns
        -------
        xarray.Dataset
        """

        path = Path(path)
        b = RecordingBuilder(path, self, units=units, checksum=checksum)
        require_matlab(path, b)
        names = mat_variables(path)
        found, rec, file_no = _pick_record(b, path, names, record)
        if "DE" not in found[rec]:
            b.warn(f"record {rec} has no drive-end (DE) channel")
        rpm_vars = [n for n in names if _RPM.match(n)]
        rpm_var = f"X{rec:03d}RPM" if f"X{rec:03d}RPM" in names else (
            f"X{rec}RPM" if f"X{rec}RPM" in names else (rpm_vars[0] if len(rpm_vars) == 1 else None))
        m = load_mat(path)
        if channels is None and record is None:
            self._check_unclaimed(b, m, found, rec, rpm_var)
        fs, reg = _rate(b, path, rec, file_no, fs)
        order = [c for c in ("DE", "FE", "BA") if c in found[rec]]
        for c in order:
            v = signal_vector(b, m[found[rec][c]], found[rec][c])
            b.add_channel(c, v, None, file_name=found[rec][c], inplace=True,
                          attrs={"location": {"DE": "drive end", "FE": "fan end",
                                              "BA": "base"}[c]})
        rpm = _speed(b, m, rpm_var, reg)
        b.attrs["cwru_record"] = rec
        if file_no is not None and file_no != rec:
            b.attrs["cwru_file_number"] = file_no
        if reg is not None:
            b.attrs.update({"cwru_defect": reg.defect, "cwru_load_hp": reg.load_hp,
                            "cwru_defect_size_in": reg.defect_size_in,
                            "cwru_defect_position": reg.defect_position or None,
                            "bearing": reg.bearing, "registry_name": reg.name})
        return b.build(fs=fs, shaft_speed_rpm=rpm, default_channel="DE", channels=channels)


def _pick_record(b, path, names, record):
    """({record: {"DE": variable, ...}}, the record read, the file name's record number or None)."""
    found = {}
    for n in names:
        m = _CHAN.match(n)
        if m:
            found.setdefault(int(m.group(1)), {})[m.group(2)] = n
    if not found:
        b.fail(f"no CWRU channel variables X###_DE_time/_FE_time/_BA_time (variables: "
               f"{', '.join(names) or 'none'})")
    mnum = re.match(r"^(\d+)", path.name)
    file_no = int(mnum.group(1)) if mnum else None
    if record is not None:
        if int(record) not in found:
            b.fail(f"record={record} has no variables in the file; it holds records "
                   f"{', '.join(map(str, sorted(found)))}")
        rec = int(record)
    elif len(found) == 1:
        rec = next(iter(found))
    elif file_no in found:
        rec = file_no
    else:
        b.fail(f"the file holds variables of records {', '.join(map(str, sorted(found)))}; "
               "pass record=<number> to pick one")
    return found, rec, file_no


def _rate(b, path, rec, file_no, fs):
    """(fs, the registry entry or None).  The rate: ``fs``, else the registry entry with this
    file's sha256 (renamed files, and files whose variables carry another record's number), then
    the file name's record, then the variables' record."""
    cands = [n for n in dict.fromkeys([file_no, rec]) if n is not None]
    by_sha = _registered_by_content(path)
    from .. import datasets  # the registry (csv, importlib.resources) for a CWRU file only
    regs = {n: datasets.cwru_record(n) for n in cands}
    rates = {r.fs_hz for r in regs.values() if r is not None and r.fs_hz}
    reg = regs.get(file_no) or regs.get(rec)
    if by_sha is not None and by_sha.fs_hz:
        reg, rates = by_sha, {by_sha.fs_hz}
    if fs is None:
        if len(rates) == 1:
            fs = rates.pop()
        elif not rates:
            b.fail(f"CWRU record {rec} is not in the registry (bearing_lab/data/recordings.csv), and CWRU "
                   "files do not store their sampling rate; pass fs=12000 or fs=48000 (CLI "
                   "--fs) as the data centre lists it")
        else:
            b.fail(f"records {cands} have different registered rates {sorted(rates)}; pass fs=")
        b.attrs["sampling_rate_source"] = "registry bearing_lab/data/recordings.csv" + (
            f" (file content, sha256, of {by_sha.name})" if reg is by_sha else "")
    else:
        b.attrs["sampling_rate_source"] = "user"
    return fs, reg


def _speed(b, m, rpm_var, reg):
    """The shaft speed, r/min: the file's ``X###RPM`` variable, else the registry's, else None."""
    if rpm_var and np.size(m.get(rpm_var, [])) >= 1:
        value = np.ravel(m[rpm_var])[0] if not isinstance(m[rpm_var], str) else m[rpm_var]
        if isinstance(value, (str, bytes)) or np.iscomplexobj(value):
            b.warn(f"variable {rpm_var} holds {value!r}, not a speed: shaft_speed_rpm unknown")
            return None
        rpm = float(value)
        b.attrs["shaft_speed_source"] = f"file variable {rpm_var}"
        return rpm
    if reg is not None and reg.rpm:
        b.attrs["shaft_speed_source"] = "registry bearing_lab/data/recordings.csv"
        return reg.rpm
    return None


def _registered_by_content(path):
    """The registry entry whose sha256 is this file's (None if none, or the file is large)."""
    if path.stat().st_size > 256 * 2 ** 20:
        return None
    from .. import datasets  # the registry (csv, importlib.resources) for a CWRU file only
    known = [r for r in datasets.load_registry().values() if r.sha256 and r.dataset.startswith("cwru")]
    if not known:
        return None
    digest = sha256_file(path)
    return next((r for r in known if r.sha256 == digest), None)


ENGINES["cwru"] = CwruReader
