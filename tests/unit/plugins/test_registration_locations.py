"""A behavior whose port name BT.CPP would refuse is reported at the line that declares it."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from kinema.errors import PluginError
from kinema.plugins.registration import validate_registration

SOURCE = """from kinema.behaviors import SyncBehavior, input_port, output_port
from kinema.bt import NodeStatus


class Weigh(SyncBehavior):
    @classmethod
    def provided_ports(cls):
        return [
            input_port("mass_kg", float, 1.0, "Mass."),
            input_port("grav ity", float, 9.81, "Gravity."),
            output_port("force_n", float, "{force_n}", "Force."),
        ]

    def tick(self):
        return NodeStatus.SUCCESS
"""


def test_a_forbidden_port_name_is_reported_at_its_line(tmp_path: Path) -> None:
    # On hot reload the user read "Port name 'grav ity' contains forbidden character ' '" and no file:line.
    path = tmp_path / "weigh_behavior.py"
    path.write_text(SOURCE)
    spec = importlib.util.spec_from_file_location("weigh_behavior", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["weigh_behavior"] = module
    try:
        spec.loader.exec_module(module)
        with pytest.raises(PluginError) as info:
            validate_registration(module.Weigh, None, "weigh::WeighBehaviorsLoader")
    finally:
        del sys.modules["weigh_behavior"]
    assert str(info.value).startswith(f"{path}:10: plugin 'weigh::WeighBehaviorsLoader': behavior 'Weigh': ")
    assert "Port name 'grav ity' contains forbidden character" in str(info.value)
