"""The journal of a run: every completed state on disk as the run goes (docs/results.md, "The journal").

A run that writes a result file ``RESULT.npz`` appends each state, as soon as it is completed, to
the journal ``RESULT.npz.journal`` beside it: one frame per state, handed to the kernel with one
``write`` call, which the kernel keeps when the process is killed (SIGKILL included). A run
killed at any moment therefore loses at most the state in flight, and ``rollqp run --resume
RESULT.npz`` continues after the last frame. When the run ends (completed, failed or stopped by
a signal) the result file is assembled from the journal (:mod:`rollqp.result`) and the journal
is removed.

The file: the 8 bytes ``RQPJNL01``, then frames. A frame is a head of 28 bytes (``b"RF"``, its
kind, flags, the payload's length, the state's index, the payload's CRC-32, the CRC-32 of the head
itself) and its payload:

* kind ``H``, the first frame: an ``.npz`` archive (:class:`~rollqp.npzfile.NpzStream`) of the
  arrays that do not change with the state (``x``, the scalars, the run's constants), the
  JSON ``meta`` and ``journal``: the layouts of the state frames and the run's settings;
* kind ``S``: one computed state, the fields of layout ``S`` as one record of a numpy structured
  dtype (each field with its own dtype and shape: a field of a 3D run, shape ``(ny, nx)``, is
  one more entry of the layout, nothing else changes), then an optional JSON object of notes;
* kind ``R``: one state imported from a result file (layout ``R``: every field of that file,
  already combined over the states it stands for; the start of a resumed run).

Nothing read is trusted: a frame whose head fails its CRC or whose payload fails its CRC is the
torn last frame of a killed writer only if it is the end of the file (a head cut short, a payload
running past the end, or zeros to the end: it is ignored, and cut off before the next append);
anywhere else the journal is corrupt (:class:`~rollqp.errors.InputError` naming the argument).
"""
from __future__ import annotations

import io
import json
import os
import struct
import tempfile
import time
import zlib

import numpy as np

from .errors import InputError
from .npzfile import NpzStream, read_npz, text_value

__all__ = ["Journal", "MAGIC", "SUFFIX", "layout_dtype", "journal_path", "json_default"]

MAGIC = b"RQPJNL01"
#: The journal of ``RESULT.npz`` is ``RESULT.npz.journal``.
SUFFIX = ".journal"
_HEAD = struct.Struct("<2sBBQqI")        # b"RF", kind, flags, payload length, state index, payload CRC
_HEAD_CRC = struct.Struct("<I")
HEAD_BYTES = _HEAD.size + _HEAD_CRC.size  # 28
KINDS = {b"H"[0]: "H", b"S"[0]: "S", b"R"[0]: "R"}
#: Largest frame payload read (1 GiB): a state of 20,000 nodes is 1 MB, a header with a
#: million-point profile table 16 MB.
MAX_FRAME = 1 << 30
#: Largest header JSON (the layouts and settings; ``meta`` is bounded by the result reader).
MAX_INFO = 1 << 20
#: Allowed dtypes of a layout's fields.
DTYPES = ("<f8", "<i8", "|i1", "<f4", "<i4", "|u1")
#: Seconds between two ``fsync`` of the journal (a machine that loses power loses at most this
#: much; a killed process loses nothing the kernel was handed).
FSYNC_SECONDS = 10.0


def journal_path(out) -> str:
    """The journal of the result file ``out``."""
    return os.fspath(out) + SUFFIX


def layout_dtype(layout, arg: str = "journal") -> np.dtype:
    """The structured dtype of a layout ``[[name, dtype, shape], ...]`` (checked: it is read from files)."""
    if not isinstance(layout, list) or not 1 <= len(layout) <= 1000:
        raise InputError(arg, "the journal's layout must be a list of 1 to 1000 fields")
    fields, seen = [], set()
    for item in layout:
        if not (isinstance(item, list) and len(item) == 3 and isinstance(item[0], str) and 0 < len(item[0]) <= 100
                and item[1] in DTYPES and isinstance(item[2], list) and len(item[2]) <= 4
                and all(isinstance(d, int) and not isinstance(d, bool) and 0 <= d <= 1 << 31 for d in item[2])):
            raise InputError(arg, f"bad field in the journal's layout: {str(item)[:80]}")
        if item[0] in seen:
            raise InputError(arg, f"field {item[0]!r} twice in the journal's layout")
        seen.add(item[0])
        fields.append((item[0], np.dtype(item[1]), tuple(item[2])))
    dt = np.dtype(fields)
    if dt.itemsize > MAX_FRAME:
        raise InputError(arg, f"the journal's states would be {dt.itemsize} bytes each, more than {MAX_FRAME}")
    return dt


def layout_of(values: dict) -> list:
    """The layout ``[[name, dtype, shape], ...]`` of one state's values (numpy arrays or scalars)."""
    return [[k, np.asarray(v).dtype.str, list(np.shape(v))] for k, v in values.items()]


class Journal:
    """An open journal: its header, its state frames (``index``, ``kinds``) and an append handle.

    Use :meth:`create` for a new run and :meth:`open` to read (and continue) one; ``len()`` is
    the number of complete state frames.
    """

    def __init__(self, path: str, fd: int, header: dict, layouts: dict, frames: "_Frames", end: int, arg: str):
        self.path, self.fd, self.header, self.layouts, self.frames, self.end, self.arg = \
            path, fd, header, layouts, frames, end, arg
        self.writable = False
        self._synced = time.monotonic()
        #: ``(index, notes)`` of the state frames that carry notes, in order
        self.notes: list = []

    # ------------------------------------------------------------------ creating and opening
    @classmethod
    def create(cls, path, arrays: dict, meta_text: str, info: dict) -> "Journal":
        """A new journal at ``path`` (replacing one there): written whole to a temporary file and renamed,
        so that a journal that exists always has its header."""
        path = os.fspath(path)
        for key in ("S", "R"):
            layout_dtype(info["layout"][key])
        buf = io.BytesIO()
        with NpzStream(buf) as z:
            for k, v in arrays.items():
                z.array(k, v)
            z.array("meta", np.asarray(meta_text))
            z.array("journal", np.asarray(json.dumps(info, sort_keys=True)))
        payload = buf.getvalue()
        folder = os.path.dirname(os.path.abspath(path))
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=os.path.basename(path) + ".", suffix=".tmp")
        try:
            _write_all(fd, MAGIC + _frame("H", 0, 0, payload))
            os.fsync(fd)
            os.replace(tmp, path)
        except BaseException:
            os.close(fd)
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        os.close(fd)
        return cls.open(path, "journal", writable=True)

    @classmethod
    def open(cls, path, arg: str, writable: bool = False) -> "Journal":
        """Read the journal at ``path`` without trusting it (module docstring); ``writable``: open it for
        appending, its torn last frame (if any) cut off."""
        path = os.fspath(path)
        try:
            fd = os.open(path, os.O_RDWR if writable else os.O_RDONLY)
        except OSError as exc:
            raise InputError(arg, f"cannot open the journal {path!r} ({exc.strerror or exc})") from None
        try:
            j = cls._scan(path, fd, arg)
            if writable:
                if os.fstat(fd).st_size != j.end:
                    os.ftruncate(fd, j.end)
                os.lseek(fd, j.end, os.SEEK_SET)
                j.writable = True
            return j
        except BaseException:
            os.close(fd)
            raise

    @classmethod
    def _scan(cls, path, fd, arg) -> "Journal":
        size = os.fstat(fd).st_size
        if os.pread(fd, len(MAGIC), 0) != MAGIC:
            raise InputError(arg, f"{path!r} is not a rollqp journal")
        pos, frames, header, notes, layouts = len(MAGIC), _Frames(), None, [], None
        while pos < size:
            got = _read_frame_head(fd, pos, size, path, arg)
            if got is None:  # the torn last frame of a killed writer
                break
            kind, flags, length, index, crc = got
            if kind == "H":
                if header is not None:
                    raise InputError(arg, f"{path!r}: a second header frame at byte {pos}: corrupt journal")
                header = os.pread(fd, length, pos + HEAD_BYTES)
                if zlib.crc32(header) != crc:
                    if _torn(fd, pos + HEAD_BYTES + length, size) and _zero_tail(fd, pos + HEAD_BYTES, length):
                        break
                    raise InputError(arg, f"{path!r}: the header fails its CRC: corrupt journal")
                head, layouts = _header(header, path, arg)
            else:
                if header is None:
                    raise InputError(arg, f"{path!r}: a state frame before the header: corrupt journal")
                if not _payload_crc(fd, pos + HEAD_BYTES, length) == crc:
                    if _torn(fd, pos + HEAD_BYTES + length, size) and _zero_tail(fd, pos + HEAD_BYTES, length):
                        break
                    raise InputError(arg, f"{path!r}: the state frame at byte {pos} fails its CRC: corrupt journal")
                frames.add(pos + HEAD_BYTES, kind, flags, length, index, crc)
                extra = length - layouts[kind].itemsize
                if extra > 0:
                    notes.append((index, _notes(os.pread(fd, extra, pos + HEAD_BYTES + length - extra), path, arg)))
            pos += HEAD_BYTES + length
        if header is None:
            raise InputError(arg, f"{path!r}: the journal has no complete header")
        j = cls(path, fd, head, layouts, frames, pos, arg)
        j.notes = notes
        j._check_frames()
        return j

    def _check_frames(self) -> None:
        f = self.frames
        idx = f.index[:len(f)]
        if idx.size and (idx[0] < 0 or np.any(np.diff(idx) <= 0)):
            raise InputError(self.arg, f"{self.path!r}: the states' indices do not increase: corrupt journal")
        for kind, dt in self.layouts.items():
            code = b"SR".index(kind.encode())
            sizes = f.length[:len(f)][f.kind[:len(f)] == code]
            if np.any(sizes < dt.itemsize) or (kind == "R" and np.any(sizes != dt.itemsize)):
                raise InputError(self.arg, f"{self.path!r}: a state frame shorter than its layout: corrupt journal")

    # ------------------------------------------------------------------ reading
    def __len__(self) -> int:
        return len(self.frames)

    def records(self, ids) -> np.ndarray:
        """The state frames ``ids`` (all of one kind) as records of their layout, each frame's CRC checked."""
        f = self.frames
        ids = np.asarray(ids, dtype=np.int64)
        kinds = set(f.kind[ids].tolist())
        if len(kinds) > 1:
            raise ValueError("Journal.records: frames of one kind at a time")
        dt = self.layouts["SR"[kinds.pop() if kinds else 0]]
        out = np.empty(ids.size, dtype=dt)
        raw = out.view(np.uint8).reshape(ids.size, dt.itemsize)
        for j, i in enumerate(ids.tolist()):
            payload = os.pread(self.fd, int(f.length[i]), int(f.offset[i]))
            if zlib.crc32(payload) != int(f.crc[i]):
                raise InputError(self.arg, f"{self.path!r}: state frame {i} changed on disk: corrupt journal")
            raw[j] = np.frombuffer(payload, dtype=np.uint8, count=dt.itemsize)
        return out

    def kind(self, i: int) -> str:
        """``"S"`` or ``"R"``: the kind of state frame ``i``."""
        return "SR"[int(self.frames.kind[i])]

    # ------------------------------------------------------------------ writing
    def append(self, kind: str, index: int, values: np.ndarray, notes: dict | None = None) -> None:
        """Append one state: ``values`` a record of layout ``kind`` (``"S"`` or ``"R"``). Whatever stops the
        write (an exception, a signal's handler raising) leaves the journal as it was before it."""
        if not self.writable:
            raise ValueError("the journal is not open for appending")
        payload = values.tobytes()
        if notes:
            payload += json.dumps(notes, sort_keys=True, default=json_default).encode()
        frame = _frame(kind, 0, index, payload)
        self.frames.add(self.end + HEAD_BYTES, kind, 0, len(payload), index, zlib.crc32(payload))
        try:
            _write_all(self.fd, frame)
        except BaseException as exc:
            self.frames.n -= 1
            os.ftruncate(self.fd, self.end)
            os.lseek(self.fd, self.end, os.SEEK_SET)
            if isinstance(exc, OSError) and exc.filename is None:  # (a full disk: ENOSPC; a file size limit: EFBIG)
                raise OSError(exc.errno, exc.strerror, self.path) from None
            raise
        self.end += len(frame)
        now = time.monotonic()
        if now - self._synced > FSYNC_SECONDS:
            os.fsync(self.fd)
            self._synced = now

    def close(self) -> None:
        if self.fd >= 0:
            if self.writable:
                os.fsync(self.fd)
            os.close(self.fd)
            self.fd = -1

    def remove(self) -> None:
        """Close and delete the journal (its states are in the result file)."""
        self.close()
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass


class _Frames:
    """The state frames' offsets, kinds, flags, lengths, indices and CRCs, in growable arrays (a
    million states take 30 MB, not the 100 MB of a list of tuples)."""

    def __init__(self):
        self.n = 0
        self.offset = np.empty(64, np.int64)
        self.kind = np.empty(64, np.int8)
        self.length = np.empty(64, np.int64)
        self.index = np.empty(64, np.int64)
        self.crc = np.empty(64, np.uint32)

    def add(self, offset, kind, flags, length, index, crc) -> None:
        if self.n == self.offset.size:
            for name in ("offset", "kind", "length", "index", "crc"):
                a = getattr(self, name)
                setattr(self, name, np.concatenate([a, np.empty_like(a)]))
        i = self.n
        self.offset[i], self.kind[i], self.length[i] = offset, b"SR".index(kind.encode()), length
        self.index[i], self.crc[i] = index, crc
        self.n += 1

    def __len__(self) -> int:
        return self.n


def _frame(kind: str, flags: int, index: int, payload: bytes) -> bytes:
    head = _HEAD.pack(b"RF", ord(kind), flags, len(payload), index, zlib.crc32(payload))
    return head + _HEAD_CRC.pack(zlib.crc32(head)) + payload


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


def _read_frame_head(fd, pos, size, path, arg):
    """``(kind, flags, length, index, crc)`` of the frame at ``pos``, or ``None`` for the torn end of the file."""
    if size - pos < HEAD_BYTES:
        return None
    raw = os.pread(fd, HEAD_BYTES, pos)
    magic, kind, flags, length, index, crc = _HEAD.unpack(raw[:_HEAD.size])
    ok = (_HEAD_CRC.unpack(raw[_HEAD.size:])[0] == zlib.crc32(raw[:_HEAD.size]) and magic == b"RF"
          and kind in KINDS and length <= MAX_FRAME)
    if not ok:
        if _torn(fd, pos, size):
            return None
        raise InputError(arg, f"{path!r}: a bad frame head at byte {pos}: corrupt journal")
    if pos + HEAD_BYTES + length > size:
        return None  # the payload runs past the end: a write cut short
    return KINDS[kind], flags, length, index, crc


def _torn(fd, pos, size) -> bool:
    """Nothing but zeros from ``pos`` to the end (a machine that lost power may leave them), or the end itself."""
    while pos < size:
        block = os.pread(fd, min(1 << 20, size - pos), pos)
        if not block or block.count(0) != len(block):
            return not block
        pos += len(block)
    return True


#: The unit in which a machine that loses power leaves unwritten data as zeros (a page of the file).
PAGE = 4096


def _zero_tail(fd, offset, length) -> bool:
    """The payload at ``offset`` ends in zeros from its last page boundary on (or is all zeros): what a write that
    never reached the disk leaves (the file's length updated, its last pages not). A complete last frame whose
    CRC fails otherwise was changed after it was written: a corrupt journal, not a torn one."""
    end = offset + length
    start = max(offset, (end - 1) // PAGE * PAGE)
    block = os.pread(fd, end - start, start)
    return block.count(0) == len(block)


def _payload_crc(fd, offset, length) -> int:
    crc, done = 0, 0
    while done < length:
        block = os.pread(fd, min(16 << 20, length - done), offset + done)
        if not block:
            return -1
        crc, done = zlib.crc32(block, crc), done + len(block)
    return crc


def _header(payload: bytes, path, arg) -> tuple[dict, dict]:
    """The header frame's arrays, ``meta`` text and settings, and the state layouts' dtypes."""
    z = read_npz(payload, arg)
    try:
        info = json.loads(text_value(z, "journal", arg, limit=MAX_INFO))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(arg, f"{path!r}: the journal's settings are not JSON ({type(exc).__name__})") from None
    if not isinstance(info, dict) or not isinstance(info.get("layout"), dict):
        raise InputError(arg, f"{path!r}: the journal's settings hold no layouts")
    layouts = {k: layout_dtype(info["layout"].get(k), arg) for k in ("S", "R")}
    arrays = {k: v for k, v in z.items() if k not in ("journal",)}
    return {"arrays": arrays, "info": info}, layouts


def _notes(raw: bytes, path, arg) -> dict:
    try:
        notes = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        raise InputError(arg, f"{path!r}: a state's notes are not JSON: corrupt journal") from None
    if not isinstance(notes, dict):
        raise InputError(arg, f"{path!r}: a state's notes are not a JSON object: corrupt journal")
    return notes


def json_default(o):
    """JSON of what ``json.dumps`` does not know (its ``default``): NumPy scalars and arrays as numbers
    and lists, anything else as its string (a result file's ``meta``, a journal's notes)."""
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
