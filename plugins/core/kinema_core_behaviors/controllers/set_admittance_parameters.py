"""SetAdmittanceParameters: read the compliance of a trajectory from a YAML file into a message."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.errors import did_you_mean

from ..files.locations import file_to_read
from ..files.yaml_messages import read_documents
from ..messages.ports import fails_on_bad_input, message_output, port_error, read_input

ADMITTANCE_PARAMETERS = "moveit_pro_controllers_msgs/msg/AdmittanceParameters"
SECTION = "SetAdmittanceParameters"
AXES = ("x", "y", "z", "rx", "ry", "rz")
# The admittance section's vectors and their units.
VECTORS = {
    "mass_position": "kg",
    "mass_rotation": "kg m^2",
    "stiffness_position": "N/m",
    "stiffness_rotation": "N m/rad",
    "damping_ratio_position": "",
    "damping_ratio_rotation": "",
}
ADMITTANCE_KEYS = ("selected_axes", *VECTORS, "joint_damping")
FRAME_KEYS = ("controller_name", "end_effector_frame", "control_frame")


class SetAdmittanceParameters(AsyncBehavior):
    """Reads admittance parameters from a YAML file and writes them to ``admittance_parameters_msg``.

    The file is MoveIt Pro's: a ``SetAdmittanceParameters:`` mapping (or the same keys at the top) with
    ``controller_name``, ``end_effector_frame``, ``control_frame`` and ``admittance:`` holding
    ``selected_axes`` (x, y, z, rx, ry, rz: true/false), ``mass_position``/``mass_rotation`` (kg, kg m^2),
    ``stiffness_position``/``stiffness_rotation`` (N/m, N m/rad), ``damping_ratio_position``/
    ``damping_ratio_rotation`` (fractions of critical damping), each an x, y, z mapping with optional
    ``min``/``max`` bounds, and ``joint_damping`` (``value``, 1/s). Pass the message to ExecuteTrajectory's
    (or ExecuteTrajectoryWithAdmittance's) ``admittance_parameters_msg``: it travels to the admittance
    controller with the trajectory, and the compliance lasts for that trajectory only.

    Fails when the file is missing or not YAML, a key is missing or unknown, a value is not a number (or a
    true/false for the axes), or a value lies outside its own ``min``/``max``; the message names the file
    and the key.
    """

    subcategory = "Motion - Execute"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "config_file_name",
                str,
                "",
                "YAML file of admittance parameters; a relative name is in the config's objectives folder "
                "(MoveIt Pro's objectives give e.g. stationary_admittance.yaml).",
            ),
            message_output(
                "admittance_parameters_msg",
                ADMITTANCE_PARAMETERS,
                "{admittance_parameters_msg}",
                "The parameters, for ExecuteTrajectory's admittance_parameters_msg.",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        from kinema.transport import from_dict

        path = file_to_read(self, "config_file_name", str(read_input(self, "config_file_name")))
        documents = read_documents(self, "config_file_name", path)
        if len(documents) != 1 or not isinstance(documents[0], dict):
            raise port_error(self, "config_file_name", f"file {path} holds no mapping", "expected one")
        fields = parameters_from_yaml(documents[0], lambda problem: self._bad(path, problem))
        self.set_output("admittance_parameters_msg", from_dict(ADMITTANCE_PARAMETERS, fields))
        return True

    def _bad(self, path: Path, problem: str) -> Exception:
        return port_error(self, "config_file_name", f"file {path}: {problem}", "")


def parameters_from_yaml(document: dict[str, Any], bad: Any) -> dict[str, Any]:
    """The ``AdmittanceParameters`` fields of a SetAdmittanceParameters YAML mapping.

    ``bad(problem)`` makes the exception raised for a problem (a missing or unknown key, a wrong value).
    """
    section = document.get(SECTION, document)
    if not isinstance(section, dict):
        raise bad(f"{SECTION} must be a mapping")
    admittance = section.get("admittance")
    if not isinstance(admittance, dict):
        raise bad("no admittance: mapping (selected_axes, mass_position, ..., joint_damping)")
    unknown = [k for k in admittance if k not in ADMITTANCE_KEYS]
    if unknown:
        raise bad(f"unknown key admittance.{unknown[0]}: {did_you_mean(str(unknown[0]), ADMITTANCE_KEYS)}")
    missing = [k for k in ADMITTANCE_KEYS if k not in admittance]
    if missing:
        raise bad(f"admittance lacks {', '.join(missing)}")
    axes = admittance["selected_axes"]
    if not isinstance(axes, dict) or any(not isinstance(axes.get(a), bool) for a in AXES):
        raise bad(f"admittance.selected_axes must give each of {', '.join(AXES)} as true or false")
    fields: dict[str, Any] = {key: str(section.get(key) or "") for key in FRAME_KEYS} | {
        "selected_axes": {a: axes[a] for a in AXES}
    }
    for key, unit in VECTORS.items():
        entry = admittance[key]
        if not isinstance(entry, dict):
            raise bad(f"admittance.{key} must be a mapping of x, y, z (and min, max)")
        fields[key] = {a: _bounded(entry, a, f"admittance.{key}", unit, bad) for a in "xyz"}
    damping = admittance["joint_damping"]
    if not isinstance(damping, dict):
        raise bad("admittance.joint_damping must be a mapping with value (and min, max)")
    fields["joint_damping"] = _bounded(damping, "value", "admittance.joint_damping", "1/s", bad)
    return fields


def _number(value: Any, where: str, bad: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise bad(f"{where} must be a number, got {value!r}")
    return float(value)


def _bounded(entry: dict[str, Any], key: str, where: str, unit: str, bad: Any) -> float:
    """``entry[key]`` as a number within the entry's own ``min``/``max``."""
    if key not in entry:
        raise bad(f"{where} lacks {key}")
    value = _number(entry[key], f"{where}.{key}", bad)
    low = _number(entry["min"], f"{where}.min", bad) if "min" in entry else None
    high = _number(entry["max"], f"{where}.max", bad) if "max" in entry else None
    if (low is not None and value < low) or (high is not None and value > high):
        shown = f"{value:g} {unit}".strip()
        raise bad(
            f"{where}.{key} = {shown} is outside [{low if low is not None else '-inf'}, "
            f"{high if high is not None else 'inf'}]"
        )
    return value
