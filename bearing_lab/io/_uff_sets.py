"""The structure of a Universal File: set boundaries, binary byte counts and the dataset-58 header.

Why apart from the reader (:mod:`bearing_lab.io.uff58`): finding the sets and reading their
fixed-width headers is one step, done header by header without touching the data (a 1 GB 58b
is scanned by seeking past its payloads); converting the data blocks and building the
recording is the next.  Every field is checked here against the header's own promises
(point counts against byte counts, padding after a payload, the delimiters), and a damaged
file is refused with the set and the byte where it breaks.
"""
from __future__ import annotations

import re

_DELIM = re.compile(rb"^[ \t]*-1[ \t]*\r?$", re.M)
_MAX_PAD = 64  # bytes of blanks/NULs a writer may leave after a binary payload


def decode_text(b: bytes) -> str:
    """A header line as text: UTF-8, else latin-1."""
    try:
        return b.decode("utf-8")
    except UnicodeDecodeError:
        return b.decode("latin-1")


def _float(tok: str) -> float:
    return float(tok.strip().replace("D", "E").replace("d", "e"))


def _fields(line: bytes, widths):
    s = decode_text(line.rstrip(b"\r\n")).ljust(sum(widths))
    out, i = [], 0
    for w in widths:
        out.append(s[i:i + w])
        i += w
    return out


class UffSet:
    """One block of the file: type, byte range, header and (for 58) where the data are."""

    def __init__(self, index, typ, binary, start):
        self.index, self.type, self.binary, self.start = index, typ, binary, start
        self.header = {}
        self.data_start = self.data_end = None
        self.truncated = False
        self.unclosed = False  # no closing '-1': the file ends inside or right after the set


def scan_sets(mm, b, force_bo=None) -> list[UffSet]:
    """The sets of a Universal File, in file order: boundaries, binary byte counts and the
    dataset-58 headers (a truncated binary payload ends the scan); ``force_bo`` (1 little, 2 big)
    overrides the byte order the binary headers declare."""
    sets, pos = [], 0
    if mm[:3] == b"\xef\xbb\xbf":
        pos = 3
    while True:
        line, nxt = _line(mm, pos)
        if line is None:
            break
        if not line.strip():
            pos = nxt
            continue
        if line.strip() != b"-1":
            where = f"set {len(sets) + 1}" if sets else "the start"
            b.fail(f"expected a '    -1' block delimiter at byte {pos} ({where}), got "
                   f"{bytes(line[:40])!r}: not a Universal File, or a corrupt one")
        start = pos
        tline, pos = _line(mm, nxt)
        if tline is None or not tline.strip():
            b.fail(f"file ends after a '-1' delimiter at byte {start}: truncated")
        m = re.fullmatch(rb"\s*(\d+)(b?)(.*?)\s*", tline, re.S)
        if not m:
            b.fail(f"dataset type line at byte {nxt} is {bytes(tline[:40])!r}, not a number")
        st = UffSet(len(sets) + 1, int(m.group(1)), bool(m.group(2)), start)
        if st.binary:
            pos = _binary_set(mm, b, st, m.group(3), tline, pos, force_bo)
            sets.append(st)
            if st.truncated:
                break
        else:
            pos = _text_set(mm, b, st, nxt, tline, pos)
            sets.append(st)
    return sets


def _binary_set(mm, b, st, rest, tline, pos, force_bo):
    """Read a 58b set's binary header line (``rest``: after the type) and its ASCII header lines
    from ``pos``; find its payload; return the position after the set."""
    parts = rest.split()
    try:
        bo, fp, nasc, nbytes = (int(x) for x in parts[:4])
    except ValueError:
        b.fail(f"set {st.index} (dataset {st.type}b): binary header line "
               f"{bytes(tline[:60])!r} is unreadable")
    if bo not in (1, 2) or fp not in (1, 2) or not 0 < nasc < 1000 or nbytes < 0:
        b.fail(f"set {st.index}: binary header says byte order {bo}, float format "
               f"{fp}, {nasc} header lines, {nbytes} bytes; expected byte order 1 "
               "(little) or 2 (big) and IEEE floats")
    hl = []
    for _ in range(nasc):
        ln, pos = _line(mm, pos)
        if ln is None:
            b.fail(f"set {st.index} (dataset {st.type}b) ends inside its header: "
                   "truncated")
        hl.append(ln)
    st.header_lines, st.nbytes = hl, nbytes
    st.bo = force_bo or bo
    st.data_start = pos
    if st.type == 58:
        parse_header58(st, b)
        need = st.n_values * st.itemsize
        if nbytes < need:
            b.fail(f"set {st.index}: the binary header declares {nbytes} data bytes "
                   f"but {st.header['num_pts']} points need {need}: corrupt header")
    else:
        need = nbytes
    shift = _leading_break(mm, pos, need)
    if shift:
        b.warn(f"set {st.index}: {shift} line-break byte(s) before the binary data "
               "skipped (a writer quirk)")
        pos += shift
        st.data_start = pos
    avail = len(mm) - pos
    if need > avail:
        st.truncated = True
        st.data_end = pos + (avail // max(getattr(st, "itemsize", 1), 1)) * \
            max(getattr(st, "itemsize", 1), 1)
        return len(mm)
    st.data_end = pos + need
    return _after_binary(mm, b, st, st.data_end)


def _text_set(mm, b, st, nxt, tline, pos):
    """Find an ASCII set's block (up to its closing '-1', from the type line at ``nxt``) and,
    for dataset 58, its 11 header lines; return the position after the set."""
    m2 = _DELIM.search(mm, pos)
    if m2 is None:
        st.unclosed = True
        end = len(mm)
        pos = len(mm)
    else:
        end = m2.start()
        pos = m2.end()
    st.block = (nxt + len(tline), end)
    if b"\x00" in mm[st.block[0]:min(end, st.block[0] + (1 << 20))]:
        b.fail(f"set {st.index} (dataset {st.type}) is declared as text but holds binary "
               "bytes: a damaged 58b header?")
    if st.type == 58:
        hdr_lines = []
        p = st.block[0]
        for _ in range(11):
            ln, p = _line(mm, p)
            if ln is None or p > end + 1:
                b.fail(f"set {st.index} (dataset 58) ends inside its 11-line header: "
                       "truncated or corrupt")
            hdr_lines.append(ln)
        st.header_lines = hdr_lines
        st.data_start, st.data_end = p, end
        parse_header58(st, b)
    return pos


def _line(mm, pos):
    """(the line at ``pos`` with its line break, the position after it); (None, pos) at the end."""
    if pos >= len(mm):
        return None, pos
    end = mm.find(b"\n", pos)
    if end < 0:
        return mm[pos:], len(mm)
    return mm[pos:end + 1], end + 1


def _closes_at(mm, pos):
    """True if the bytes at ``pos`` are blanks/line breaks then a '-1' line (or EOF)."""
    tail = bytes(mm[pos:pos + 16])
    stripped = tail.lstrip(b"\r\n")
    return stripped.lstrip(b" ").startswith(b"-1") or (not stripped and pos >= len(mm) - 2)


def _leading_break(mm, pos, need):
    """Bytes of stray CR/LF before a binary payload (some writers add them), else 0."""
    if _closes_at(mm, pos + need):
        return 0
    for k in (1, 2):
        if bytes(mm[pos:pos + k]) in (b"\n", b"\r\n", b"\r") and _closes_at(mm, pos + k + need):
            return k
    return 0


def _after_binary(mm, b, st, pos):
    """Return the position after the closing delimiter of a binary set.

    Between the declared payload and the closing ``-1`` only line breaks, blanks and
    NUL bytes (writers' padding) are accepted; anything else means the point count
    or the payload is damaged, and reading on would swallow the next set as padding.
    """
    line, nxt = _line(mm, pos)
    if line is None:
        st.unclosed = True
        return len(mm)
    if line.strip() == b"-1":
        return nxt
    if not line.strip():
        line2, nxt2 = _line(mm, nxt)
        if line2 is not None and line2.strip() == b"-1":
            return nxt2
    m = _DELIM.search(mm, pos)
    end = m.start() if m is not None else len(mm)
    pad = bytes(mm[pos:end])
    junk = pad.translate(None, b" \r\n\t\x00")
    used = st.n_values * st.itemsize if st.type == 58 else st.nbytes   # other datasets: the declared bytes
    if junk or len(pad) > max(_MAX_PAD, st.nbytes - used):
        declared = (f"{used} data bytes the header declares ({st.header['num_pts']} points)" if st.type == 58
                    else f"{used} bytes its binary header declares (dataset {st.type}b)")
        b.fail(f"set {st.index}: {len(pad)} bytes that are not padding ({pad[:16]!r}...) "
               f"follow the {declared} before the closing '-1': the "
               f"{'point' if st.type == 58 else 'byte'} count or the data are damaged")
    if m is None:
        st.unclosed = True
        return len(mm)
    b.warn(f"set {st.index}: {len(pad)} bytes of padding after the binary data ignored")
    return m.end()


def parse_header58(st, b):
    """Parse the 11 header records of a dataset-58 set into ``st.header``, checked; set the
    set's value layout (complex, double, values per point, value count, item size)."""
    hl = st.header_lines
    if len(hl) < 11:
        b.fail(f"set {st.index} (dataset 58): header has {len(hl)} lines, expected 11")
    h = st.header
    for i in range(5):
        h[f"id{i + 1}"] = decode_text(hl[i].rstrip(b"\r\n")).strip()
    try:
        f = _fields(hl[5], [5, 10, 5, 10, 11, 10, 4, 11, 10, 4])
        h["func_type"] = int(f[0])
        h["func_id"], h["ver_num"], h["load_case_id"] = int(f[1] or 0), int(f[2] or 0), \
            int(f[3] or 0)
        h["rsp_ent_name"] = f[4].strip()
        h["rsp_node"], h["rsp_dir"] = int(f[5]), int(f[6])
        h["ref_ent_name"] = f[7].strip()
        h["ref_node"] = int(f[8]) if f[8].strip() else 0
        h["ref_dir"] = int(f[9]) if f[9].strip() else 0
    except ValueError:
        b.fail(f"set {st.index} (dataset 58): record 6 {bytes(hl[5][:60])!r} is unreadable "
               "(function type, node, direction)")
    try:
        toks = decode_text(hl[6]).split()
        if len(toks) != 6:
            toks = _fields(hl[6], [10, 10, 10, 13, 13, 13])
        h["ord_data_type"], h["num_pts"], h["abscissa_spacing"] = (int(t) for t in toks[:3])
        h["abscissa_min_text"], h["abscissa_inc_text"] = toks[3].strip(), toks[4].strip()
        h["abscissa_min"], h["abscissa_inc"] = _float(toks[3]), _float(toks[4])
        h["z_axis_value"] = _float(toks[5])
    except (ValueError, IndexError):
        b.fail(f"set {st.index} (dataset 58): record 7 {bytes(hl[6][:80])!r} is unreadable "
               "(data type, number of points, increment)")
    for rec, axis in zip(hl[7:11], ("abscissa", "ordinate", "orddenom", "z_axis")):
        f = _fields(rec, [10, 5, 5, 5, 21, 21])
        try:
            h[f"{axis}_spec_data_type"] = int(f[0])
            h[f"{axis}_len_unit_exp"] = int(f[1] or 0)
            h[f"{axis}_force_unit_exp"] = int(f[2] or 0)
            h[f"{axis}_temp_unit_exp"] = int(f[3] or 0)
        except ValueError:
            b.fail(f"set {st.index} (dataset 58): {axis} record {bytes(rec[:60])!r} is unreadable")
        h[f"{axis}_axis_lab"] = f[4].strip()
        h[f"{axis}_axis_units_lab"] = f[5].strip()
    odt, npts, spacing = h["ord_data_type"], h["num_pts"], h["abscissa_spacing"]
    if odt not in (2, 4, 5, 6):
        b.fail(f"set {st.index}: ordinate data type {odt} is not 2/4 (real) or 5/6 (complex)")
    if npts <= 0:
        b.fail(f"set {st.index}: header promises {npts} points")
    if spacing not in (0, 1):
        b.fail(f"set {st.index}: abscissa spacing {spacing} is not 0 (uneven) or 1 (even)")
    st.complex = odt in (5, 6)
    st.double = odt in (4, 6)
    st.per_point = (2 if st.complex else 1) + (1 if spacing == 0 else 0)
    st.n_values = npts * st.per_point
    st.itemsize = 8 if st.double else 4
