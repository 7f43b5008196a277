"""A bounds-checked reader of MATLAB level-5 MAT-files (v5, v6 and v7 with compression).

Why our own reader: scipy.io's compiled v5 reader trusts the element tags it
finds.  One flipped byte in a data type or a size (a CWRU file with byte 192 set
to 0x19, say) makes it index outside its tables or buffers and the whole process
dies with a segmentation fault (scipy/scipy#6072 is one of that family); other
corrupt sizes make it allocate gigabytes before failing.  A reader of users'
files must never take the process down, so here every tag, size and offset is
checked against the bytes that are really there *before* numpy looks at them:

- the 128-byte header (text, version 0x0100, endian indicator ``IM``/``MI``);
- every data element: a known type, a size inside its parent, 8-byte padding,
  the small-element form (size <= 4 in the tag);
- arrays: the dimensions' product times the storage type's size must equal the
  data element's size exactly (a shortened or lengthened array is refused, never
  silently cut or padded);
- compressed (miCOMPRESSED) variables are inflated with a ceiling taken from the
  size their inner tag declares (itself bounded by zlib's largest ratio, and above
  64 MiB by :data:`MAX_INFLATE_RATIO`, a ratio no recording's samples reach: a 1 MB
  element of zeros that inflates to 1 GB is refused before anything is allocated), the
  stream must end with its checksum, and nothing may follow it in its element (a
  second stream would be dropped);
- nesting depth and element counts are bounded by the bytes available.

Only native Python and ``numpy.frombuffer`` on checked ranges touch the bytes.
The result is plain Python, as :func:`bearing_lab.io._matlab.load_mat`
promises: structs -> dict (struct arrays -> list of dicts), char arrays -> str
(several rows -> list of str), cells -> list (a 1×1 cell -> its content),
numeric and logical arrays -> squeezed ndarray in the class's dtype, a single
value -> Python scalar.  Sparse, object, function-handle and opaque variables
are refused by name when asked for (recordings never need them).

Reference: The MathWorks, *MAT-File Format*, version 7 (2019), chapter 1.
"""
from __future__ import annotations

import os
import struct
import zlib

import numpy as np

__all__ = ["Mat5Error", "variable_names", "load"]

_MI_MATRIX, _MI_COMPRESSED = 14, 15
# data element type -> numpy storage code (miUTF8/16/32 only occur in char arrays)
_MI_DTYPE = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 9: "f8",
             12: "i8", 13: "u8", 16: "u1", 17: "u2", 18: "u4"}
# array class -> numpy dtype of the values MATLAB holds
_CLASS_DTYPE = {6: "f8", 7: "f4", 8: "i1", 9: "u1", 10: "i2", 11: "u2", 12: "i4", 13: "u4",
                14: "i8", 15: "u8"}
_CLASS_NAME = {1: "cell", 2: "struct", 3: "object", 4: "char", 5: "sparse", 16: "function handle",
               17: "opaque"}
_MAX_DEPTH = 32
_ZLIB_MAX_RATIO = 1032          # deflate cannot expand data more than this
_NAME_PREFIX = 1 << 16          # inflated bytes enough to hold a variable's tag, flags, dims, name
_MAX_EMPTY_STRUCTS = 1 << 16    # a struct array without fields takes no bytes: bound it
MAX_INFLATE_RATIO = 100.0       # recorded samples deflate by 1-2 (CWRU, MFPT); zeros by 1000
INFLATE_FREE_BYTES = 64 << 20   # a variable this large may inflate by any ratio deflate allows


class Mat5Error(ValueError):
    """The bytes are not a well-formed level-5 MAT-file (the message says where and why)."""


def _fail(msg):
    raise Mat5Error(msg)


def header_endian(buf) -> str:
    """Return the byte order ``"<"`` or ``">"`` of a level-5 file, checking its header."""
    if len(buf) < 128:
        _fail(f"{len(buf)} bytes: shorter than the 128-byte MAT-file header")
    if bytes(buf[:6]) != b"MATLAB":
        _fail("no 'MATLAB' text at the start of the header")
    ind = bytes(buf[126:128])
    if ind == b"IM":
        endian = "<"
    elif ind == b"MI":
        endian = ">"
    else:
        _fail(f"endian indicator {ind!r} at byte 126 is neither 'IM' nor 'MI'")
    version = struct.unpack(endian + "H", bytes(buf[124:126]))[0]
    if version != 0x0100:
        _fail(f"header version {version:#06x} at byte 124, expected 0x0100")
    return endian


class _Reader:
    """Checked access to one buffer (the file, or one inflated variable)."""

    def __init__(self, buf, endian, where, owned=False):
        self.buf, self.e, self.where = buf, endian, where
        self.owned = owned  # an inflated buffer of our own: arrays may be views of it

    def tag(self, pos, end):
        """Return (type, nbytes, data start, next element) of the element at ``pos``."""
        if pos + 8 > end:
            _fail(f"{self.where}: element tag at byte {pos} runs past the end of its parent "
                  f"(byte {end})")
        w0, w1 = struct.unpack_from(self.e + "II", self.buf, pos)
        small = w0 >> 16
        if small:  # small data element: size and type in the first word, data in the second
            typ = w0 & 0xFFFF
            if small > 4:
                _fail(f"{self.where}: small element at byte {pos} claims {small} bytes (at most 4)")
            return typ, small, pos + 4, pos + 8
        start = pos + 8
        if w1 > end - start:
            _fail(f"{self.where}: element at byte {pos} declares {w1} bytes but only "
                  f"{end - start} remain in its parent: truncated or corrupt")
        stop = start + w1
        return w0, w1, start, min(stop + (-w1) % 8, end)  # elements are padded to 8 bytes

    def numbers(self, typ, start, nbytes, count, what):
        code = _MI_DTYPE.get(typ)
        if code is None:
            _fail(f"{what} has data type {typ}, not a numeric MAT type")
        size = int(code[1])
        if nbytes != count * size:
            _fail(f"{what} should hold {count} values of {size} bytes "
                  f"({count * size} bytes) but its data element has {nbytes} bytes")
        return np.frombuffer(self.buf, dtype=self.e + code, count=count, offset=start)

    def text(self, typ, start, nbytes):
        if typ not in (1, 2, 16):
            _fail(f"{self.where}: a name has data type {typ}, expected miINT8")
        return bytes(self.buf[start:start + nbytes]).split(b"\0", 1)[0].decode("latin-1")


def _prod(dims):
    n = 1
    for d in dims:
        n *= d
    return n


def _matrix_head(r: _Reader, pos, end):
    """Parse array flags, dimensions and name; return (cls, flags, dims, name, position)."""
    typ, nb, start, pos = r.tag(pos, end)
    if typ != 6 or nb != 8:
        _fail(f"{r.where}: array flags have type {typ} and {nb} bytes (expected miUINT32, 8)")
    flags = struct.unpack_from(r.e + "I", r.buf, start)[0]
    typ, nb, start, pos = r.tag(pos, end)
    if typ != 5 or nb % 4 or nb < 8:
        _fail(f"{r.where}: dimensions have type {typ} and {nb} bytes (expected miINT32, >= 2 "
              "values)")
    dims = struct.unpack_from(r.e + f"{nb // 4}i", r.buf, start)
    if any(d < 0 for d in dims):
        _fail(f"{r.where}: negative dimension in {dims}")
    typ, nb, start, pos = r.tag(pos, end)
    name = r.text(typ, start, nb)
    return flags & 0xFF, flags, tuple(dims), name, pos


def _squeeze(arr):
    if arr.size == 0:
        return np.empty(0, dtype=arr.dtype)
    arr = np.squeeze(arr)
    return arr.item() if arr.ndim == 0 else arr


def _numeric(r, cls, flags, dims, pos, end, where):
    count = _prod(dims)
    typ, nb, start, pos = r.tag(pos, end)
    real = r.numbers(typ, start, nb, count, f"{where} (real part)")
    dtype = np.dtype(_CLASS_DTYPE[cls])
    if flags & 0x800:  # complex
        typ, nb, start, pos = r.tag(pos, end)
        imag = r.numbers(typ, start, nb, count, f"{where} (imaginary part)")
        arr = real.astype(np.complex128 if dtype.itemsize >= 8 or dtype.kind != "f" else
                          np.complex64)
        arr.imag = imag
    elif flags & 0x200:  # logical
        arr = real != 0
    else:
        if dtype.kind in "iu" and real.size and real.dtype != dtype:
            info = np.iinfo(dtype)
            lo, hi = real.min(), real.max()
            if lo < info.min or hi > info.max or (real.dtype.kind == "f" and not np.all(real == np.round(real))):
                _fail(f"{where}: values {lo:g} .. {hi:g} do not fit the array's class {dtype} "
                      "(they would wrap around): corrupt")
        if r.owned and real.dtype == dtype:
            arr = real  # a view of the inflated buffer (ours): no second copy of a large signal
        else:
            with np.errstate(invalid="ignore", over="ignore"):
                arr = real.astype(dtype)  # a copy: nothing keeps a view of the file's bytes
    return _squeeze(arr.reshape(dims, order="F"))


def _char(r, dims, pos, end, where):
    count = _prod(dims)
    typ, nb, start, pos = r.tag(pos, end)
    if typ == 16:  # UTF-8: variable width
        try:
            text = bytes(r.buf[start:start + nb]).decode("utf-8")
        except UnicodeDecodeError:
            _fail(f"{where}: UTF-8 text is not valid UTF-8")
        codes = [ord(c) for c in text]
        if len(codes) != count:
            _fail(f"{where}: {len(codes)} characters for dimensions {dims}")
        codes = np.asarray(codes, dtype=np.uint32)
    elif typ == 17:  # UTF-16
        try:
            text = bytes(r.buf[start:start + nb]).decode("utf-16-le" if r.e == "<" else "utf-16-be")
        except UnicodeDecodeError:
            _fail(f"{where}: UTF-16 text is not valid UTF-16")
        codes = np.asarray([ord(c) for c in text], dtype=np.uint32)
        if codes.size != count:
            _fail(f"{where}: {codes.size} characters for dimensions {dims}")
    else:
        codes = r.numbers(typ, start, nb, count, where).astype(np.int64)
        if codes.size and (codes.min() < 0 or codes.max() > 0x10FFFF):
            _fail(f"{where}: character codes outside Unicode")
    if count == 0:
        return ""
    rows = codes.reshape(dims, order="F").reshape(-1, dims[-1]) if len(dims) > 1 else \
        codes.reshape(1, -1)
    strings = ["".join(map(chr, row)) for row in rows.tolist()]
    if len(strings) == 1:
        return strings[0]
    if all(len(s) <= 1 for s in strings):  # a column of characters is one text
        return "".join(strings)
    return strings


def _struct(r, dims, pos, end, where, depth, object_class=False):
    if object_class:
        typ, nb, start, pos = r.tag(pos, end)
        r.text(typ, start, nb)  # class name: not needed
    typ, nb, start, pos = r.tag(pos, end)
    if typ != 5 or nb != 4:
        _fail(f"{where}: field-name length has type {typ} and {nb} bytes (expected miINT32, 4)")
    width = struct.unpack_from(r.e + "i", r.buf, start)[0]
    typ, nb, start, pos = r.tag(pos, end)
    if typ not in (1, 2):
        _fail(f"{where}: field names have data type {typ}, expected miINT8")
    if width <= 0 and nb:
        _fail(f"{where}: field-name length {width} with {nb} bytes of names")
    if nb and nb % width:
        _fail(f"{where}: {nb} bytes of field names are not a multiple of the length {width}")
    raw = bytes(r.buf[start:start + nb])
    names = [raw[i:i + width].split(b"\0", 1)[0].decode("latin-1")
             for i in range(0, nb, width)] if nb else []
    count = _prod(dims)
    if count * len(names) * 8 > end - pos:  # each field value needs at least its 8-byte tag
        _fail(f"{where}: {count} struct elements × {len(names)} fields cannot fit in "
              f"{end - pos} bytes")
    if not names and count > _MAX_EMPTY_STRUCTS:
        _fail(f"{where}: {count} struct elements without fields")
    items = []
    for k in range(count):
        item = {}
        for fname in names:
            value, _, pos = _element(r, pos, end, f"{where}.{fname}", depth + 1)
            item[fname] = value
        items.append(item)
    if count == 1:
        return items[0]
    return items


def _cell(r, dims, pos, end, where, depth):
    count = _prod(dims)
    if count * 8 > end - pos:
        _fail(f"{where}: {count} cells cannot fit in {end - pos} bytes")
    out = []
    for k in range(count):
        value, _, pos = _element(r, pos, end, f"{where}{{{k + 1}}}", depth + 1)
        out.append(value)
    return out[0] if count == 1 else out


def _element(r: _Reader, pos, end, where, depth):
    """Parse the miMATRIX element at ``pos``; return (value, name, next position)."""
    if depth > _MAX_DEPTH:
        _fail(f"{where}: arrays nested deeper than {_MAX_DEPTH} levels")
    typ, nb, start, nxt = r.tag(pos, end)
    if typ != _MI_MATRIX:
        _fail(f"{where}: element at byte {pos} has type {typ}, expected an array (miMATRIX)")
    if nb == 0:  # an empty array inside a cell or struct
        return np.empty(0), "", nxt
    stop = start + nb
    cls, flags, dims, name, p = _matrix_head(r, start, stop)
    label = where or name
    if cls in _CLASS_DTYPE:
        value = _numeric(r, cls, flags, dims, p, stop, label)
    elif cls == 4:
        value = _char(r, dims, p, stop, label)
    elif cls in (2, 3):
        value = _struct(r, dims, p, stop, label, depth, object_class=cls == 3)
    elif cls == 1:
        value = _cell(r, dims, p, stop, label, depth)
    else:
        what = _CLASS_NAME.get(cls)
        _fail(f"{label}: " + (f"a {what} array is not supported" if what else
                              f"unknown array class {cls}"))
    return value, name, nxt


def max_inflate_ratio() -> float:
    """The largest inflate ratio accepted for a variable above :data:`INFLATE_FREE_BYTES`
    (``BEARING_LAB_MAX_INFLATE_RATIO`` overrides :data:`MAX_INFLATE_RATIO`)."""
    text = os.environ.get("BEARING_LAB_MAX_INFLATE_RATIO", "")
    try:
        value = float(text) if text else MAX_INFLATE_RATIO
    except ValueError:
        _fail(f"BEARING_LAB_MAX_INFLATE_RATIO={text!r} is not a number")
    return value if value > 0 else MAX_INFLATE_RATIO


def _inflate(buf, start, nbytes, endian, where, *, prefix=False):
    """Inflate one miCOMPRESSED payload with a ceiling; ``prefix``: only its first bytes.

    The output goes into one buffer of the declared size, filled in blocks (no second copy).
    The stream must end exactly where the element ends: a second zlib stream or junk after
    the first would otherwise be dropped without a word.
    """
    d = zlib.decompressobj()
    data = memoryview(buf)[start:start + nbytes]
    try:
        head = d.decompress(data, 8)
        while len(head) < 8 and not d.eof and d.unconsumed_tail:
            head += d.decompress(d.unconsumed_tail, 8 - len(head))
    except zlib.error as exc:
        _fail(f"{where}: compressed variable is corrupt ({exc})")
    if len(head) < 8:
        _fail(f"{where}: compressed variable inflates to {len(head)} bytes, less than a tag")
    declared = 8 + struct.unpack_from(endian + "I", head, 4)[0]
    if declared > _ZLIB_MAX_RATIO * nbytes + 64:
        _fail(f"{where}: compressed variable of {nbytes} bytes declares {declared} bytes inside, "
              "more than deflate can produce: corrupt")
    ratio = max_inflate_ratio()
    if not prefix and declared > INFLATE_FREE_BYTES and declared > ratio * nbytes:
        _fail(f"{where}: compressed variable of {nbytes} bytes declares {declared} bytes inside "
              f"(inflate ratio {declared / nbytes:.0f}, more than the {ratio:g} a recording's "
              "samples compress by): a decompression bomb or damaged sizes; if the file is "
              "genuine, raise the limit with BEARING_LAB_MAX_INFLATE_RATIO")
    want = min(declared, _NAME_PREFIX) if prefix else declared
    out = bytearray(want)
    out[:len(head)] = head
    filled = len(head)
    try:
        while filled < want:
            chunk = d.decompress(d.unconsumed_tail, min(want - filled, 1 << 24))
            if not chunk:
                break
            out[filled:filled + len(chunk)] = chunk
            filled += len(chunk)
        if not prefix:
            extra = d.decompress(d.unconsumed_tail, 8) if not d.eof else b""
            if extra:
                _fail(f"{where}: compressed variable holds more than the {declared} bytes its "
                      "tag declares")
            if not d.eof:
                d.flush()
    except zlib.error as exc:
        _fail(f"{where}: compressed variable is corrupt ({exc})")
    if filled < want:
        _fail(f"{where}: compressed variable inflates to {filled} of the {want} bytes its tag "
              "declares: truncated or corrupt")
    if not prefix and not d.eof:
        _fail(f"{where}: compressed variable ends before its checksum: truncated or corrupt")
    if not prefix and d.unused_data and (len(d.unused_data) > 7 or d.unused_data.strip(b"\0")):
        _fail(f"{where}: {len(d.unused_data)} bytes follow the end of the compressed stream inside "
              "its element (a second zlib stream or appended data, which MATLAB never writes); "
              "they would be dropped: refused")
    return out


def _top_elements(buf):
    """Yield (type, nbytes, data start) of every top-level element, checking the layout."""
    endian = header_endian(buf)
    r = _Reader(buf, endian, "MAT-file")
    pos, end = 128, len(buf)
    while pos < end:
        if end - pos < 8:
            _fail(f"{end - pos} stray bytes at the end of the file (byte {pos}): truncated or "
                  "corrupt")
        typ, nb, start, nxt = r.tag(pos, end)
        if typ not in (_MI_MATRIX, _MI_COMPRESSED):
            _fail(f"top-level element at byte {pos} has type {typ}; a MAT-file holds only "
                  "arrays (14) and compressed arrays (15)")
        yield r, typ, nb, start, pos
        pos = start + nb  # top-level elements follow each other without padding


def _variable(buf, r, typ, nb, start, pos, *, name_only):
    """(name, value or None) of one top-level element."""
    if typ == _MI_MATRIX:
        if name_only:
            return _matrix_head(r, start, start + nb)[3], None
        value, name, _ = _element(r, pos, start + nb, "", 0)
        return name, value
    inner = _inflate(buf, start, nb, r.e, f"compressed variable at byte {pos}", prefix=name_only)
    ri = _Reader(inner, r.e, f"compressed variable at byte {pos}", owned=not name_only)
    if name_only:  # ``inner`` holds only the first bytes of the array
        typ2, nb2 = struct.unpack_from(r.e + "II", inner, 0)
        if typ2 != _MI_MATRIX:
            _fail(f"compressed variable at byte {pos} does not hold an array (type {typ2})")
        return _matrix_head(ri, 8, min(8 + nb2, len(inner)))[3], None
    value, name, nxt = _element(ri, 0, len(inner), "", 0)
    return name, value


def variable_names(buf) -> list[str]:
    """Names of the variables in the file, in file order (only their headers are parsed)."""
    names = []
    for r, typ, nb, start, pos in _top_elements(buf):
        name, _ = _variable(buf, r, typ, nb, start, pos, name_only=True)
        names.append(name)
    return names


def load(buf, variable_names=None) -> dict:
    """Read the variables (all, or those named) into plain Python values.

    Raises
    ------
    Mat5Error
        If any part of the file that is read is malformed; the message says where.
    """
    wanted = None if variable_names is None else set(variable_names)
    out = {}
    for r, typ, nb, start, pos in _top_elements(buf):
        if wanted is not None:
            name, _ = _variable(buf, r, typ, nb, start, pos, name_only=True)
            if name not in wanted:
                continue
        name, value = _variable(buf, r, typ, nb, start, pos, name_only=False)
        if name.startswith("__"):
            continue
        where = name or f"variable at byte {pos}"
        try:
            out[name] = value
        except TypeError:  # pragma: no cover - names are str
            _fail(f"{where}: unusable name")
    return out
