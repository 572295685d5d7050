"""The folder ``kinema security init`` writes: a CA, certificates and zenoh configs with access rules.

Layout (default ``$XDG_CONFIG_HOME/kinema/security``, ``~/.config/kinema/security``)::

    ca.pem  ca.key                 the certificate authority (keep ca.key on this machine, private)
    router.pem  router.key         the robot's router: its addresses are in the certificate
    router.json5                   zenoh router config: loopback + TLS listeners, mutual TLS, access rules
    clients/<name>.json5           one self-contained client config per operator machine (its key,
                                   certificate and the CA inline): copy it there, nothing else

``kinema run --connect tls/<address>:7448`` uses ``router.json5`` (see :mod:`kinema.runtime.router_plan`);
another machine runs ``KINEMA_ZENOH_CONFIG=<name>.json5 kinema ui`` (or any verb, or the SDK).

The access rules: processes on this machine (loopback interface, plain TCP) may do everything, and so
may the other machines of the cell (``--machine``: one that runs ``kinema run -n`` or ``-o``); a client
whose certificate's common name is one of the operators holds the grants of :data:`ROLES`: it runs the
library's objectives by name with parameters, cancels and watches (the objective streams, the waypoints,
the robot's state), and nothing else (no ad-hoc XML, no controller calls, no publishing, no waypoint
edits, no simulation services). Running ad-hoc XML is a grant of its own (``--allow-xml NAME``): the XML
doors (``/do_objective`` goals, the ``start_xml`` JSON key) are keys apart from the name-only ones, so
the router, which reads only keys, can tell them apart. ``kinema security`` prints the roles.
Certificates are X.509 v3 with ECDSA P-256 keys (what rustls, zenoh's TLS, accepts), made with the
``cryptography`` package.
"""

from __future__ import annotations

import base64
import datetime
import ipaddress
import json
import os
import socket
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kinema.errors import TransportError

ROUTER_CONFIG = "router.json5"
CLIENTS = "clients"
DEFAULT_TLS_PORT = 7448
DEFAULT_LOCAL_ENDPOINT = "tcp/127.0.0.1:7447"
CA_DAYS = 3650
LEAF_DAYS = 825


def default_security_dir() -> Path:
    """``$KINEMA_SECURITY_DIR``, else ``<user config>/kinema/security``."""
    configured = os.environ.get("KINEMA_SECURITY_DIR")
    if configured:
        return Path(configured).expanduser()
    import platformdirs

    return platformdirs.user_config_path("kinema") / "security"


def this_machines_addresses() -> list[str]:
    """The non-loopback IP addresses other machines can probably reach this one at (may be empty)."""
    found: list[str] = []
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.connect(
            ("192.0.2.1", 9)
        )  # a documentation address: picks the outgoing interface, sends nothing
        found.append(probe.getsockname()[0])
    except OSError:
        pass
    finally:
        probe.close()
    try:
        found += socket.gethostbyname_ex(socket.gethostname())[2]
    except OSError:
        pass
    unique = []
    for address in found:
        if not ipaddress.ip_address(address).is_loopback and address not in unique:
            unique.append(address)
    return unique


@dataclass(frozen=True)
class SecurityFolder:
    """What ``init`` wrote (paths) and how to use it."""

    path: Path
    addresses: tuple[str, ...]
    tls_endpoints: tuple[str, ...]
    clients: tuple[Path, ...]
    reused_ca: bool

    @property
    def router_config(self) -> Path:
        """The router's zenoh config."""
        return self.path / ROUTER_CONFIG


def init_security_folder(
    path: Path,
    *,
    addresses: Sequence[str],
    clients: Sequence[str] = ("operator",),
    machines: Sequence[str] = (),
    xml_clients: Sequence[str] = (),
    port: int = DEFAULT_TLS_PORT,
    local_endpoint: str = DEFAULT_LOCAL_ENDPOINT,
    domain_id: int = 0,
    force: bool = False,
) -> SecurityFolder:
    """Write (or complete) the security folder at ``path``.

    An existing CA is kept (certificates it signed stay valid) unless ``force``; the router's certificate,
    the configs of the clients named and ``router.json5`` are written anew every time. With the CA kept,
    the clients an earlier run gave access keep it (and their config files): running it again adds
    clients, and a client named again takes the role given now.

    Raises:
        TransportError: a bad address or client name, or the folder cannot be written.
    """
    _check_names([*clients, *machines])
    given = {*clients, *machines}  # their config files are written; earlier clients keep theirs
    unknown = [name for name in xml_clients if name not in clients]
    if unknown:
        raise TransportError(
            f"--allow-xml {unknown[0]}: not one of the clients ({', '.join(clients)}); "
            "name it with --client too"
        )
    ips, names = _split_addresses(addresses)
    try:
        path.mkdir(parents=True, exist_ok=True)
        os.chmod(path, 0o700)
        earlier = (holders(path) or []) if not force else []
        ca_key, ca_cert, reused = _certificate_authority(path, force=force)
        if reused:
            clients, machines, xml_clients = _with_earlier(earlier, clients, machines, xml_clients)
        san_ips = list(dict.fromkeys([ipaddress.ip_address("127.0.0.1"), *ips]))
        san_names = ["localhost", socket.gethostname(), *names]
        router_key, router_cert = _leaf("kinema-router", ca_key, ca_cert, san_ips, san_names)
        _write_pem(path / "router.key", _key_pem(router_key), private=True)
        _write_pem(path / "router.pem", _cert_pem(router_cert))
        reachable = [*(str(ip) for ip in ips), *names] or ["127.0.0.1"]
        tls_endpoints = tuple(f"tls/{_host(address)}:{port}" for address in reachable)
        _write_json5(
            path / ROUTER_CONFIG,
            "zenoh router config written by `kinema security init` (used by `kinema run --connect tls/…`).",
            router_config(
                path,
                [local_endpoint, *tls_endpoints],
                list(clients),
                domain_id,
                list(machines),
                list(xml_clients),
            ),
        )
        written = []
        for client in [name for name in [*clients, *machines] if name in given]:
            key, cert = _leaf(client, ca_key, ca_cert, [], [client])
            config = client_config(tls_endpoints[0], _cert_pem(ca_cert), _cert_pem(cert), _key_pem(key))
            target = path / CLIENTS / f"{client}.json5"
            target.parent.mkdir(exist_ok=True)
            _write_json5(
                target,
                f"zenoh client config for {client!r}, written by `kinema security init`. Copy this one "
                "file to that machine; it holds the machine's private key: keep it private.\n"
                f"Use: KINEMA_ZENOH_CONFIG=/path/{client}.json5 kinema ui   (or any kinema verb, or the SDK)",
                config,
                private=True,
            )
            written.append(target)
    except OSError as error:
        raise TransportError(f"cannot write the security folder {path}: {error.strerror or error}") from None
    return SecurityFolder(path, tuple(reachable), tls_endpoints, tuple(written), reused)


def _with_earlier(
    earlier: Sequence[tuple[str, str]],
    clients: Sequence[str],
    machines: Sequence[str],
    xml_clients: Sequence[str],
) -> tuple[list[str], list[str], list[str]]:
    """The clients, machines and XML clients of this run plus those of ``earlier`` (``holders``) that it
    does not name: a name given now takes the role given now."""
    named = {*clients, *machines}
    out_clients, out_machines, out_xml = list(clients), list(machines), list(xml_clients)
    for name, role in earlier:
        if name in named:
            continue
        named.add(name)
        if role.startswith("machine"):
            out_machines.append(name)
        else:
            out_clients.append(name)
            if role == "operator with XML":
                out_xml.append(name)
    return out_clients, out_machines, out_xml


def router_config(
    folder: Path,
    listen: Sequence[str],
    clients: Sequence[str],
    domain_id: int,
    machines: Sequence[str] = (),
    xml_clients: Sequence[str] = (),
) -> dict[str, Any]:
    """The router's zenoh config: the listeners, mutual TLS with ``folder``'s files, the access rules."""
    return {
        "mode": "router",
        "listen": {"endpoints": list(listen)},
        "transport": {
            "link": {
                "tls": {
                    "root_ca_certificate": str(folder / "ca.pem"),
                    "listen_certificate": str(folder / "router.pem"),
                    "listen_private_key": str(folder / "router.key"),
                    "enable_mtls": True,
                }
            }
        },
        "access_control": access_rules(clients, domain_id, machines, xml_clients),
    }


def client_config(endpoint: str, ca_pem: bytes, cert_pem: bytes, key_pem: bytes) -> dict[str, Any]:
    """A self-contained client config: connect to ``endpoint`` with this certificate, trusting the CA."""

    def b64(data: bytes) -> str:
        return base64.b64encode(data).decode("ascii")

    return {
        "mode": "client",
        "connect": {"endpoints": [endpoint]},
        "transport": {
            "link": {
                "tls": {
                    "root_ca_certificate_base64": b64(ca_pem),
                    "connect_certificate_base64": b64(cert_pem),
                    "connect_private_key_base64": b64(key_pem),
                    "enable_mtls": True,
                }
            }
        },
    }


@dataclass(frozen=True)
class Grant:
    """One thing a role may do: a sentence for people and the keys it opens (``{d}``: the domain id).

    The holder may ask on these keys (queries: service calls, action goals, the JSON endpoints) and
    subscribe to them; it never publishes and never serves.
    """

    name: str
    summary: str
    keys: tuple[str, ...]

    def key_exprs(self, domain_id: int) -> list[str]:
        """The zenoh key expressions, each with its ``@adv`` cache keys (``**`` skips ``@`` chunks)."""
        out: list[str] = []
        for key in self.keys:
            expr = key.format(d=domain_id)
            out.append(expr)
            if expr.endswith("/**") and not expr.startswith("@"):
                out.append(expr + "/@adv/**")
        return out


GRANTS: dict[str, Grant] = {
    grant.name: grant
    for grant in (
        Grant(
            "run",
            "run the library's objectives by name, with parameters (/execute_objective, "
            "/kinema/run_objective, `kinema objective run`)",
            (
                "{d}/execute_objective/**",
                "{d}/kinema/run_objective/**",
                "kinema/{d}/objective_server/start",
            ),
        ),
        Grant(
            "cancel",
            "cancel the running objective (/cancel_objective, a /do_objective goal's cancel, "
            "`kinema objective cancel`)",
            (
                "{d}/cancel_objective/**",
                "{d}/do_objective/_action/cancel_goal/**",
                "kinema/{d}/objective_server/cancel",
            ),
        ),
        Grant(
            "watch",
            "watch: the heartbeat and health, node states, the blackboard, logs, the objective list and "
            "XML, saved waypoints (read), joint states, the clock, task planning, goals' results",
            (
                "{d}/objective_server_heartbeat/**",
                "{d}/objective_server/node_status/**",
                "{d}/objective_server/node_table/**",
                "{d}/objective_server/blackboard/**",
                "{d}/objective_server/log/**",
                "{d}/objective_server/health/**",
                "{d}/objective_server/list_objectives/**",
                "{d}/objective_server/get_objective_xml/**",
                "{d}/kinema/task_planning/**",
                "{d}/do_objective/_action/status/**",
                "{d}/do_objective/_action/feedback/**",
                "{d}/do_objective/_action/get_result/**",
                "{d}/get_saved_waypoints/**",
                "{d}/joint_states/**",
                "{d}/clock/**",
                "kinema/{d}/objective_server/status",
                "@ros2_lv/{d}/**",
                "@kinema_lv/{d}/**",
            ),
        ),
        Grant(
            "xml",
            "run ad-hoc objective XML (/do_objective goals, `kinema objective do`, the SDK's do_xml): "
            "any behavior with any ports, within the file, security and robot rules",
            ("{d}/do_objective/_action/send_goal/**", "kinema/{d}/objective_server/start_xml"),
        ),
    )
}

ROLES: dict[str, tuple[str, ...]] = {
    # --client NAME: the default operator.
    "operator": ("run", "cancel", "watch"),
    # --client NAME --allow-xml NAME.
    "operator with XML": ("run", "cancel", "watch", "xml"),
}
EVERYTHING = (
    "everything: processes on this machine (loopback) and the cell's other machines (--machine) may "
    "publish, serve and call every key (waypoint edits, controllers, simulation services included)"
)
FILE_RULES = (
    "whatever the role, a file path an objective gets (any port, any parameter override) resolves only "
    "inside the workspace, the config packages and Kinema's data folder, and never inside this "
    "security folder"
)


def describe_roles() -> list[str]:
    """The roles as lines a person reads (``kinema security`` prints them)."""
    lines = []
    for role, grants in ROLES.items():
        lines.append(f"{role}:")
        lines += [f"  - {GRANTS[name].summary}" for name in grants]
    lines.append("local processes and --machine:")
    lines.append(f"  - {EVERYTHING}")
    lines.append("every role:")
    lines.append(f"  - {FILE_RULES}")
    return lines


def holders(folder: Path) -> list[tuple[str, str]] | None:
    """``(client, role)`` for each client of ``folder``'s ``router.json5``; None when there is none."""
    try:
        text = (folder / ROUTER_CONFIG).read_text(encoding="utf-8")
        # What _write_json5 wrote: '//' comment lines, then JSON.
        config = json.loads("".join(line for line in text.splitlines(True) if not line.startswith("//")))
    except (OSError, ValueError):
        return None
    roles = {
        "operators": "operator",
        "operators_with_xml": "operator with XML",
        "cell_machines": "machine (everything)",
    }
    out = []
    for subject in config.get("access_control", {}).get("subjects", []):
        role = roles.get(subject.get("id", ""))
        if role is not None:
            out += [(str(name), role) for name in subject.get("cert_common_names", [])]
    return out


def access_rules(
    clients: Iterable[str],
    domain_id: int,
    machines: Iterable[str] = (),
    xml_clients: Iterable[str] = (),
) -> dict[str, Any]:
    """The rule set of :data:`ROLES`: ``clients`` are operators, ``xml_clients`` (some of them) may also
    run ad-hoc XML, ``machines`` get what local processes get."""
    d = domain_id
    clients, machines, xml_clients = list(clients), list(machines), list(xml_clients)
    loopback = [name for _index, name in socket.if_nameindex() if name.startswith("lo")] or ["lo"]
    rules: list[dict[str, Any]] = [
        {
            "id": "everything",
            "messages": [
                "put",
                "delete",
                "declare_subscriber",
                "query",
                "reply",
                "declare_queryable",
                "liveliness_token",
                "liveliness_query",
                "declare_liveliness_subscriber",
            ],
            "flows": ["ingress", "egress"],
            "permission": "allow",
            "key_exprs": ["**", "**/@adv/**", "@ros2_lv/**", "@kinema_lv/**"],
        },
        {
            # Its SDK nodes appear in the ROS graph like any other.
            "id": "operator_graph",
            "messages": ["liveliness_token"],
            "flows": ["ingress"],
            "permission": "allow",
            "key_exprs": [f"@ros2_lv/{d}/**"],
        },
    ]
    for grant in GRANTS.values():
        keys = grant.key_exprs(d)
        rules.append(
            {
                # What the holder sends: calls, subscriptions, graph lookups; never data or servers.
                "id": f"{grant.name}_requests",
                "messages": [
                    "query",
                    "declare_subscriber",
                    "liveliness_query",
                    "declare_liveliness_subscriber",
                ],
                "flows": ["ingress"],
                "permission": "allow",
                "key_exprs": keys,
            }
        )
        rules.append(
            {
                # What the holder receives: the answers and the data it subscribed to.
                "id": f"{grant.name}_answers",
                "messages": [
                    "put",
                    "delete",
                    "reply",
                    "declare_subscriber",
                    "declare_queryable",
                    "liveliness_token",
                    "declare_liveliness_subscriber",
                ],
                "flows": ["egress"],
                "permission": "allow",
                "key_exprs": keys,
            }
        )

    def grant_rules(role: str) -> list[str]:
        names = [r for g in ROLES[role] for r in (f"{g}_requests", f"{g}_answers")]
        return ["operator_graph", *names]

    operators = [name for name in clients if name not in xml_clients]
    subjects: list[dict[str, Any]] = [
        {"id": "local_processes", "interfaces": loopback, "link_protocols": ["tcp"]}
    ]
    policies: list[dict[str, Any]] = [
        {"rules": ["everything"], "subjects": ["local_processes", *(["cell_machines"] if machines else [])]}
    ]
    if operators:
        subjects.append({"id": "operators", "cert_common_names": operators})
        policies.append({"rules": grant_rules("operator"), "subjects": ["operators"]})
    if xml_clients:
        subjects.append({"id": "operators_with_xml", "cert_common_names": xml_clients})
        policies.append({"rules": grant_rules("operator with XML"), "subjects": ["operators_with_xml"]})
    if machines:
        subjects.append({"id": "cell_machines", "cert_common_names": machines})
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }


# -- certificates ---------------------------------------------------------------------------------------


def _certificate_authority(folder: Path, *, force: bool) -> tuple[Any, Any, bool]:
    from cryptography import x509
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric import ec

    key_file, cert_file = folder / "ca.key", folder / "ca.pem"
    if not force and key_file.is_file() and cert_file.is_file():
        key = serialization.load_pem_private_key(key_file.read_bytes(), password=None)
        return key, x509.load_pem_x509_certificate(cert_file.read_bytes()), True
    key = ec.generate_private_key(ec.SECP256R1())
    name = x509.Name([x509.NameAttribute(x509.NameOID.COMMON_NAME, f"kinema-ca-{socket.gethostname()}")])
    now = datetime.datetime.now(datetime.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(name)
        .issuer_name(name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=CA_DAYS))
        .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
        .add_extension(_key_usage(cert_sign=True), critical=True)
        .add_extension(x509.SubjectKeyIdentifier.from_public_key(key.public_key()), critical=False)
        .sign(key, _sha256())
    )
    _write_pem(key_file, _key_pem(key), private=True)
    _write_pem(cert_file, _cert_pem(cert))
    return key, cert, False


def _leaf(
    common_name: str, ca_key: Any, ca_cert: Any, ips: Sequence[Any], names: Sequence[str]
) -> tuple[Any, Any]:
    from cryptography import x509
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import ExtendedKeyUsageOID

    key = ec.generate_private_key(ec.SECP256R1())
    now = datetime.datetime.now(datetime.UTC)
    alternative = [x509.IPAddress(ip) for ip in ips] + [x509.DNSName(n) for n in dict.fromkeys(names) if n]
    builder = (
        x509.CertificateBuilder()
        .subject_name(x509.Name([x509.NameAttribute(x509.NameOID.COMMON_NAME, common_name)]))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=LEAF_DAYS))
        .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
        .add_extension(_key_usage(cert_sign=False), critical=True)
        .add_extension(
            x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH]),
            critical=False,
        )
        .add_extension(
            x509.AuthorityKeyIdentifier.from_issuer_public_key(ca_cert.public_key()), critical=False
        )
    )
    if alternative:
        builder = builder.add_extension(x509.SubjectAlternativeName(alternative), critical=False)
    return key, builder.sign(ca_key, _sha256())


def _key_usage(*, cert_sign: bool) -> Any:
    from cryptography import x509

    return x509.KeyUsage(
        digital_signature=not cert_sign,
        content_commitment=False,
        key_encipherment=False,
        data_encipherment=False,
        key_agreement=False,
        key_cert_sign=cert_sign,
        crl_sign=cert_sign,
        encipher_only=False,
        decipher_only=False,
    )


def _sha256() -> Any:
    from cryptography.hazmat.primitives import hashes

    return hashes.SHA256()


def _key_pem(key: Any) -> bytes:
    from cryptography.hazmat.primitives import serialization

    return bytes(
        key.private_bytes(
            serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
        )
    )


def _cert_pem(cert: Any) -> bytes:
    from cryptography.hazmat.primitives import serialization

    return bytes(cert.public_bytes(serialization.Encoding.PEM))


# -- files and names ------------------------------------------------------------------------------------


def _write_pem(path: Path, data: bytes, *, private: bool = False) -> None:
    from kinema.config.atomic_write import atomic_write_bytes

    atomic_write_bytes(path, data, error=TransportError)
    os.chmod(path, 0o600 if private else 0o644)


def _write_json5(path: Path, comment: str, data: dict[str, Any], *, private: bool = False) -> None:
    header = "".join(f"// {line}\n" for line in comment.splitlines())
    _write_pem(path, (header + json.dumps(data, indent=2) + "\n").encode(), private=private)


def _check_names(clients: Sequence[str]) -> None:
    import re

    if not clients:
        raise TransportError("name at least one client (--client NAME): the operators' machines")
    for client in clients:
        if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,62}", client):
            raise TransportError(
                f"bad client name {client!r}: use letters, digits, '_', '.', '-' (it becomes the "
                "certificate's common name and a file name), e.g. operator-laptop"
            )


def _split_addresses(addresses: Sequence[str]) -> tuple[list[Any], list[str]]:
    import re

    ips, names = [], []
    for address in addresses:
        address = address.strip().strip("[]")
        try:
            ips.append(ipaddress.ip_address(address))
            continue
        except ValueError:
            pass
        if not re.fullmatch(r"[A-Za-z0-9]([A-Za-z0-9-]{0,62})(\.[A-Za-z0-9]([A-Za-z0-9-]{0,62}))*", address):
            raise TransportError(
                f"bad address {address!r}: give an IP address (192.168.1.10) or a host name (robot.local) "
                "that the other machines use to reach this one"
            )
        names.append(address)
    return ips, names


def _host(address: str) -> str:
    return f"[{address}]" if ":" in address else address
