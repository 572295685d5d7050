"""The hand-laid set_transform bytes equal what meshcat's own packer (umsgpack) produces."""

from __future__ import annotations

import numpy as np
import pytest
import umsgpack

from kinema.viz import scene_commands as sc


@pytest.mark.parametrize("path", ["/a", "/kinema/bodies/" + "x" * 40, "/p" * 200])
def test_set_transform_bytes_match_umsgpack(path: str) -> None:
    matrix = np.arange(16, dtype=float).reshape(4, 4) / 7.0
    kind, sent_path, payload = sc.set_transform(path, matrix)
    expected = {"type": "set_transform", "path": path, "matrix": [float(v) for v in matrix.T.ravel()]}
    assert (kind, sent_path) == ("set_transform", path)
    assert payload == umsgpack.packb(expected)
