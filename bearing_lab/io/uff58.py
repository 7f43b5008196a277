"""Universal File Format dataset 58 (ASCII) and 58b (binary): Testlab/catman exports.

Why our own parser instead of ``pyuff.UFF(...).read_sets()``: pyuff 2.5.8 drops a
truncated last set silently, returns 42 values for a header that promises
2 508 876, lets NaN tokens through, reports 0 from ``get_set_formats()`` for
binary sets and reads the whole file twice (once to find the blocks, once to
parse them) with a per-value ``struct.unpack``.  This module reads the fixed
headers itself (the same field widths as pyuff; the sets and their headers are found by
:mod:`._uff_sets`, the data blocks decoded here), reads the file once (a plain read, not a
memory map: a map of a file truncated while it is read kills the process), seeks past
each binary payload while scanning (so a 1 GB 58b is scanned header by header)
and converts each payload with one ``numpy.frombuffer``.  pyuff stays the
reference: the tests compare our values with pyuff's on every real file, the
export (:mod:`bearing_lab.io.export`) is read back by pyuff, and the benchmark
measures both.

Handled: point counts checked against the header (refused, or kept with a
warning when ``allow_truncated=True``); truncated payloads; the rate snapped to
a whole number of Hz when the printed increment (E13.5) rounded it (the file's
value kept in ``file_sampling_rate_hz``); non-zero start time kept in the time
coordinate; repeated node/direction made unique (``1+Z``, ``1+Z_2``); uneven
abscissa kept as the time coordinate (refused when not increasing); dataset 164
unit factors applied when a channel has no unit label; CR/LF or padding around a
binary payload; both byte orders, 4- and 8-byte floats; D exponents.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..errors import RecordingError, check_choice
from ._base import ENGINES, MAX_RATE_HZ, MIN_RATE_HZ, RecordingBuilder, RecordingReader, clean_name, read_file
from ._uff_sets import decode_text, scan_sets

_MIN_164_FACTOR = 1e-12   # dataset 164 factors scale by 1e±3 (mm), 39.37 (in): 1e±12 is no unit
# Universal File dataset numbers seen in test and modal files (others are refused as damage)
_KNOWN_DATASETS = {15, 18, 55, 58, 82, 151, 164, 773, 780, 781, 1710, 1858, 2400, 2411, 2412,
                   2414, 2420, 2429, 2430, 2431, 2432, 2435, 2437, 2467, 2477}
_DIRS = {1: "+X", 2: "+Y", 3: "+Z", -1: "-X", -2: "-Y", -3: "-Z", 4: "+RX", 5: "+RY", 6: "+RZ",
         -4: "-RX", -5: "-RY", -6: "-RZ"}
# UFF specific data type -> quantity (for channels whose label does not say)
_SPEC_QUANTITY = {8: "displacement", 11: "velocity", 12: "acceleration", 15: "pressure",
                  13: "force", 9: "force", 17: "time"}
_SPEC_SI = {"displacement": ("m", 1, 0), "velocity": ("m/s", 1, 0), "acceleration": ("m/s2", 1, 0),
            "pressure": ("Pa", -1, 1), "force": ("N", 0, 1)}


class Uff58Reader(RecordingReader):
    """Read UFF dataset 58/58b time histories (one channel per set)."""

    name = "uff58"
    description = "Universal File Format dataset 58 / 58b time histories (.uff, .unv)"
    extensions = (".uff", ".unv", ".uf", ".58")
    libraries = ("numpy",)

    def guess_can_open(self, path, head):
        lines = head.lstrip(b"\xef\xbb\xbf").splitlines()
        lines = [ln for ln in lines[:6] if ln.strip()]
        return len(lines) >= 2 and lines[0].strip() == b"-1" and \
            re.fullmatch(rb"\d+b?", lines[1].split()[0] if lines[1].split() else b"") is not None

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None,
                     allow_truncated=False, fs=None, snap_rate=True, byte_order=None,
                     checksum=True):
        """Read the time-history sets of a UFF file into one recording Dataset.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
            Channel names to read (others are not converted); needed when sets
            have different rates or lengths.
        units : str or dict, optional
            Unit label for every channel, or channel -> label, overriding the file's.
        sensitivity : str, dict or False, optional
            For voltage channels, e.g. ``"9.91mV/g"``.
        allow_truncated : bool
            Keep the values present when a header promises more (warning) instead
            of refusing the file.
        fs : float, optional
            Sampling rate, Hz, replacing the header's increment.
        snap_rate : bool
            Snap a rate that the printed increment rounded (51200.13 -> 51200 Hz).
        byte_order : "little" or "big", optional
            Override the byte order the binary headers declare (for files whose
            header is wrong; refused otherwise with a clear message).
        checksum : bool
            Compute ``source_sha256``.

        Returns
        -------
        xarray.Dataset
        """
        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        check_choice(byte_order, (None, "little", "big"), f"{path}: byte_order", RecordingError)
        self._force_bo = {None: None, "little": 1, "big": 2}[byte_order]
        data = read_file(path)
        return self._read(data, b, channels, allow_truncated, fs, snap_rate)

    # -- scanning -------------------------------------------------------------------
    def _scan(self, mm, b):
        """The file's sets (:func:`._uff_sets.scan_sets`), with the byte order the caller forced."""
        return scan_sets(mm, b, self._force_bo)

    # -- data -----------------------------------------------------------------------
    def _values(self, mm, st, b, allow_truncated):
        h = st.header
        if st.binary:
            nbytes = st.data_end - st.data_start
            count = nbytes // st.itemsize
            dt = np.dtype(("<" if st.bo == 1 else ">") + ("f8" if st.double else "f4"))
            raw = np.frombuffer(mm, dtype=dt, count=count, offset=st.data_start)
            if self._implausible(raw) and not self._implausible(raw.byteswap()):
                order = "little" if st.bo == 1 else "big"
                other = "big" if st.bo == 1 else "little"
                b.fail(f"set {st.index}: the header declares {order}-endian data but the values "
                       f"only make sense {other}-endian: the byte order in the file is wrong; "
                       f"pass byte_order='{other}' to read it anyway")
            vals = raw.astype(np.float64)
            del raw
        else:
            text = mm[st.data_start:st.data_end]
            if b"D" in text or b"d" in text:
                text = text.replace(b"D", b"E").replace(b"d", b"e")
            toks = text.split()
            vals = self._parse_tokens(toks, st, b)
            if vals.size != st.n_values and vals.size > 0:
                fixed = self._fixed_width(text, st)
                if fixed is not None and fixed.size == st.n_values:
                    vals = fixed
        got, want = vals.size, st.n_values
        if st.unclosed and not st.binary and got and not bytes(mm[st.data_start:st.data_end]) \
                .rstrip(b" \t").endswith((b"\n", b"\r")):
            # the file ends inside the data: the last number may be cut short
            got -= st.per_point
            vals = vals[:got]
        what = f"set {st.index} ({h.get('rsp_ent_name') or h.get('id1')!r})"
        if got > want:
            b.fail(f"{what}: header promises {h['num_pts']} points, {got // st.per_point} present "
                   "(more values than promised): corrupt header or data")
        if got != want:
            pts = got // st.per_point
            if pts < 2:
                b.fail(f"{what}: header promises {h['num_pts']} points, {pts} present: truncated, "
                       "nothing to keep")
            b.shortfall(what, h["num_pts"], pts, allow_truncated, declares="header promises")
            vals = vals[:pts * st.per_point]
        elif st.unclosed:
            msg = (f"{what}: no closing '-1' delimiter: the file ends inside or right after this "
                   "set (later sets may be missing)")
            if not allow_truncated:
                b.fail(msg + "; pass allow_truncated=True (CLI --allow-truncated) to read it as it is")
            b.warn(msg + ": truncated file read as it is")
            b.attrs["truncated"] = 1
        return vals

    @staticmethod
    def _implausible(v):
        """True if many values are NaN/Inf or of absurd magnitude (wrong byte order)."""
        v = np.asarray(v[:4096], dtype=np.float64)
        if v.size == 0:
            return False
        with np.errstate(over="ignore", invalid="ignore"):
            a = np.abs(v)
            ok = np.isfinite(v) & ((a == 0) | ((a > 1e-30) & (a < 1e30)))
        return ok.mean() < 0.9

    def _parse_tokens(self, toks, st, b):
        try:
            return np.array(toks, dtype=np.float64) if toks else np.empty(0)
        except ValueError:
            for i, t in enumerate(toks):
                try:
                    float(t)
                except ValueError:
                    b.fail(f"set {st.index}: corrupt number {bytes(t[:30])!r} at value {i} of the "
                           "data block")
            raise  # pragma: no cover

    def _fixed_width(self, text, st):
        """Parse fixed-width fields (numbers printed without separating blanks)."""
        h = st.header
        if st.complex:
            return None
        widths = [13] if not st.double else ([20] if h["abscissa_spacing"] == 1 else [13, 20])
        out = []
        try:
            for line in text.splitlines():
                line = line.rstrip()
                i, k = 0, 0
                while i < len(line):
                    w = widths[k % len(widths)]
                    tok = line[i:i + w]
                    if tok.strip():
                        out.append(float(tok))
                    i += w
                    k += 1
        except ValueError:
            return None
        return np.asarray(out)

    # -- channels -------------------------------------------------------------------
    def _channel_name(self, st, k):
        h = st.header
        ent = h.get("rsp_ent_name", "")
        if ent and ent.upper() != "NONE":
            return clean_name(ent, f"ch{k}")
        node, d = h.get("rsp_node", 0), h.get("rsp_dir", 0)
        if node:
            return f"{node}{_DIRS.get(d, '')}" if d else f"node{node}"
        return f"ch{k}"

    def _unit_from_164(self, st, units164, b):
        """Unit label from the ordinate's spec data type and exponents when the label is empty."""
        h = st.header
        q = _SPEC_QUANTITY.get(h["ordinate_spec_data_type"])
        if q is None or q not in _SPEC_SI:
            return None, None
        label = _SPEC_SI[q][0]
        factor = 1.0
        if units164 is not None:
            lf, ff = units164
            e_len, e_force = h["ordinate_len_unit_exp"], h["ordinate_force_unit_exp"]
            try:
                with np.errstate(all="ignore"):
                    factor = float(1.0 / (np.float64(lf) ** e_len * np.float64(ff) ** e_force))
            except (OverflowError, ZeroDivisionError):
                factor = math.inf
            if not (math.isfinite(factor) and _MIN_164_FACTOR <= factor <= 1.0 / _MIN_164_FACTOR):
                b.fail(f"set {st.index}: the unit factors of dataset 164 (length {lf:g}, force {ff:g}) "
                       f"with the ordinate's unit exponents (length {e_len}, force {e_force}) would "
                       f"scale every value by {factor:.3g}: not a unit conversion, the units set is "
                       "damaged; give the channels' unit with units='m/s2' (CLI --units)")
        return label, factor

    def _read(self, mm, b, channels, allow_truncated, fs_override, snap_rate):
        if len(mm) == 0:  # pragma: no cover - open_recording refuses empty files earlier
            b.fail("file is empty")
        sets = self._scan(mm, b)
        if not sets:
            b.fail("no datasets found between '-1' delimiters")
        units164, times = self._sort_sets(mm, sets, b)
        picked = self._pick(times, channels, b)
        h0 = times[picked[0][0]].header
        time = self._add_channels(mm, b, times, picked, units164, allow_truncated)
        fs = self._rate(b, h0, time, fs_override, snap_rate)
        for k in ("id1", "id2", "id3", "id4", "id5"):
            if h0.get(k) and h0[k].upper() != "NONE":
                b.attrs[f"uff_{k}"] = h0[k]
        b.attrs["uff_n_sets"] = len(sets)
        if units164 is not None:
            b.attrs["uff_164_length_factor"], b.attrs["uff_164_force_factor"] = units164
        return b.build(fs=fs, t0=h0["abscissa_min"], time=time, data=mm, channels=None)

    def _sort_sets(self, mm, sets, b):
        """(dataset 164's unit factors or None, the time-history sets): model and units sets
        read, other known datasets dropped with a warning, unknown ones refused."""
        units164 = None
        others, nontime = [], []
        times = []
        for st in sets:
            if st.type == 164 and not st.binary:
                units164 = self._parse_164(mm, st, b)
            elif st.type == 151 and not st.binary:
                lines = bytes(mm[st.block[0]:st.block[1]]).splitlines()
                if len(lines) >= 2:
                    b.attrs["uff_model_name"] = decode_text(lines[0]).strip()
                    b.attrs["uff_model_description"] = decode_text(lines[1]).strip()
                if len(lines) >= 6:
                    b.attrs["uff_program"] = decode_text(lines[5]).strip()
            elif st.type == 58:
                h = st.header
                is_time = h["func_type"] == 1
                time_axis = h.get("abscissa_spec_data_type") in (17, 0, 1)
                if is_time != time_axis:  # the header contradicts itself: never drop in silence
                    b.fail(f"set {st.index}: function type {h['func_type']} with abscissa data type "
                           f"{h.get('abscissa_spec_data_type')}: a time history (type 1) has a time "
                           "abscissa (17) and other functions do not; the header is damaged")
                if is_time:
                    times.append(st)
                else:
                    nontime.append(f"{st.index} (function type {h['func_type']})")
            elif st.type in _KNOWN_DATASETS:
                others.append(st.type)
            else:
                b.fail(f"set {st.index} at byte {st.start} has dataset type {st.type}, which is not a "
                       "Universal File dataset: the file is damaged")
        if not times:
            found = sorted({s.type for s in sets})
            extra = f"; 58 sets that are not time responses: {', '.join(nontime)}" if nontime else ""
            b.fail(f"no time-history datasets (dataset 58 with function type 1) in the file: "
                   f"it holds datasets {', '.join(map(str, found))}{extra}; export a time history "
                   "from the measurement software")
        if others:
            b.warn(f"dropped {len(others)} non-time-history sets (datasets "
                   f"{', '.join(map(str, sorted(set(others))))})")
        if nontime:
            b.warn(f"dropped dataset-58 sets that are not time responses: {', '.join(nontime)}")
        return units164, times

    def _pick(self, times, channels, b):
        """[(index in ``times``, channel name)] of the channels read: names first (cheap), then
        the selection; refused when the picked sets differ in rate, length or start."""
        names, used = [], {}
        for k, st in enumerate(times, 1):
            base = self._channel_name(st, k)
            used[base] = used.get(base, 0) + 1
            names.append(base if used[base] == 1 else f"{base}_{used[base]}")
        if channels is not None:
            wanted = [channels] if isinstance(channels, str) else list(channels)
            missing = [c for c in wanted if c not in names]
            if missing:
                b.fail(f"no channel {missing[0]!r}; the file has {', '.join(names)}")
            picked = [(names.index(c), c) for c in wanted]
        else:
            picked = list(enumerate(names))
        groups = {}
        for i, name in picked:
            h = times[i].header
            key = (h["num_pts"], h["abscissa_spacing"], h["abscissa_inc_text"],
                   h["abscissa_min_text"])
            groups.setdefault(key, []).append((i, name))
        if len(groups) > 1:
            desc = "; ".join(f"{', '.join(n for _, n in g)}: {k[0]} points, increment {k[2]} s"
                             for k, g in groups.items())
            b.fail(f"channels differ in rate, length or start ({desc}); read one group at a time "
                   "with channels=[...]")
        return picked

    def _add_channels(self, mm, b, times, picked, units164, allow_truncated):
        """Decode and add the picked channels; return the uneven time base (None when even)."""
        time = None
        for i, name in picked:
            st = times[i]
            h = st.header
            vals = self._values(mm, st, b, allow_truncated)
            x = None
            if h["abscissa_spacing"] == 0:
                k = 3 if st.complex else 2
                x, vals = vals[0::k], vals[1::k] if not st.complex else vals[1::k] + 1j * vals[2::k]
            elif st.complex:
                vals = vals[0::2] + 1j * vals[1::2]
            if st.complex:
                b.fail(f"set {st.index} ({name!r}) holds complex values (ordinate data type "
                       f"{h['ord_data_type']}): not a time history")
            if x is not None:
                if time is None:
                    time = np.asarray(x, dtype=np.float64)
                elif time.size != x.size or not np.array_equal(time, x):
                    b.fail("channels have different uneven time bases; read them separately "
                           "with channels=[...]")
            label = h["ordinate_axis_units_lab"]
            factor164 = None
            if (not label or label.upper() == "NONE") and b.units is None:
                # no label: the spec data type, unit exponents and dataset 164 say it
                label, factor164 = self._unit_from_164(st, units164, b)
                if factor164 not in (None, 1.0):
                    vals = np.asarray(vals, dtype=np.float64) * factor164
            b.add_channel(name, vals, label, attrs=self._channel_attrs(st, factor164), inplace=True,
                          quantity=_SPEC_QUANTITY.get(h["ordinate_spec_data_type"]))
        return time

    @staticmethod
    def _channel_attrs(st, factor164):
        """A channel's attributes: the set's ids and header fields (and a dataset 164 factor)."""
        h = st.header
        attrs = {k: h[k] for k in ("id1", "id2", "id3", "id4", "id5", "rsp_ent_name")
                 if h.get(k) and h[k].upper() != "NONE"}
        attrs.update({"uff_set": st.index, "uff_rsp_node": h["rsp_node"],
                      "uff_rsp_dir": h["rsp_dir"], "uff_func_type": h["func_type"],
                      "uff_ord_data_type": h["ord_data_type"],
                      "uff_ordinate_axis_lab": h["ordinate_axis_lab"],
                      "uff_binary": int(st.binary)})
        if factor164 not in (None, 1.0):
            attrs["uff_164_factor"] = factor164
        return attrs

    def _rate(self, b, h0, time, fs_override, snap_rate):
        """The sampling rate: None for an uneven time base, else ``fs`` or the header's
        increment (checked, snapped to whole Hz when the printed increment rounded it)."""
        inc = h0["abscissa_inc"]
        if time is not None:
            b.warn("uneven abscissa: the file's time values are kept as the time coordinate "
                   "(sampling_rate_hz is the median rate)")
            b.attrs["uneven_time"] = 1
            return None
        if fs_override is not None:
            fs = float(fs_override)
            b.attrs["file_sampling_rate_hz"] = 1.0 / inc if inc > 0 else 0.0
            return fs
        if not inc > 0:
            b.fail(f"abscissa increment {h0['abscissa_inc_text']!r} is not positive; pass fs=<Hz>")
        with np.errstate(over="ignore"):
            fs = float(np.float64(1.0) / np.float64(inc))
        if not MIN_RATE_HZ <= fs <= MAX_RATE_HZ:
            b.fail(f"abscissa increment {h0['abscissa_inc_text'].strip()!r} s means a sampling "
                   f"rate of {fs:.6g} Hz, outside {MIN_RATE_HZ:g} Hz .. {MAX_RATE_HZ:.0e} Hz: a "
                   "damaged header; pass fs=<Hz>")
        if snap_rate:
            fs = self._snap(fs, h0["abscissa_inc_text"], b)
        return fs

    def _snap(self, fs, text, b):
        """Snap ``fs`` to the whole number of Hz whose increment prints as ``text``."""
        cand = round(fs)
        if cand <= 0 or cand == fs:
            return fs
        txt = text.replace("D", "E").replace("d", "e")
        mant = re.match(r"\s*[-+]?(\d*)\.?(\d*)[eE]?([-+]?\d*)", txt)
        if not mant or not mant.group(3):
            return fs
        digits = len((mant.group(1) + mant.group(2)).lstrip("0")) or 1
        inc = float(txt)
        ulp = 10.0 ** (math.floor(math.log10(abs(inc))) - (digits - 1))
        # the writer may round or truncate the last printed digit: accept one unit of it
        if abs(1.0 / cand - inc) <= ulp * (1 + 1e-9):
            b.warn(f"sampling rate snapped from {fs:.6f} Hz to {cand} Hz (the increment is "
                   f"printed as {text})")
            b.attrs["file_sampling_rate_hz"] = fs
            return float(cand)
        return fs

    def _parse_164(self, mm, st, b):
        lines = bytes(mm[st.block[0]:st.block[1]]).splitlines()
        try:
            toks = lines[1].replace(b"D", b"E").split()
            length, force = float(toks[0]), float(toks[1])
            b.attrs["uff_units_system"] = decode_text(lines[0][10:30]).strip()
        except (IndexError, ValueError):
            b.warn(f"set {st.index} (dataset 164, units) is unreadable and was ignored")
            return None
        if not (0 < length < math.inf and 0 < force < math.inf):  # also NaN
            # used, these would turn every value into 0, inf or NaN: a channel that needs them
            # is refused (_unit_from_164); channels with their own unit labels do not need them
            b.warn(f"set {st.index} (dataset 164) has factors {length}, {force}, which are not unit "
                   "factors")
        return (length, force)


ENGINES["uff58"] = Uff58Reader
