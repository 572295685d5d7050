"""The behavior reference: every registered behavior as MoveIt Pro's behavior documentation shows it.

Generated from the registry, so it cannot drift from the code: behaviors grouped by subcategory, each
with its ID, description and a table of ports (direction, type, default, description). ``kinema
behaviors --markdown`` prints it; ``docs/behavior-reference.md`` is this text for lab_sim's loaders and a
test keeps it current.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

HEADER = """# Behavior reference

The behaviors of Kinema's bundled loaders (`kinema::CoreBehaviorsLoader`, `kinema::MujocoBehaviorsLoader`),
grouped by subcategory. Generated from the registry: do not edit by hand; regenerate with

```bash
kinema behaviors --markdown -c lab_sim > docs/behavior-reference.md
```

Types are BehaviorTree.CPP's names (`std::string`, `double`, `std::vector<...>`, ROS messages as
`pkg::msg::Name`); `BT::AnyTypeAllowed` ports take a value of any type. Outputs default to the
blackboard entry named in braces.
"""


def _cell(text: str | None) -> str:
    if text is None:
        return ""
    return str(text).replace("\\", "\\\\").replace("|", "\\|").replace("\n", " ").strip()


def _code(text: str | None) -> str:
    if text is None:
        return "—"
    return f"`{_cell(text)}`" if text != "" else '`""`'


def behavior_markdown(record: Any) -> str:
    """One behavior: heading, description, plugin and its ports table."""
    lines = [f"### {record.behavior_id}", ""]
    description = str(record.metadata.get("description", "")).strip()
    if description:
        lines += [description, ""]
    lines += [f"Plugin: `{record.plugin}`.", ""]
    lines += [f"{line}" for line in _former_spellings(record)]
    ports = list(record.ports)
    if not ports:
        lines += ["No ports.", ""]
        return "\n".join(lines)
    lines += ["| Port | Direction | Type | Default | Description |", "|---|---|---|---|---|"]
    for port in ports:
        direction = port.direction.xml_tag.replace("_port", "")
        lines.append(
            f"| `{port.name}` | {direction} | `{_cell(port.type_name)}` | {_code(port.default_str)} "
            f"| {_cell(port.description)} |"
        )
    lines.append("")
    return "\n".join(lines)


def _former_spellings(record: Any) -> list[str]:
    """Lines naming the old spellings objectives may still use (read as this behavior, with a warning)."""
    from kinema.plugins.registry import former_spellings_of

    parts: list[str] = []
    for spelling in former_spellings_of(record):
        ports = [f"`{old}` is `{new}`" for old, new in spelling.ports.items()]
        for old, reason in spelling.dropped.items():
            accepted = spelling.accepted_values.get(old)
            if accepted is None:
                ports.append(f"`{old}` is ignored — {reason}")
            else:
                ports.append(f"`{old}` is ignored when `{accepted[0]}`, refused otherwise — {reason}")
        if spelling.old_id:
            text = f"`{spelling.old_id}`" + (
                f" is read as the SubTree `{spelling.current_id}`" if spelling.subtree else ""
            )
            parts.append(text + (f" (port {'; '.join(ports)})" if ports else ""))
        elif ports:
            parts.append("port " + "; ".join(ports))
    if not parts:
        return []
    origin = former_spellings_of(record)[0].origin
    return [f"Former spellings ({origin}), read with a warning: " + "; ".join(parts) + ".", ""]


def reference_markdown(records: Iterable[Any], header: str = HEADER) -> str:
    """The whole reference: ``header``, a table of contents by subcategory, then every behavior."""
    by_subcategory: dict[str, list[Any]] = {}
    for record in records:
        subcategory = str(record.metadata.get("subcategory", "")) or "Uncategorized"
        by_subcategory.setdefault(subcategory, []).append(record)
    parts = [header.rstrip(), ""]
    for subcategory in sorted(by_subcategory, key=str.lower):
        ids = ", ".join(f"`{r.behavior_id}`" for r in sorted(by_subcategory[subcategory], key=_id))
        parts += [f"- **{subcategory}**: {ids}"]
    parts.append("")
    for subcategory in sorted(by_subcategory, key=str.lower):
        parts += [f"## {subcategory}", ""]
        parts += [behavior_markdown(r) for r in sorted(by_subcategory[subcategory], key=_id)]
    return "\n".join(parts).rstrip() + "\n"


def _id(record: Any) -> str:
    return str(record.behavior_id).lower()
