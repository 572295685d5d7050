"""``kinema shell``: a Python REPL with a connected ObjectiveClient named ``client``."""

from __future__ import annotations

import click

from kinema.cli.objective import connect_option, timeout_option

BANNER = """Kinema shell: `client` is a connected kinema.sdk.ObjectiveClient.
  client.execute("Close Gripper")               run an objective and wait for its result
  h = client.start("3 Waypoints Pick and Place") start one (it loops until cancelled) ...
  h.cancel(); h.result()                        ... then cancel it
  client.status(), client.objectives()          what the runtime is doing, what it can run
  for s in client.statuses(timeout=2): ...      the heartbeat (also client.blackboard(), client.logs())
Ctrl-D leaves."""


@click.command()
@connect_option
@timeout_option
@click.option("--plain", is_flag=True, help="Use the standard Python REPL even when IPython is installed.")
def shell(connect: str | None, timeout: float, plain: bool) -> None:
    """Open a Python REPL connected to the running Kinema (`client` is an ObjectiveClient)."""
    import kinema.sdk as sdk
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(connect, timeout=timeout) as client:
        client.wait_for_runtime()
        namespace = {"client": client, "sdk": sdk, "ObjectiveClient": ObjectiveClient}
        if not plain:
            try:
                from IPython import start_ipython
            except ImportError:
                pass
            else:
                click.echo(BANNER)
                start_ipython(argv=["--no-banner"], user_ns=namespace)
                return
        import code

        code.interact(banner=BANNER, local=namespace, exitmsg="")
