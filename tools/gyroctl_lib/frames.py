"""Telemetry frames of the tuning UART and the receiver that separates them from text.

The byte layout and the text/frame rule are defined in firmware/comm/tlm_frame.h; this
module follows tools/tlm_decode/tlm_decode.c rule for rule (same states, same checks, same
counters), and its tests compare the two on the same bytes (tests/test_frames.py, with
streams written by the firmware's own encoder through the tlm-vectors program).

Summary of the wire format:
    frame on the wire   00 | COBS(raw) | 00         (COBS bytes never 0x00; the first is 0x01)
    raw                 00 marker | type 'H'/'D' | seq u16 | payload | CRC-16 (big-endian)
    CRC                 CRC-16/CCITT-FALSE over marker..payload = binascii.crc_hqx(b, 0xFFFF)
    header payload      version u8 = 1, stream_id u32, fs_hz u32, decim u32, rec_per_frame u16,
                        lost u32, dropped u32, n_fields u8, then per field: type u8
                        (0 f32, 1 u32), name length u8, name
    data payload        stream u16 (low half of stream_id), first_rec u32, n_rec u8,
                        n_rec records of n_fields little-endian 4-byte words
Text lines hold only 0x20-0x7E, TAB and CR LF; a 0x01 in text position starts a frame.
"""

from __future__ import annotations

import binascii
import dataclasses
import struct

MARKER = 0x00
TYPE_HEADER = 0x48  # 'H'
TYPE_DATA = 0x44    # 'D'
HEAD_BYTES = 4
CRC_BYTES = 2
OVERHEAD = HEAD_BYTES + CRC_BYTES
FRAME_MAX = 1086  # a header of FIELDS_MAX fields with NAME_MAX-byte names
HEADER_VERSION = 1
HEADER_FIXED = 24
DATA_FIXED = 7
FIELDS_MAX = 32  # as firmware/comm/tlm_frame.h (16 before the field table grew)
NAME_MAX = 31
LINE_MAX = 300
T_F32, T_U32 = 0, 1


def cobs_max(n: int) -> int:
    return n + 1 + n // 254


BUF_MAX = cobs_max(FRAME_MAX)  # COBS bytes of the largest frame
WIRE_MAX = BUF_MAX + 2

_NAME_CHARS = frozenset(b"abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.")
_TEXT_CHARS = frozenset(range(0x20, 0x7F)) | {0x09}


def crc16(data: bytes, crc: int = 0xFFFF) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, MSB first, no final XOR)."""
    return binascii.crc_hqx(data, crc)


def cobs_encode(data: bytes) -> bytes:
    """COBS as in tlm_frame.h: a full 254-byte block at the end gets no trailing 01."""
    out = bytearray([0])
    code_at, code = 0, 1
    n = len(data)
    for i, b in enumerate(data):
        if b == 0:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
            continue
        out.append(b)
        code += 1
        if code == 0xFF:
            out[code_at] = code
            code = 1
            if i + 1 < n:
                code_at = len(out)
                out.append(0)
            else:
                return bytes(out)
    out[code_at] = code
    return bytes(out)


def cobs_decode(data: bytes, cap: int = FRAME_MAX):
    """Decoded bytes, or None for a 0x00, a block running past the end, or > cap bytes."""
    out = bytearray()
    i, n = 0, len(data)
    while i < n:
        code = data[i]
        i += 1
        if code == 0:
            return None
        k = code - 1
        if k > n - i or len(out) + k > cap:
            return None
        block = data[i:i + k]
        if 0 in block:
            return None
        out += block
        i += k
        if code != 0xFF and i < n:
            if len(out) >= cap:
                return None
            out.append(0)
    return bytes(out)


def seal(ftype: int, seq: int, payload: bytes) -> bytes:
    """A raw frame: marker, type, seq, payload, CRC (big-endian)."""
    body = bytes([MARKER, ftype]) + struct.pack("<H", seq & 0xFFFF) + payload
    return body + struct.pack(">H", crc16(body))


def to_wire(raw: bytes) -> bytes:
    return b"\x00" + cobs_encode(raw) + b"\x00"


@dataclasses.dataclass
class Layout:
    """A stream's header frame."""
    stream_id: int
    fs_hz: int
    decim: int
    rec_per_frame: int
    lost: int
    dropped: int
    seq: int
    fields: list  # [(name, type)], type T_F32 or T_U32

    @property
    def rate_hz(self) -> float:
        return self.fs_hz / self.decim

    @property
    def names(self) -> list:
        return [n for n, _ in self.fields]

    def time_s(self, index: int) -> float:
        """Stream time of record `index` (0 = the stream's first record)."""
        return index * self.decim / self.fs_hz


@dataclasses.dataclass
class DataFrame:
    layout: Layout
    seq: int
    first_rec: int
    words: list      # per record, a tuple of n_fields uint32 words

    @property
    def records(self) -> list:
        """Per record, a tuple of Python values (float for f32, int for u32)."""
        out = []
        fmt = "<" + "".join("f" if t == T_F32 else "I" for _, t in self.layout.fields)
        for w in self.words:
            out.append(struct.unpack(fmt, struct.pack("<%dI" % len(w), *w)))
        return out


@dataclasses.dataclass
class Stats:
    lines: int = 0
    lines_bad: int = 0
    headers: int = 0
    data: int = 0
    corrupt: int = 0
    bad_format: int = 0
    no_layout: int = 0
    seq_missing: int = 0
    rec_missing: int = 0


def parse_header(p: bytes, seq: int):
    """Header payload -> Layout, or None if malformed (the checks of tlm_decode.c)."""
    n = len(p)
    if n < HEADER_FIXED or p[0] != HEADER_VERSION:
        return None
    stream_id, fs_hz, decim, rpf, lost, dropped, nf = struct.unpack_from("<IIIHIIB", p, 1)
    if fs_hz == 0 or decim == 0 or rpf == 0 or nf == 0 or nf > FIELDS_MAX:
        return None
    off = HEADER_FIXED
    fields = []
    for _ in range(nf):
        if n - off < 2:
            return None
        ftype, ln = p[off], p[off + 1]
        off += 2
        name = p[off:off + ln]
        if ftype > 1 or ln > n - off or not 1 <= ln <= NAME_MAX or any(c not in _NAME_CHARS for c in name):
            return None
        name = name.decode("ascii")
        if any(name == f for f, _ in fields):
            return None
        fields.append((name, ftype))
        off += ln
    if off != n:
        return None
    return Layout(stream_id, fs_hz, decim, rpf, lost, dropped, seq, fields)


_TEXT, _FRAME, _SKIP = 0, 1, 2


class Decoder:
    """Byte stream in; text lines, headers and data frames out through callbacks.

    on_text(str) gets a line without CR LF; on_header(Layout) every valid header;
    on_data(DataFrame) every valid data frame of the stream whose header came last.
    Counters in .stats (see tools/tlm_decode/tlm_decode.h for their meaning).
    """

    def __init__(self, on_text=None, on_header=None, on_data=None):
        self.on_text, self.on_header, self.on_data = on_text, on_header, on_data
        self.stats = Stats()
        self.layout = None
        self._state = _TEXT
        self._line = bytearray()
        self._line_bad = False
        self._line_cr = False
        self._buf = bytearray()
        self._next_seq = 0
        self._have_rec = False
        self._next_rec = 0

    # ---- text ----
    def _line_reset(self):
        self._line = bytearray()
        self._line_bad = self._line_cr = False

    def _line_abort(self):
        if self._line or self._line_bad or self._line_cr:
            self.stats.lines_bad += 1
        self._line_reset()

    def _line_end(self):
        if self._line_bad:
            self.stats.lines_bad += 1
        elif self._line:
            self.stats.lines += 1
            if self.on_text:
                self.on_text(self._line.decode("ascii"))
        self._line_reset()

    def _text_byte(self, c):
        if c == 0x0A:
            self._line_end()
        elif c == 0x00:
            self._line_abort()
        elif c == 0x01:
            self._line_abort()
            self._state = _FRAME
            self._buf = bytearray(b"\x01")
        elif c == 0x0D:
            if self._line_cr:
                self._line_bad = True
            self._line_cr = True
        elif c in _TEXT_CHARS:
            if self._line_cr or len(self._line) >= LINE_MAX:
                self._line_bad = True
            else:
                self._line.append(c)
        else:
            self._line_bad = True

    # ---- frames ----
    def _track_seq(self, seq):
        self.stats.seq_missing += (seq - self._next_seq) & 0xFFFF
        self._next_seq = (seq + 1) & 0xFFFF

    def _frame_end(self):
        raw = cobs_decode(bytes(self._buf))
        self._buf = bytearray()
        if raw is None or len(raw) < OVERHEAD or crc16(raw) != 0 or raw[0] != MARKER:
            self.stats.corrupt += 1
            return
        ftype, seq = raw[1], struct.unpack_from("<H", raw, 2)[0]
        payload = raw[HEAD_BYTES:-CRC_BYTES]
        if ftype == TYPE_HEADER:
            self._header(payload, seq)
        elif ftype == TYPE_DATA:
            self._data(payload, seq)
        else:
            self.stats.bad_format += 1

    def _header(self, p, seq):
        lay = parse_header(p, seq)
        if lay is None:
            self.stats.bad_format += 1
            return
        if self.layout is None or lay.stream_id != self.layout.stream_id:
            self._next_seq = seq
            self._have_rec = False
        self._track_seq(seq)
        self.layout = lay
        self.stats.headers += 1
        if self.on_header:
            self.on_header(lay)

    def _data(self, p, seq):
        n = len(p)
        if n < DATA_FIXED:
            self.stats.bad_format += 1
            return
        tag, first, n_rec = struct.unpack_from("<HIB", p, 0)
        lay = self.layout
        if lay is None or tag != (lay.stream_id & 0xFFFF):
            self.stats.no_layout += 1
            return
        nf = len(lay.fields)
        if n_rec == 0 or n != DATA_FIXED + 4 * n_rec * nf:
            self.stats.bad_format += 1
            return
        self._track_seq(seq)
        gap = (first - self._next_rec) & 0xFFFFFFFF
        if self._have_rec and gap != 0 and gap < 0x80000000:
            self.stats.rec_missing += gap
        self._next_rec = (first + n_rec) & 0xFFFFFFFF
        self._have_rec = True
        self.stats.data += 1
        if self.on_data:
            flat = struct.unpack_from("<%dI" % (n_rec * nf), p, DATA_FIXED)
            words = [flat[r * nf:(r + 1) * nf] for r in range(n_rec)]
            self.on_data(DataFrame(lay, seq, first, words))

    # ---- bytes ----
    def feed(self, data: bytes):
        i, n = 0, len(data)
        while i < n:
            if self._state == _FRAME:
                j = data.find(b"\x00", i)
                end = n if j < 0 else j
                if len(self._buf) + (end - i) > BUF_MAX:
                    self.stats.corrupt += 1  # longer than any frame
                    self._buf = bytearray()
                    self._state = _SKIP
                    continue  # the SKIP state consumes up to the 0x00
                self._buf += data[i:end]
                i = end
                if j >= 0:
                    self._frame_end()
                    self._state = _TEXT
                    i = j + 1
            elif self._state == _SKIP:
                j = data.find(b"\x00", i)
                if j < 0:
                    return
                self._state = _TEXT
                i = j + 1
            else:
                self._text_byte(data[i])
                i += 1
