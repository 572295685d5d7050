"""Round-trip latency of a raw zenoh query and of a Kinema service call (AddTwoInts), same machine.

A server process hosts the router, a raw zenoh queryable and a Kinema ``/add_two_ints`` service; this
process joins it as a peer and times, one after the other:

* the raw zenoh query round trip (``session.get`` on a complete queryable, 64-byte payload): the floor;
* a Kinema service call (CDR request/response, rmw_zenoh attachments, reply checking);
* the same Kinema call with server and client in one session (in-process delivery).

It prints p50/p99 per case and the ratio of the Kinema call to the raw query measured in the same run.
Run: ``python benchmarks/transport_rtt.py [--calls N] [--warmup N]``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

from latency import MICROSECOND_NS, percentiles, time_calls

RAW_KEY = "kinema_bench/raw_echo"


def serve(endpoint: str) -> None:
    """Host the router with a raw echo queryable and a Kinema AddTwoInts service until stdin closes."""
    from kinema.transport import Node, host_router

    with host_router(endpoint) as session:
        raw = session.zenoh.declare_queryable(
            RAW_KEY, lambda query: query.reply(query.key_expr, query.payload), complete=True
        )
        Node(session, "bench_server").create_service(
            "example_interfaces/srv/AddTwoInts",
            "/add_two_ints",
            lambda request: {"sum": request.a + request.b},
        )
        print("ready", flush=True)
        sys.stdin.readline()
        raw.undeclare()


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--calls", type=int, default=3000, help="timed calls per case")
    parser.add_argument("--warmup", type=int, default=300, help="untimed calls before each case")
    parser.add_argument("--serve", metavar="ENDPOINT", help=argparse.SUPPRESS)
    parser.add_argument("--smoke", action="store_true", help="few calls per case (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.calls, args.warmup = 50, 10
    if args.serve:
        serve(args.serve)
        return

    import zenoh

    from kinema.transport import Node, free_endpoint, open_session

    endpoint = free_endpoint()
    server = subprocess.Popen(
        [sys.executable, __file__, "--serve", endpoint],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert server.stdout is not None and server.stdin is not None
        if server.stdout.readline().strip() != "ready":
            raise SystemExit("benchmark server did not start")
        with open_session(endpoint) as session:
            node = Node(session, "bench_client")
            payload = bytes(64)

            def raw_query() -> None:
                replies = list(
                    session.zenoh.get(
                        RAW_KEY,
                        payload=payload,
                        target=zenoh.QueryTarget.ALL_COMPLETE,
                        consolidation=zenoh.ConsolidationMode.NONE,
                        timeout=5,
                    )
                )
                assert replies and replies[0].ok is not None

            client = node.create_client("example_interfaces/srv/AddTwoInts", "/add_two_ints")
            request = client.registry.typestore.types[client.service.request](a=2, b=40)
            client.call(request, timeout=5)

            def kinema_call() -> None:
                assert client.call(request, timeout=5).sum == 42

            local = Node(session, "bench_local")
            local.create_service(
                "example_interfaces/srv/AddTwoInts", "/local_add", lambda r: {"sum": r.a + r.b}
            )
            local_client = local.create_client("example_interfaces/srv/AddTwoInts", "/local_add")

            def local_call() -> None:
                assert local_client.call(request, timeout=5).sum == 42

            results = {}
            for name, call in (
                ("raw zenoh query (2 processes)", raw_query),
                ("Kinema AddTwoInts call (2 processes)", kinema_call),
                ("Kinema AddTwoInts call (same session)", local_call),
            ):
                results[name] = percentiles(time_calls(call, args.calls, args.warmup), MICROSECOND_NS)
        server.stdin.write("\n")
        server.stdin.flush()
        server.wait(10)
    finally:
        if server.poll() is None:
            server.kill()

    print(f"{args.calls} calls per case after {args.warmup} warm-up calls")
    for name, (p50, p99) in results.items():
        print(f"  {name:40s} p50 {p50:8.1f} µs   p99 {p99:8.1f} µs")
    raw_p50 = results["raw zenoh query (2 processes)"][0]
    kinema_p50 = results["Kinema AddTwoInts call (2 processes)"][0]
    print(f"  Kinema call / raw query (p50): {kinema_p50 / raw_p50:.2f}x")


if __name__ == "__main__":
    main()
