"""ros2-style verbs: ``kinema topic|service|action|node ...`` on Kinema's zenoh network.

Values are YAML flow text as ``ros2`` takes them (``"{a: 1, b: 2}"``). Every verb joins the router at
``--connect`` (default ``KINEMA_ZENOH_CONNECT`` or ``tcp/127.0.0.1:7447``) and exits 1 with one line when
nothing answers within ``--timeout``.
"""

from __future__ import annotations

import itertools
import math
import os
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import click

from kinema.cli.groups import VerbGroup
from kinema.errors import TransportError

if TYPE_CHECKING:
    from kinema.transport import Graph, Node

_CONNECT_HELP = (
    "Router endpoint to join (default: $KINEMA_ZENOH_CONNECT, else the endpoint of $KINEMA_ZENOH_CONFIG, "
    "else tcp/127.0.0.1:7447)."
)


def _common(default_timeout: float) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        func = click.option(
            "--connect", "-e", "connect", metavar="ENDPOINT", default=None, help=_CONNECT_HELP
        )(func)
        func = click.option(
            "--timeout",
            type=float,
            default=default_timeout,
            show_default=True,
            help="Seconds to wait for an answer before giving up.",
        )(func)
        return func

    return decorate


@contextmanager
def _node(connect: str | None, timeout: float) -> Iterator[Node]:
    from kinema.transport import Node, open_session

    with open_session(connect, connect_timeout=min(max(timeout, 0.5), 5.0)) as session:
        yield Node(session, f"_kinema_cli_{os.getpid()}")


def _graph(node: Node, timeout: float) -> Graph:
    """The network's graph, once two answers in a row agree.

    Right after this process joins, its routes to the other processes are still forming: the first
    answers can leave out whole processes (an agent, a driver) while the next ones have them all.
    """
    deadline = time.monotonic() + timeout
    own = node.session.zid
    previous: frozenset[Any] | None = None
    while True:
        graph = node.graph(timeout=max(0.05, min(deadline - time.monotonic(), 2.0)))
        seen = frozenset(graph.entities)
        foreign = any(entity.zid != own for entity in graph.entities)
        if (foreign and seen == previous) or time.monotonic() >= deadline:
            return graph
        previous = seen if foreign else None
        time.sleep(0.05)


def _print_names(names_and_types: dict[str, list[str]], show_types: bool, as_json: bool) -> None:
    import json

    if as_json:
        click.echo(json.dumps(names_and_types, indent=2))
        return
    for name, types in names_and_types.items():
        click.echo(f"{name} [{', '.join(types)}]" if show_types else name)


def _print_endpoints(graph: Graph, kinds: tuple[str, ...], hidden: bool) -> None:
    """One line per endpoint: name, role, node, type and RIHS01 hash (to spot definition mismatches)."""
    from kinema.transport.keys import EntityKind

    roles = {
        EntityKind.PUBLISHER: "publisher",
        EntityKind.SUBSCRIPTION: "subscription",
        EntityKind.SERVICE_SERVER: "server",
        EntityKind.SERVICE_CLIENT: "client",
    }
    rows = sorted(
        (entity.name, roles[entity.kind], entity.node_fqn, entity.type_name, entity.type_hash)
        for entity in graph.of_kind(*(EntityKind(kind) for kind in kinds))
        if hidden or "/_action/" not in entity.name
    )
    for row in rows:
        click.echo("  ".join(row))


def _discover_type(
    node: Node, name: str, what: str, lookup: Callable[[Graph], dict[str, list[str]]], timeout: float
) -> str:
    """The type of a topic/service/action from the graph, waiting up to ``timeout`` for it to appear."""
    found: list[str] = []

    def present(graph: Graph) -> bool:
        found[:] = lookup(graph).get(name, [])
        return bool(found)

    cache = node.session.graph_cache()
    if not cache.wait_for(present, timeout):
        known = sorted(lookup(cache.snapshot()))
        from kinema.errors import did_you_mean

        raise TransportError(
            f"no {what} {name} on the network within {timeout:g} s ({did_you_mean(name, known)})"
        )
    if len(found) > 1:
        raise TransportError(
            f"{what} {name} has several types ({', '.join(found)}); give the type explicitly"
        )
    return found[0]


# -- topic ---------------------------------------------------------------------------------------


@click.group(cls=VerbGroup)
def topic() -> None:
    """Inspect and use topics (list, echo, pub, hz)."""


@topic.command("list")
@click.option("-t", "--show-types", is_flag=True, help="Show each topic's type.")
@click.option("-a", "--include-hidden", is_flag=True, help="Include action internals (…/_action/…).")
@click.option("--json", "as_json", is_flag=True, help="Print {topic: [types]} as JSON.")
@click.option(
    "-v", "--verbose", is_flag=True, help="One line per publisher/subscription with node and type hash."
)
@_common(2.0)
def topic_list(
    show_types: bool, include_hidden: bool, as_json: bool, verbose: bool, connect: str | None, timeout: float
) -> None:
    """List the topics that have a publisher or a subscription."""
    with _node(connect, timeout) as node:
        graph = _graph(node, timeout)
    if verbose:
        _print_endpoints(graph, ("MP", "MS"), include_hidden)
        return
    _print_names(graph.topics(hidden=include_hidden), show_types, as_json)


@topic.command("echo")
@click.argument("topic_name")
@click.argument("msg_type", required=False)
@click.option("-n", "--count", type=int, default=0, help="Exit after this many messages (0: until Ctrl-C).")
@click.option("--once", is_flag=True, help="Exit after the first message (same as -n 1).")
@click.option("--flow", is_flag=True, help="Print each message on one line (YAML flow style).")
@click.option("--latched", is_flag=True, help="Also receive the last message of latched publishers.")
@_common(5.0)
def topic_echo(
    topic_name: str,
    msg_type: str | None,
    count: int,
    once: bool,
    flow: bool,
    latched: bool,
    connect: str | None,
    timeout: float,
) -> None:
    """Print the messages on TOPIC_NAME (type found from the graph unless MSG_TYPE is given).

    With --count/--once, exits 1 when the messages do not arrive within --timeout.
    """
    from kinema.transport import to_yaml

    wanted = 1 if once else count
    with _node(connect, timeout) as node:
        name = node.resolve(topic_name)
        type_name = msg_type or _discover_type(node, name, "topic", lambda g: g.topics(hidden=True), timeout)
        received = 0
        done = threading.Event()
        lock = threading.Lock()

        def show(message: Any) -> None:
            nonlocal received
            with lock:
                if done.is_set():
                    return
                text = to_yaml(message, flow=flow)
                try:
                    click.echo(text if flow else f"{text}---")
                except BrokenPipeError:  # the reader went away (`| head`): stop like ros2 does
                    closed.set()
                    done.set()
                    return
                received += 1
                if wanted and received >= wanted:
                    done.set()

        closed = threading.Event()
        node.create_subscription(type_name, name, show, latched=latched)
        if wanted:
            if not done.wait(timeout):
                raise TransportError(
                    f"received {received} of {wanted} messages on {name} within {timeout:g} s"
                )
        else:
            while not done.wait(0.2):  # short waits so Ctrl-C is handled promptly
                pass
    if closed.is_set():
        # Python would report the closed stdout again when it flushes at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


@topic.command("pub")
@click.argument("topic_name")
@click.argument("msg_type")
@click.argument("values", required=False, default="")
@click.option("-r", "--rate", type=float, default=1.0, show_default=True, help="Publishing rate in Hz.")
@click.option("-1", "--once", is_flag=True, help="Publish one message and exit.")
@click.option(
    "-t", "--times", type=int, default=0, help="Publish this many messages and exit (0: until Ctrl-C)."
)
@click.option(
    "--latched", is_flag=True, help="Latched publisher (transient local): late subscribers get the last one."
)
@click.option(
    "-w",
    "--wait-matching",
    type=int,
    default=0,
    help="Wait until this many subscriptions match before publishing.",
)
@_common(5.0)
def topic_pub(
    topic_name: str,
    msg_type: str,
    values: str,
    rate: float,
    once: bool,
    times: int,
    latched: bool,
    wait_matching: int,
    connect: str | None,
    timeout: float,
) -> None:
    """Publish MSG_TYPE messages on TOPIC_NAME, with VALUES in YAML flow syntax like "{data: hello}"."""
    from kinema.transport import parse_yaml_flow, to_yaml

    count = 1 if once else times
    if rate <= 0:
        raise click.BadParameter("must be positive", param_hint="--rate")
    with _node(connect, timeout) as node:
        publisher = node.create_publisher(msg_type, topic_name, latched=latched)
        message = parse_yaml_flow(publisher.type_name, values)
        name = publisher.name
        cache = node.session.graph_cache()
        if wait_matching and not cache.wait_for(
            lambda g: len(g.subscriptions(name)) >= wait_matching, timeout
        ):
            raise TransportError(f"fewer than {wait_matching} subscriptions on {name} after {timeout:g} s")
        if count:
            # Give subscriptions already on the graph a moment to see this new publisher.
            cache.wait_for(lambda g: bool(g.subscriptions(name)), min(timeout, 0.5))
        click.echo(f"publisher: beginning loop\npublishing #1: {to_yaml(message, flow=True)}")
        sent = 0
        period = 1.0 / rate
        next_time = time.monotonic()
        while True:
            publisher.publish(message)
            sent += 1
            if count and sent >= count:
                break
            if sent > 1:
                click.echo(f"publishing #{sent}: {to_yaml(message, flow=True)}")
            next_time += period
            time.sleep(max(0.0, next_time - time.monotonic()))
        # Let the last message leave before the session closes.
        time.sleep(0.05)


@topic.command("hz")
@click.argument("topic_name")
@click.argument("msg_type", required=False)
@click.option(
    "-w", "--window", type=int, default=10000, show_default=True, help="Messages in the rolling window."
)
@click.option(
    "-d", "--duration", type=float, default=0.0, help="Stop after this many seconds (0: until Ctrl-C)."
)
@_common(5.0)
def topic_hz(
    topic_name: str, msg_type: str | None, window: int, duration: float, connect: str | None, timeout: float
) -> None:
    """Print the publishing rate of TOPIC_NAME once a second."""
    import statistics

    with _node(connect, timeout) as node:
        name = node.resolve(topic_name)
        type_name = msg_type or _discover_type(node, name, "topic", lambda g: g.topics(hidden=True), timeout)
        stamps: deque[float] = deque(maxlen=max(window, 2))
        lock = threading.Lock()

        def on_message(_payload: Any) -> None:
            with lock:
                stamps.append(time.monotonic())

        node.create_subscription(type_name, name, on_message, raw=True)
        end = time.monotonic() + duration if duration > 0 else math.inf
        reported = False
        while time.monotonic() < end:
            time.sleep(min(1.0, max(0.0, end - time.monotonic())))
            with lock:
                times = list(stamps)
            if len(times) < 2:
                continue
            gaps = [b - a for a, b in itertools.pairwise(times)]
            mean = statistics.fmean(gaps)
            click.echo(
                f"average rate: {1.0 / mean:.3f}\n\tmin: {min(gaps):.3f}s max: {max(gaps):.3f}s "
                f"std dev: {statistics.pstdev(gaps):.5f}s window: {len(times)}"
            )
            reported = True
        if not reported:
            raise TransportError(f"fewer than 2 messages on {name} in {duration:g} s")


# -- service -------------------------------------------------------------------------------------


@click.group(cls=VerbGroup)
def service() -> None:
    """Inspect and call services (list, call)."""


@service.command("list")
@click.option("-t", "--show-types", is_flag=True, help="Show each service's type.")
@click.option("-a", "--include-hidden", is_flag=True, help="Include action internals (…/_action/…).")
@click.option("--json", "as_json", is_flag=True, help="Print {service: [types]} as JSON.")
@click.option("-v", "--verbose", is_flag=True, help="One line per server/client with node and type hash.")
@_common(2.0)
def service_list(
    show_types: bool, include_hidden: bool, as_json: bool, verbose: bool, connect: str | None, timeout: float
) -> None:
    """List the services that have a server or a client."""
    with _node(connect, timeout) as node:
        graph = _graph(node, timeout)
    if verbose:
        _print_endpoints(graph, ("SS", "SC"), include_hidden)
        return
    _print_names(graph.services(hidden=include_hidden), show_types, as_json)


@service.command("call")
@click.argument("service_name")
@click.argument("srv_type", required=False)
@click.argument("values", required=False, default="")
@click.option("--flow", is_flag=True, help="Print the response on one line (YAML flow style).")
@_common(5.0)
def service_call(
    service_name: str, srv_type: str | None, values: str, flow: bool, connect: str | None, timeout: float
) -> None:
    """Call SERVICE_NAME with VALUES in YAML flow syntax like "{a: 1, b: 2}"; print the response.

    SRV_TYPE (pkg/srv/Name) may be omitted when a server is on the graph.
    """
    from kinema.transport import parse_yaml_flow, to_yaml

    if srv_type and not values and (srv_type.lstrip().startswith("{") or ":" in srv_type):
        # `kinema service call /name "{a: 1}"`: the type was left out
        values, srv_type = srv_type, None
    with _node(connect, timeout) as node:
        name = node.resolve(service_name)
        type_name = srv_type or _discover_type(
            node, name, "service", lambda g: g.services(hidden=True), timeout
        )
        client = node.create_client(type_name, name)
        request = parse_yaml_flow(client.service.request, values)
        click.echo(f"requester: making request: {to_yaml(request, flow=True)}\n")
        response = client.call(request, timeout=timeout)
    click.echo("response:")
    click.echo(to_yaml(response, flow=flow).rstrip())


# -- action --------------------------------------------------------------------------------------


@click.group(cls=VerbGroup)
def action() -> None:
    """Inspect actions and send goals (list, send_goal)."""


@action.command("list")
@click.option("-t", "--show-types", is_flag=True, help="Show each action's type.")
@click.option("--json", "as_json", is_flag=True, help="Print {action: [types]} as JSON.")
@_common(2.0)
def action_list(show_types: bool, as_json: bool, connect: str | None, timeout: float) -> None:
    """List the actions that have a server or a client."""
    with _node(connect, timeout) as node:
        actions = _graph(node, timeout).actions()
    _print_names(actions, show_types, as_json)


@action.command("send_goal")
@click.argument("action_name")
@click.argument("action_type")
@click.argument("goal", required=False, default="")
@click.option("-f", "--feedback", is_flag=True, help="Print the feedback messages.")
@click.option(
    "--result-timeout", type=float, default=0.0, help="Seconds to wait for the result (0: until it arrives)."
)
@_common(5.0)
def action_send_goal(
    action_name: str,
    action_type: str,
    goal: str,
    feedback: bool,
    result_timeout: float,
    connect: str | None,
    timeout: float,
) -> None:
    """Send GOAL (YAML flow) to ACTION_NAME of ACTION_TYPE and wait for the result.

    Exits 0 only when the goal SUCCEEDED; Ctrl-C cancels the goal.
    """
    from kinema.transport import STATUS_SUCCEEDED, parse_yaml_flow, to_yaml

    with _node(connect, timeout) as node:
        client = node.create_action_client(action_type, action_name)
        goal_msg = parse_yaml_flow(client.action.goal, goal)
        click.echo("Waiting for an action server to become available...")
        if not client.wait_for_server(timeout):
            raise TransportError(f"no action server {client.name} [{client.type_name}] within {timeout:g} s")
        click.echo(f"Sending goal:\n{_indent(to_yaml(goal_msg))}")

        def on_feedback(message: Any) -> None:
            click.echo(f"Feedback:\n{_indent(to_yaml(message))}")

        handle = client.send_goal(goal_msg, on_feedback if feedback else None, timeout=timeout)
        if not handle.accepted:
            raise TransportError(f"goal rejected by {client.name}")
        click.echo(f"Goal accepted with ID: {handle.goal_uuid.hex}\n")
        try:
            outcome = handle.result(result_timeout or None)
        except KeyboardInterrupt:
            click.echo("Canceling goal...", err=True)
            handle.cancel(timeout)
            raise
    click.echo(f"Result:\n{_indent(to_yaml(outcome.result))}")
    click.echo(f"Goal finished with status: {outcome.status_name}")
    if outcome.status != STATUS_SUCCEEDED:
        raise click.exceptions.Exit(1)


def _indent(text: str) -> str:
    return "\n".join(f"    {line}" for line in text.rstrip().splitlines())


# -- node ----------------------------------------------------------------------------------------


@click.group(cls=VerbGroup)
def node() -> None:
    """Inspect the nodes on the network (list)."""


@node.command("list")
@click.option("-a", "--all", "show_all", is_flag=True, help="Include hidden nodes (names starting with '_').")
@click.option("--json", "as_json", is_flag=True, help="Print the names as a JSON list.")
@_common(2.0)
def node_list(show_all: bool, as_json: bool, connect: str | None, timeout: float) -> None:
    """List the nodes on the network."""
    import json

    with _node(connect, timeout) as cli_node:
        names = _graph(cli_node, timeout).nodes()
    names = [n for n in names if show_all or not n.rsplit("/", 1)[-1].startswith("_")]
    if as_json:
        click.echo(json.dumps(names))
    else:
        for name in names:
            click.echo(name)


def _wait_forever() -> None:
    # Sleep in short steps so Ctrl-C is handled promptly on every platform.
    while True:
        time.sleep(0.2)
