"""rmw_zenoh key expressions and liveliness tokens (the ROS graph on zenoh).

Data keys: ``<domain>/<fully qualified name without the leading '/'>/<dds type>/<RIHS01 hash>``.
Graph tokens::

    @ros2_lv/<domain>/<zid>/<node id>/<node id>/NN/<enclave>/<namespace>/<node name>
    @ros2_lv/<domain>/<zid>/<node id>/<entity id>/<MP|MS|SS|SC>/<enclave>/<namespace>/<node name>/
        <fully qualified name>/<dds type>/<hash>/<qos>

where names are mangled ('/' → '%') and an empty enclave or root namespace is ``%``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum

from kinema.errors import TransportError

LIVELINESS_PREFIX = "@ros2_lv"
_NAME_TOKEN = re.compile(r"^[A-Za-z_~{][A-Za-z0-9_/{}~]*$")


class EntityKind(StrEnum):
    """Kinds of graph entity, as written in liveliness tokens."""

    NODE = "NN"
    PUBLISHER = "MP"
    SUBSCRIPTION = "MS"
    SERVICE_SERVER = "SS"
    SERVICE_CLIENT = "SC"


@dataclass(frozen=True)
class QoS:
    """The QoS a graph token advertises (defaults = ROS 2 ``rmw_qos_profile_default``)."""

    reliable: bool = True
    transient_local: bool = False
    keep_all: bool = False
    depth: int = 10

    def encode(self) -> str:
        """rmw_zenoh's compact form ``rel:dur:hist,depth:dl:ls:liv``; defaults are left empty."""
        reliability = "" if self.reliable else "2"
        durability = "1" if self.transient_local else ""
        history = "2" if self.keep_all else ""
        return f"{reliability}:{durability}:{history},{self.depth}:,:,:,,"

    @classmethod
    def decode(cls, text: str) -> QoS:
        """Parse the compact form (unknown or empty fields take the defaults)."""
        parts = text.split(":")
        reliability = parts[0] if parts else ""
        durability = parts[1] if len(parts) > 1 else ""
        history, _, depth = (parts[2] if len(parts) > 2 else ",").partition(",")
        return cls(
            reliable=reliability != "2",
            transient_local=durability == "1",
            keep_all=history == "2",
            depth=int(depth) if depth.isdigit() else 10,
        )


SERVICE_QOS = QoS()
LATCHED_QOS = QoS(transient_local=True, depth=1)
# Keep all: every message is delivered. Over zenoh (as rmw_zenoh maps KEEP_ALL) a full link queue makes
# ``publish`` wait instead of dropping the message. For drawings a user asked for (snapshots, markers,
# planned paths): a large one dropped under load simply never appears.
KEEP_ALL_QOS = QoS(keep_all=True)


def mangle(name: str) -> str:
    """``/robot1/chatter`` → ``%robot1%chatter``; an empty name (root namespace, no enclave) → ``%``."""
    return name.replace("/", "%") if name else "%"


def demangle(text: str) -> str:
    """Inverse of ``mangle`` (``%`` alone is the empty name)."""
    return "" if text == "%" else text.replace("%", "/")


def normalize_namespace(namespace: str) -> str:
    """``""``/``"/"`` → ``""``; ``"robot1"`` → ``"/robot1"``; trailing slashes dropped."""
    namespace = namespace.strip().strip("/")
    return f"/{namespace}" if namespace else ""


def fully_qualified(name: str, namespace: str = "", node_name: str = "") -> str:
    """Resolve a topic/service name as rcl does: absolute names stay, relative ones join the namespace.

    ``~/x`` expands to ``<namespace>/<node>/x``.
    """
    name = name.strip()
    if not name:
        raise TransportError("a topic, service or action name cannot be empty")
    if name.startswith("~"):
        if not node_name:
            raise TransportError(f"name {name!r} uses '~' but no node name is known")
        name = f"{normalize_namespace(namespace)}/{node_name}{name[1:]}"
    elif not name.startswith("/"):
        name = f"{normalize_namespace(namespace)}/{name}"
    name = "/" + "/".join(part for part in name.split("/") if part)
    if not _NAME_TOKEN.match(name[1:]) or "//" in name:
        raise TransportError(f"invalid topic/service name {name!r}: use letters, digits, '_' and '/'")
    return name


def data_key(domain_id: int, fq_name: str, dds_type: str, type_hash: str) -> str:
    """The key expression samples and queries travel on."""
    return f"{domain_id}/{fq_name.lstrip('/')}/{dds_type}/{type_hash}"


def node_token(
    domain_id: int, zid: str, node_id: int, namespace: str, node_name: str, enclave: str = ""
) -> str:
    """Liveliness token announcing a node."""
    return (
        f"{LIVELINESS_PREFIX}/{domain_id}/{zid}/{node_id}/{node_id}/{EntityKind.NODE.value}/"
        f"{mangle(enclave)}/{mangle(namespace)}/{node_name}"
    )


def entity_token(
    domain_id: int,
    zid: str,
    node_id: int,
    entity_id: int,
    kind: EntityKind,
    namespace: str,
    node_name: str,
    fq_name: str,
    dds_type: str,
    type_hash: str,
    qos: QoS,
    enclave: str = "",
) -> str:
    """Liveliness token announcing a publisher, subscription, service server or client."""
    return (
        f"{LIVELINESS_PREFIX}/{domain_id}/{zid}/{node_id}/{entity_id}/{kind.value}/{mangle(enclave)}/"
        f"{mangle(namespace)}/{node_name}/{mangle(fq_name)}/{dds_type}/{type_hash}/{qos.encode()}"
    )


@dataclass(frozen=True)
class GraphEntity:
    """One parsed liveliness token."""

    domain_id: int
    zid: str
    node_id: str
    entity_id: str
    kind: EntityKind
    enclave: str
    namespace: str
    node_name: str
    name: str = ""
    dds_type: str = ""
    type_hash: str = ""
    qos: QoS | None = None

    @property
    def node_fqn(self) -> str:
        """``/namespace/node`` of the owning node."""
        return f"{self.namespace}/{self.node_name}"

    @property
    def type_name(self) -> str:
        """ROS type name (``pkg/msg/Name``) from the DDS name (``pkg::msg::dds_::Name_``)."""
        parts = self.dds_type.split("::")
        if len(parts) == 4 and parts[2] == "dds_" and parts[3].endswith("_"):
            return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"
        return self.dds_type


def parse_token(key: str) -> GraphEntity | None:
    """Parse a ``@ros2_lv/...`` token; ``None`` when it is not one (or malformed)."""
    parts = str(key).split("/")
    if len(parts) < 9 or parts[0] != LIVELINESS_PREFIX:
        return None
    try:
        kind = EntityKind(parts[5])
        domain_id = int(parts[1])
    except ValueError:
        return None
    common = {
        "domain_id": domain_id,
        "zid": parts[2],
        "node_id": parts[3],
        "entity_id": parts[4],
        "kind": kind,
        "enclave": demangle(parts[6]),
        "namespace": demangle(parts[7]),
        "node_name": parts[8],
    }
    if kind == EntityKind.NODE:
        return GraphEntity(**common)  # type: ignore[arg-type]
    if len(parts) < 13:
        return None
    return GraphEntity(
        **common,  # type: ignore[arg-type]
        name=demangle(parts[9]),
        dds_type=parts[10],
        type_hash=parts[11],
        qos=QoS.decode("/".join(parts[12:])),
    )
