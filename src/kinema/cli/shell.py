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
    """Open a Python REPL connected to the running Kinema (`client` is an ObjectiveClient).

    Code piped in (`echo 'print(client.status())' | kinema shell`) runs as a script: no banner, no
    prompts, and a traceback with exit code 1 when it raises.
    """
    import sys

    import kinema.sdk as sdk
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(connect, timeout=timeout) as client:
        client.wait_for_runtime()
        namespace = {"client": client, "sdk": sdk, "ObjectiveClient": ObjectiveClient}
        if not sys.stdin.isatty():
            _run_script(sys.stdin.read(), namespace)
            return
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


def _run_script(source: str, namespace: dict[str, object]) -> None:
    """Run piped-in code in the shell's namespace, as `python -` would."""
    import traceback

    try:
        exec(compile(source, "<stdin>", "exec"), namespace)  # the user's own code, as at the prompt
    except SystemExit:
        raise
    except BaseException as error:
        # From the piped code's own frames on, as Python prints a script's error.
        inner = error.__traceback__.tb_next if error.__traceback__ is not None else None
        traceback.print_exception(error.with_traceback(inner))
        raise click.exceptions.Exit(1) from None
