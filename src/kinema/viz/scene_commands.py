"""meshcat drawing commands as the bridge relays them: ``(type, path, msgpack payload)``."""

from __future__ import annotations

from typing import Any

import numpy as np
import umsgpack

from kinema.viz.meshcat_server import Command


def set_object(path: str, obj: Any) -> Command:
    """Draw ``obj`` (a ``meshcat.geometry.Object``: Mesh, Line, Points, ...) at ``path``."""
    return ("set_object", path, umsgpack.packb({"type": "set_object", "object": obj.lower(), "path": path}))


# A set_transform message is msgpack {"type": "set_transform", "path": <str>, "matrix": [16 x float64]}.
# umsgpack (pure Python) takes ~0.1 ms to pack one; the viewer sends one per moving body per frame, so
# the bytes are laid out here directly (the same bytes umsgpack produces, checked by the unit tests).
_TRANSFORM_HEAD = b"\x83\xa4type\xadset_transform\xa4path"
_MATRIX_KEY = b"\xa6matrix\xdc\x00\x10"
_FLOAT64 = np.dtype([("marker", "u1"), ("value", ">f8")])


def _msgpack_str(text: str) -> bytes:
    data = text.encode("utf-8")
    if len(data) < 32:
        return bytes([0xA0 | len(data)]) + data
    if len(data) < 256:
        return b"\xd9" + bytes([len(data)]) + data
    return b"\xda" + len(data).to_bytes(2, "big") + data


def set_transform(path: str, matrix: np.ndarray) -> Command:
    """Place ``path`` at the 4x4 ``matrix`` relative to its parent."""
    values = np.empty(16, dtype=_FLOAT64)
    values["marker"] = 0xCB
    values["value"] = np.asarray(matrix, dtype=float).T.ravel()  # three.js matrices are column-major
    payload = _TRANSFORM_HEAD + _msgpack_str(path) + _MATRIX_KEY + values.tobytes()
    return ("set_transform", path, payload)


def set_property(path: str, key: str, value: Any) -> Command:
    """Set a property (``visible``, ``top_color``, ...) of the object at ``path``."""
    payload = {"type": "set_property", "path": path, "property": key, "value": value}
    return ("set_property", path, umsgpack.packb(payload))


def delete(path: str) -> Command:
    """Remove ``path`` and everything under it."""
    return ("delete", path, umsgpack.packb({"type": "delete", "path": path}))
