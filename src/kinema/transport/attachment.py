"""The rmw_zenoh attachment carried beside every sample, query and reply.

Current format (rmw_zenoh >= 0.2.4 on Jazzy, Kilted, Rolling): 33 bytes, little endian::

    offset 0   int64  sequence_number
    offset 8   int64  source_timestamp (ns since the epoch)
    offset 16  uint8  gid length (16)
    offset 17  16 B   gid of the sending entity

Jazzy 0.2.0-0.2.3 sent a string-keyed zenoh-ext serialisation instead; ``decode`` reads both so a
Kinema node understands an older peer (it always writes the current format).
"""

from __future__ import annotations

import os
import struct
import time
from dataclasses import dataclass, field

from kinema.errors import TransportError

GID_SIZE = 16
_HEADER = struct.Struct("<qqB")
SIZE = _HEADER.size + GID_SIZE  # 33


def new_gid() -> bytes:
    """A fresh random 16-byte global id for an entity (publisher, client, server)."""
    return os.urandom(GID_SIZE)


def encode_attachment(sequence_number: int, gid: bytes) -> bytes:
    """The wire form of ``Attachment(sequence_number, now, gid)`` without building the object (hot path:
    every published message). ``gid`` must have :data:`GID_SIZE` bytes (checked where it is made)."""
    return _HEADER.pack(sequence_number, time.time_ns(), GID_SIZE) + gid


@dataclass(frozen=True)
class Attachment:
    """Sequence number, source timestamp and GID of one message, request or reply."""

    sequence_number: int
    source_timestamp: int = field(default_factory=time.time_ns)
    gid: bytes = b"\0" * GID_SIZE

    def encode(self) -> bytes:
        """The 33-byte wire form."""
        if len(self.gid) != GID_SIZE:
            raise TransportError(f"a GID has {GID_SIZE} bytes, got {len(self.gid)}")
        return _HEADER.pack(self.sequence_number, self.source_timestamp, GID_SIZE) + self.gid

    @classmethod
    def decode(cls, data: bytes | None) -> Attachment:
        """Parse an attachment in the current or the legacy (Jazzy 0.2.0-0.2.3) format."""
        if data is None:
            raise TransportError("message has no rmw_zenoh attachment")
        raw = bytes(data)
        if len(raw) == SIZE and raw[16] == GID_SIZE:
            sequence, stamp, _ = _HEADER.unpack_from(raw)
            return cls(sequence, stamp, raw[17:])
        return cls._decode_legacy(raw)

    @classmethod
    def _decode_legacy(cls, raw: bytes) -> Attachment:
        # zenoh-ext serialisation of ("sequence_number", i64, "source_timestamp", i64,
        # "source_gid", [u8; 16]):
        # strings and byte arrays are prefixed with a LEB128 length, integers are fixed little endian.
        pos = 0
        integers: dict[str, int] = {}
        gid = b""

        def leb128() -> int:
            nonlocal pos
            shift = result = 0
            while True:
                if pos >= len(raw):
                    raise TransportError(f"cannot parse a {len(raw)}-byte rmw_zenoh attachment")
                byte = raw[pos]
                pos += 1
                result |= (byte & 0x7F) << shift
                shift += 7
                if not byte & 0x80:
                    return result

        try:
            for _ in range(3):
                length = leb128()
                key = raw[pos : pos + length].decode()
                pos += length
                if key == "source_gid":
                    count = GID_SIZE if len(raw) - pos == GID_SIZE else leb128()
                    gid = raw[pos : pos + count]
                    pos += count
                else:
                    integers[key] = struct.unpack_from("<q", raw, pos)[0]
                    pos += 8
            return cls(integers["sequence_number"], integers["source_timestamp"], gid)
        except (KeyError, UnicodeDecodeError, struct.error) as error:
            raise TransportError(f"cannot parse a {len(raw)}-byte rmw_zenoh attachment: {error}") from error
