"""Reader base class, engine registry and the shared Dataset builder.

Why: every format ends in the same Dataset contract (``schema.check_dataset(...,
kind="recording")``), with the same checks (non-finite values, unknown units,
voltage without sensitivity, clipping, flat lines) and the same provenance.  A
format module only finds its channels in the file and hands them to
:class:`RecordingBuilder`; the builder converts to SI, records warnings and
assembles the Dataset.  So a new format is one module that ends with
``ENGINES["name"] = NameReader``.

Warnings convention: non-fatal findings (clipping, flat line, rate snapped,
dropped sets, truncated data kept on request) are issued with
:func:`warnings.warn` (category :class:`RecordingWarning`) *and* stored in the
global attribute ``warnings`` as one string, the messages joined by ``"; "``
(empty string when there are none).  :func:`get_warnings` splits it again.

Shortfalls are never silent: when a file declares more samples than it holds
(a header's point count, a segment's size, a fixed row count), the reader calls
:meth:`RecordingBuilder.shortfall`, which refuses the file unless the user opted
in (``allow_truncated=True``); then the recording says so in ``warnings`` and in
the attributes ``truncated = 1`` and ``declared_samples`` (what the file promised).

Channel naming rule (all readers):

1. a channel is named after the file's own channel identity (UFF: response
   entity name, else node+direction such as ``1+Z``; Testlab: the point name;
   CSV: the column header), cleaned to letters, digits and ``_ + - .``;
2. the public sets use fixed names: CWRU ``DE``, ``FE``, ``BA``; IMS ``b1`` ..
   ``b4`` (8-channel set 1: ``b1x``, ``b1y`` ... ``b4y``); MFPT ``acc``;
   WAV/unnamed columns ``ch1``, ``ch2`` ...;
3. a name that repeats gets ``_2``, ``_3`` ... in file order (``1+Z``, ``1+Z_2``);
4. the global attribute ``default_channel`` names the channel analysis should use
   when none is given: the first acceleration channel in file order (CWRU ``DE``,
   IMS ``b1``), else the first channel.
"""
from __future__ import annotations

import contextvars
import hashlib
import importlib
import importlib.util
from importlib import metadata
import inspect
import json
import os
import re
import sys
import warnings
from abc import ABC, abstractmethod
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import BearingLabError, RecordingError
from .. import units as _units

MIN_RATE_HZ = 1e-3   # slower than a sample every 17 minutes: not a vibration recording
MAX_RATE_HZ = 1e9    # faster than any vibration data-acquisition front end

MAX_RPM = 1e6        # faster than any rolling bearing turns (dental turbines: about 4e5 r/min)


def speed_problem(rpm) -> str | None:
    """None if ``rpm`` is a plausible shaft speed in r/min, else what is wrong with it."""
    try:
        rpm = float(rpm)
    except (TypeError, ValueError):
        return "is not a number"
    if not np.isfinite(rpm):
        return "is not finite"
    if rpm <= 0:
        return "is not positive"
    if rpm > MAX_RPM:
        return f"is faster than any rolling bearing turns (more than {MAX_RPM:.0e} r/min)"
    return None


ENGINES: dict[str, type["RecordingReader"]] = {}
"""Format name -> reader class, in sniffing order (registered by each format module)."""


class RecordingWarning(UserWarning):
    """A non-fatal problem found in a recording (also stored in ``ds.attrs['warnings']``)."""


def get_warnings(ds) -> list[str]:
    """Return the recording's warnings as a list (the attribute is ``"; "``-joined)."""
    text = ds.attrs.get("warnings", "")
    return [w for w in str(text).split("; ") if w]


class RecordingReader(ABC):
    """One file format.

    Subclasses set :attr:`description`, :attr:`extensions` and :attr:`libraries`,
    implement :meth:`guess_can_open` (from the content, not only the name) and
    :meth:`open_dataset` with explicit keyword arguments, and register themselves
    with ``ENGINES["name"] = TheReader`` on the module's last line.
    """

    name: str = ""
    description: str = ""
    extensions: tuple[str, ...] = ()
    libraries: tuple[str, ...] = ("numpy",)
    """Modules the reader needs; their versions go into the provenance."""

    def available(self) -> str | None:
        """Return None when the reader can run, else what to install."""
        for lib in self.libraries:  # found, not imported: the reader imports what it uses
            if lib not in sys.modules and importlib.util.find_spec(lib) is None:
                return f"needs the optional package {lib!r}: pip install bearing_lab[formats]"
        return None

    @abstractmethod
    def guess_can_open(self, path: Path, head: bytes) -> bool:
        """Return True if ``path`` looks like this format (``head``: its first 8 KiB)."""

    @abstractmethod
    def open_dataset(self, path, **options):
        """Read ``path`` into a recording Dataset (explicit keyword arguments in subclasses)."""

    def option_names(self) -> list[str]:
        sig = inspect.signature(self.open_dataset)
        return [p.name for p in sig.parameters.values()
                if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD) and p.name != "path"]


def library_versions(libraries) -> str:
    """Return ``"numpy 2.1.0, pyuff 2.5.8"`` for the given module names."""
    out = []
    for lib in libraries:
        mod = sys.modules.get(lib)
        version = getattr(mod, "__version__", None)
        if version is None:  # from the installed distribution's metadata: no import
            try:
                version = metadata.version(lib)
            except metadata.PackageNotFoundError:
                try:
                    version = getattr(importlib.import_module(lib), "__version__", "?")
                except ImportError:
                    version = "missing"
        out.append(f"{lib} {version}")
    return ", ".join(out)


def file_sha256(path, data=None) -> str:
    """Return the hex sha256 of a file (or of an already mapped buffer ``data``)."""
    h = hashlib.sha256()
    if data is not None:
        mv = memoryview(data)
        for i in range(0, len(mv), 1 << 24):
            h.update(mv[i:i + (1 << 24)])
        return h.hexdigest()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 22), b""):
            h.update(chunk)
    return h.hexdigest()


def read_file(path) -> bytes:
    """Return the whole content of a regular file, refusing a file that changes while read.

    Why not ``mmap``: a mapped file that another program truncates while it is read takes
    the process down with SIGBUS the moment numpy or the checksum touch a page that no
    longer exists; no Python code can catch that.  A plain read of the size ``fstat``
    reports costs the same page-cache copy and turns the same event into a short read,
    refused here with a message.

    Raises
    ------
    RecordingError
        If the file grew, shrank or was rewritten while it was read.
    """
    with open(path, "rb") as fh:
        before = os.fstat(fh.fileno())
        data = fh.read(before.st_size + 1)
        after = os.fstat(fh.fileno())
    if (len(data) != before.st_size or after.st_size != before.st_size
            or after.st_mtime_ns != before.st_mtime_ns):
        raise RecordingError(f"{path}: the file changed while it was read ({before.st_size} bytes "
                             f"when opened, {len(data)} read, {after.st_size} now): another program "
                             "is writing or truncating it; read it again once it is complete")
    return data


_NAME_BAD = re.compile(r"[^A-Za-z0-9_+\-.]+")
_NAME_OK = re.compile(r"[A-Za-z0-9][A-Za-z0-9_+\-.]*")


def clean_name(name, fallback: str) -> str:
    """Clean a channel name to letters, digits and ``_ + - .``; ``fallback`` if empty.

    The name starts with a letter or digit: netCDF refuses variable names that start with
    ``.``, ``+`` or ``-`` (a column ``../../etc [g]`` becomes ``etc``), and the refusal would
    only come when the recording is written, naming the output instead of the input.
    """
    s = _NAME_BAD.sub("_", str(name).strip()).strip("_").lstrip("_+-.")
    if not s or s.upper() == "NONE":
        return fallback
    return s


def _attr_value(v):
    """Make an attribute value netCDF-safe (str, int, float or 1-D numeric array)."""
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if isinstance(v, (int, float, str, np.integer, np.floating)):
        return v
    if isinstance(v, bytes):
        return v.decode("utf-8", errors="replace")
    if isinstance(v, np.ndarray) and v.ndim == 1 and v.dtype.kind in "if":
        return v
    if isinstance(v, (dict, list, tuple)):
        return json.dumps(v, default=str)
    return str(v)


def _runs(mask):
    """Return (starts, lengths) of runs of True in a boolean array."""
    if not mask.any():
        return np.empty(0, int), np.empty(0, int)
    d = np.diff(np.concatenate(([0], mask.view(np.int8), [0])))
    starts = np.flatnonzero(d == 1)
    ends = np.flatnonzero(d == -1)
    return starts, ends - starts


class RecordingBuilder:
    """Collect channels of one file, convert them to SI and build the Dataset.

    Parameters
    ----------
    path : path of the file (named in every message).
    reader : the reader instance (its ``name`` and ``libraries`` go into the attrs).
    units : None, a unit label for every channel, or a dict channel -> label that
        overrides (or supplies) the file's unit labels.
    sensitivity : None, ``"9.91mV/g"`` for every voltage channel, a dict
        channel -> sensitivity, or False to keep voltage channels in V.
    checksum : compute the file's sha256 (``source_sha256``); ``False`` stores "".
    """

    def __init__(self, path, reader, *, units=None, sensitivity=None, checksum=True,
                 clip_volts=5.0):
        self.path = Path(path)
        self.reader = reader
        self.units = units
        self.sensitivity = sensitivity
        self.checksum = checksum
        self.clip_volts = clip_volts
        self.warnings: list[str] = []
        self.channels: dict[str, tuple[np.ndarray, dict]] = {}
        self.attrs: dict = {}
        self.sha256: str | None = None
        self._used_units = set()
        self._sens_ignored: list[str] = []

    # -- messages -------------------------------------------------------------------
    def fail(self, msg: str):
        """Raise :class:`RecordingError` naming the file."""
        raise RecordingError(f"{self.path}: {msg}")

    def warn(self, msg: str):
        """Record a non-fatal finding (attribute ``warnings`` and warnings.warn)."""
        msg = str(msg).replace("; ", ", ")
        self.warnings.append(msg)
        warnings.warn(f"{self.path.name}: {msg}", RecordingWarning, stacklevel=4)

    def shortfall(self, what: str, declared: int, present: int, allow: bool, *,
                  unit: str = "points", declares: str = "the file declares"):
        """A file holds fewer samples than it declares: refuse, or keep them when allowed.

        ``what`` names the part of the file (``"set 2 ('acc')"``); with ``allow`` the
        recording keeps ``present`` samples, warns and records ``declared_samples``.
        """
        what = f"{what}: {declares} {declared} {unit}, {present} present"
        if not allow:
            self.fail(f"{what}: truncated file; pass allow_truncated=True (CLI --allow-truncated) "
                      f"to keep the {present} {unit}")
        self.warn(f"{what}: truncated, kept the {present} {unit} present")
        self.attrs["truncated"] = 1
        self.attrs["declared_samples"] = max(int(self.attrs.get("declared_samples", 0)), int(declared))

    # -- channels -------------------------------------------------------------------
    def unique_name(self, name: str) -> str:
        if name not in self.channels and name != "time":
            return name
        k = 2
        while f"{name}_{k}" in self.channels:
            k += 1
        return f"{name}_{k}"

    def _per_channel(self, option, name, original):
        if isinstance(option, dict):
            if name in option:
                self._used_units.add(name)
                return option[name]
            if original in option:
                self._used_units.add(original)
                return option[original]
            return None
        return option

    def add_channel(self, name, values, label, *, already_si=False, quantity=None,
                    attrs=None, file_name=None, inplace=False):
        """Add one channel.

        Parameters
        ----------
        name : cleaned channel name (made unique here).
        values : 1-D numeric array as stored in the file.
        label : the file's unit label for the channel (None or "" if it has none).
        already_si : the stored values are already SI (Testlab MAT stores MKS and
            labels the display unit): ``label`` is only recorded.
        quantity : physical quantity when the file says it and the label does not.
        attrs : extra variable attributes (file metadata).
        file_name : the channel's name in the file, for ``units``/``sensitivity`` dicts.
        inplace : the reader no longer needs ``values``: scale it in place (saves a copy).
        """
        if not _NAME_OK.fullmatch(str(name)):  # a reader's own name (UFF node "-5+Z"): netCDF-safe
            name = clean_name(name, f"ch{len(self.channels) + 1}")
        name = self.unique_name(name)
        original = file_name if file_name is not None else name
        x = np.asarray(values)
        if x.ndim != 1:
            self.fail(f"channel {name!r} has shape {x.shape}; expected one dimension")
        if x.dtype.kind == "c":
            self.fail(f"channel {name!r} holds complex values; a recorded time signal is real")
        if x.dtype.kind not in "iuf":
            self.fail(f"channel {name!r} holds {x.dtype} values, not numbers")
        if x.dtype != np.float64:
            x = x.astype(np.float64)
            inplace = True
        with np.errstate(all="ignore"):
            total = float(np.add.reduce(x)) if x.size else 0.0
        bad = None if np.isfinite(total) else ~np.isfinite(x)  # one cheap pass when all is well
        if bad is not None and bad.any():
            first = int(np.flatnonzero(bad)[0])
            self.fail(f"channel {name!r} holds {int(bad.sum())} NaN/Inf values (first at sample "
                      f"{first}); the file is corrupt or has gaps: repair or cut it")
        override = self._per_channel(self.units, name, original)
        raw_label = "" if label is None else str(label).strip()
        use_label = override if override is not None else raw_label
        try:
            unit = _units.lookup_unit(use_label, what=f"channel {name!r}")
        except RecordingError as exc:
            self.fail(str(exc))
        vattrs = {}
        sens = self._per_channel(self.sensitivity, name, original)
        if unit.quantity == "voltage" and not already_si:
            volts = x * unit.factor if unit.factor != 1.0 else x
            vmax = float(np.max(np.abs(volts))) if volts.size else 0.0
            if self.clip_volts and vmax >= 0.99 * self.clip_volts:
                self.warn(f"channel {name!r} reaches {vmax:.3g} V, at the ±{self.clip_volts:g} V "
                          "swing of an IEPE input: probable clipping")
            if sens is False or (isinstance(sens, str) and sens.lower() in ("none", "off", "v")):
                si, si_unit, q = volts, "V", "voltage"
            elif sens is None or sens is True:
                self.fail(f"channel {name!r} is in {use_label or 'V'}; a voltage channel needs a "
                          "sensor sensitivity: pass sensitivity='9.91mV/g' (CLI --sensitivity), "
                          "or sensitivity=False to keep volts")
            else:
                try:
                    s = _units.parse_sensitivity(sens)
                except RecordingError as exc:
                    self.fail(str(exc))
                si, si_unit, q = s.to_si(volts), s.unit.si, s.unit.quantity
                vattrs["sensitivity"] = s.text
        else:
            if sens not in (None, False, True):
                self._sens_ignored.append(name)
            if already_si or (unit.factor == 1.0 and unit.offset == 0.0):
                si = x
            elif inplace and x.flags.writeable:
                si = np.multiply(x, unit.factor, out=x)
                if unit.offset:
                    si += unit.offset
            else:
                si = x * unit.factor + unit.offset
            si_unit = unit.si
            q = quantity or unit.quantity
        self._flag_shape(name, si)
        vattrs.update({"units": si_unit, "original_units": raw_label if override is None
                       else str(override), "quantity": q})
        if override is not None:
            vattrs["file_units"] = raw_label or "none"
        if file_name is not None and file_name != name:
            vattrs["file_channel"] = str(file_name)
        for k, v in (attrs or {}).items():
            if v is not None and k not in vattrs:
                vattrs[k] = _attr_value(v)
        self.channels[name] = (si, vattrs)
        return name

    def _flag_shape(self, name, x):
        n = x.size
        if n < 2:
            return
        lo, hi = float(x.min()), float(x.max())
        if lo == hi:
            self.warn(f"channel {name!r} is a flat line (all {n} samples equal {lo:g})")
            return
        for ext, word in ((hi, "maximum"), (lo, "minimum")):
            at = x == ext
            if np.count_nonzero(at) < 3:  # the usual case: one sample at the extreme
                continue
            starts, lengths = _runs(at)
            long = lengths >= 3
            if long.any():
                self.warn(f"channel {name!r}: {int(lengths[long].sum())} samples in "
                          f"{int(long.sum())} runs stuck at the {word} {ext:.6g}: probable clipping")
        # longest run of equal consecutive samples, from the change points only
        limit = max(100, n // 100)
        same = x[1:] == x[:-1]
        if np.count_nonzero(same) < limit - 1:  # no run that long can exist: skip the scan
            return
        change = np.flatnonzero(~same)
        bounds = np.concatenate(([-1], change, [n - 1]))
        lengths = np.diff(bounds)
        k = int(np.argmax(lengths))
        longest = int(lengths[k])
        if longest >= limit:
            self.warn(f"channel {name!r} is flat for {longest} samples from sample "
                      f"{int(bounds[k]) + 1} (dropout or stuck sensor?)")

    # -- dataset --------------------------------------------------------------------
    def select(self, channels):
        """Keep only ``channels`` (str or list), in that order; unknown names fail."""
        if channels is None:
            return
        wanted = [channels] if isinstance(channels, str) else list(channels)
        missing = [c for c in wanted if c not in self.channels]
        if missing:
            self.fail(f"no channel {missing[0]!r}; the file has {', '.join(self.channels)}")
        self.channels = {c: self.channels[c] for c in wanted}

    def _plausible_speed(self, rpm):
        """The stored speed if plausible; else None, a warning and ``file_shaft_speed_rpm``
        (the vibration data are fine: they are kept, only the speed is dropped)."""
        if rpm is None:
            return None
        problem = speed_problem(rpm)
        if problem is None:
            return float(rpm)
        self.warn(f"the stored shaft speed {rpm!r} r/min {problem}: not used (give the speed with "
                  "--rpm)")
        self.attrs["file_shaft_speed_rpm"] = str(rpm)
        return None

    def build(self, *, fs, t0=0.0, time=None, shaft_speed_rpm=None, default_channel=None,
              data=None, channels=None):
        """Assemble and check the Dataset.

        Parameters
        ----------
        fs : sampling rate, Hz.
        t0 : time of the first sample, s (the time coordinate is ``t0 + k / fs``).
        time : explicit time values (uneven time base), overrides ``fs``/``t0``.
        shaft_speed_rpm : stored when known.
        default_channel : overrides the rule "first acceleration channel".
        data : an mmap/bytes of the whole file to hash (avoids reading it again).
        channels : channel selection (see :meth:`select`).
        """
        if isinstance(self.units, dict):
            extra = set(self.units) - self._used_units
            if extra:
                self.fail(f"units= names channel(s) {sorted(extra)} that the file does not have; "
                          f"it has {', '.join(self.channels)}")
        if self._sens_ignored:
            self.warn(f"sensitivity ignored for channel(s) {', '.join(self._sens_ignored)}: "
                      "they are not in volts")
        self.select(channels)
        if not self.channels:
            self.fail("no channels found")
        lengths = {n: v.size for n, (v, _) in self.channels.items()}
        if len(set(lengths.values())) != 1:
            self.fail(f"channels have different lengths {lengths}; read them separately with "
                      "channels=[...]")
        n = next(iter(lengths.values()))
        if n < 2:
            self.fail(f"only {n} sample(s): not a time history")
        if time is None:
            try:
                fs = float(fs)
            except (TypeError, ValueError):
                self.fail(f"sampling rate {fs!r} is not a number; pass fs=<Hz>")
            if not (np.isfinite(fs) and fs > 0):
                self.fail(f"sampling rate {fs!r} Hz is not positive; pass fs=<Hz>")
            t = float(t0) + np.arange(n, dtype=np.float64) / fs
        else:
            t = np.asarray(time, dtype=np.float64)
            if t.size != n:
                self.fail(f"time column has {t.size} values for {n} samples")
            dt = np.diff(t)
            if not np.all(np.isfinite(t)) or not np.all(dt > 0):
                k = int(np.flatnonzero(~(dt > 0))[0]) if not np.all(dt > 0) else 0
                self.fail(f"time values are not strictly increasing (at sample {k + 1}); "
                          "sort or repair the time column, or pass fs= and drop it")
            fs = 1.0 / float(np.median(dt))
        if not MIN_RATE_HZ <= fs <= MAX_RATE_HZ:
            self.fail(f"sampling rate {fs:.6g} Hz is outside {MIN_RATE_HZ:g} Hz .. {MAX_RATE_HZ:.0e} "
                      "Hz: not a rate of a vibration recording (a damaged increment, or a wrong "
                      "fs=/time unit)")
        if self.sha256 is None:
            # after parsing, so the bytes come from the page cache (or the reader's map)
            self.sha256 = file_sha256(self.path, data) if self.checksum else ""
        rpm = self._plausible_speed(shaft_speed_rpm)
        q_acc = [k for k, (_, a) in self.channels.items() if a.get("quantity") == "acceleration"]
        default = default_channel if default_channel in self.channels else \
            (q_acc[0] if q_acc else next(iter(self.channels)))
        attrs = {
            "sampling_rate_hz": float(fs),
            "bearing_lab_version": __version__,
            "source_file": str(self.path.resolve()),
            "source_sha256": self.sha256,
            "reader": self.reader.name,
            "reader_libraries": library_versions(self.reader.libraries),
            "warnings": "; ".join(self.warnings),
            "default_channel": default,
            "start_time_s": float(t[0]),
            "n_samples": int(n),
        }
        if rpm is not None:
            attrs["shaft_speed_rpm"] = rpm
        for k, v in self.attrs.items():
            if v is not None and k not in attrs:
                attrs[k] = _attr_value(v)
        rec = RecordingArrays(t, self.channels, attrs)
        if ARRAYS_ONLY.get():
            return rec
        try:
            return rec.to_dataset()
        except BearingLabError as exc:  # pragma: no cover - a reader bug
            self.fail(str(exc))


#: Set by :func:`bearing_lab.io.read_arrays`: :meth:`RecordingBuilder.build` then returns the
#: :class:`RecordingArrays` instead of the Dataset (no xarray import, for ``bearing-lab info``).
ARRAYS_ONLY = contextvars.ContextVar("bearing_lab_io_arrays_only", default=False)


class _Channel:
    """One channel of :class:`RecordingArrays`: the few Variable attributes ``info`` reads."""
    __slots__ = ("values", "attrs", "dims")

    def __init__(self, values, attrs):
        self.values, self.attrs, self.dims = values, attrs, ("time",)

    @property
    def dtype(self):
        return self.values.dtype


class RecordingArrays:
    """A checked recording as plain numpy arrays and attributes, before it becomes a Dataset.

    Everything :meth:`RecordingBuilder.build` checks has been checked; :meth:`to_dataset` makes
    the contract Dataset.  It answers the read-only part of the Dataset interface that a summary
    needs (``attrs``, ``sizes``, ``data_vars``, ``ds["time"].values``), so ``bearing-lab info``
    prints a recording without importing xarray and pandas (a third of a second).
    """

    def __init__(self, time, channels, attrs):
        self.time = time
        self.data_vars = {k: _Channel(v, a) for k, (v, a) in channels.items()}
        self.attrs = attrs
        self.sizes = {"time": int(time.size)}

    def __getitem__(self, name):
        if name == "time":
            return _Channel(self.time, dict(_TIME_ATTRS))
        return self.data_vars[name]

    def to_dataset(self):
        """The recording Dataset of :mod:`bearing_lab.schema` (checked against it)."""
        import xarray as xr  # `info` reads plain arrays, without xarray
        from .. import schema  # schema (6 ms) when a Dataset is made: `info` reads plain arrays
        tvar = xr.Variable("time", self.time, dict(_TIME_ATTRS))
        data_vars = {k: xr.Variable("time", c.values, c.attrs) for k, c in self.data_vars.items()}
        ds = xr.Dataset(data_vars, coords={"time": tvar}, attrs=self.attrs)
        schema.check_dataset(ds, kind="recording")
        return ds


_TIME_ATTRS = {"units": "s", "long_name": "time", "standard_name": "time"}
