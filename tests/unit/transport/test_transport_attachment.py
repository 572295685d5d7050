"""The 33-byte rmw_zenoh attachment, and the legacy string-keyed one it can still read."""

from __future__ import annotations

import struct

import pytest

from kinema.errors import TransportError
from kinema.transport.attachment import SIZE, Attachment

GID = bytes.fromhex("3852c437b77e486fba8b79c385dfc2a0")


def test_encoding_matches_the_reference_capture() -> None:
    # attachment(33)=0100000000000000 6fdd66103a3bea18 10 3852c437b77e486fba8b79c385dfc2a0
    captured = bytes.fromhex("01000000000000006fdd66103a3bea18103852c437b77e486fba8b79c385dfc2a0")
    stamp = struct.unpack("<q", bytes.fromhex("6fdd66103a3bea18"))[0]
    assert Attachment(1, stamp, GID).encode() == captured
    assert Attachment.decode(captured) == Attachment(1, stamp, GID)
    assert SIZE == 33


def _leb(value: int) -> bytes:
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def _key(name: str) -> bytes:
    return _leb(len(name)) + name.encode()


def test_legacy_jazzy_format_is_read() -> None:
    legacy = (
        _key("sequence_number")
        + struct.pack("<q", 9)
        + _key("source_timestamp")
        + struct.pack("<q", 123456789)
        + _key("source_gid")
        + _leb(16)
        + GID
    )
    assert Attachment.decode(legacy) == Attachment(9, 123456789, GID)


@pytest.mark.parametrize("raw", [None, b"", b"\x01\x02\x03"])
def test_garbage_is_reported(raw: bytes | None) -> None:
    with pytest.raises(TransportError):
        Attachment.decode(raw)


def test_encode_attachment_writes_what_the_dataclass_writes() -> None:
    """The publishers' hot path (no object built) equals Attachment(...).encode() byte for byte."""
    import time

    from kinema.transport.attachment import Attachment, encode_attachment, new_gid

    gid = new_gid()
    before = time.time_ns()
    raw = encode_attachment(12345, gid)
    after = time.time_ns()
    decoded = Attachment.decode(raw)
    assert decoded.sequence_number == 12345 and decoded.gid == gid
    assert before <= decoded.source_timestamp <= after
    assert raw == Attachment(12345, decoded.source_timestamp, gid).encode()
