"""Entry point of the ``kinema`` command.

Verb modules are imported only when their verb runs (or when ``--help`` needs their one-line summary),
so ``kinema --help`` stays fast and never imports mujoco, pinocchio, zenoh or textual.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys

import click

from kinema import __version__
from kinema.cli.groups import VerbGroup
from kinema.errors import KinemaError

# verb -> "module:attribute". A verb is offered only when its module exists, so `kinema --help`
# lists exactly what this installation can do.
VERBS: dict[str, str] = {
    "run": "kinema.cli.run:run",
    "down": "kinema.cli.run:down",
    "security": "kinema.cli.security:security",
    "ui": "kinema.cli.ui:ui",
    "view": "kinema.cli.view:view",
    "configure": "kinema.cli.workspace:configure",
    "init": "kinema.cli.workspace:init",
    "config": "kinema.cli.config:config",
    "objective": "kinema.cli.objective:objective",
    "tree": "kinema.cli.tree:tree",
    "new": "kinema.cli.new:new",
    "build": "kinema.cli.build:build",
    "test": "kinema.cli.build:test",
    "plugins": "kinema.cli.plugins:plugins",
    "behaviors": "kinema.cli.plugins:behaviors",
    "topic": "kinema.cli.ros:topic",
    "service": "kinema.cli.ros:service",
    "action": "kinema.cli.ros:action",
    "node": "kinema.cli.ros:node",
    "logs": "kinema.cli.logs:logs",
    "export-logs": "kinema.cli.logs:export_logs",
    "shell": "kinema.cli.shell:shell",
    "example": "kinema.cli.example:example",
    "sim": "kinema.cli.sim:sim",
    "waypoint": "kinema.cli.waypoint:waypoint",
}


def _module_exists(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except ModuleNotFoundError:
        return False


class LazyGroup(VerbGroup):
    """A click group whose subcommands are imported on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return [verb for verb, target in VERBS.items() if _module_exists(target.split(":")[0])]

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        target = VERBS.get(cmd_name)
        if target is None:
            return None
        module_name, attribute = target.split(":")
        if not _module_exists(module_name):
            return None
        module = importlib.import_module(module_name)
        command = getattr(module, attribute)
        assert isinstance(command, click.Command), f"{target} is not a click command"
        return command

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = []
        for verb in self.list_commands(ctx):
            command = self.get_command(ctx, verb)
            if command is not None and not command.hidden:
                rows.append((verb, command.get_short_help_str(limit=200)))
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(
    cls=LazyGroup,
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 110},
)
@click.version_option(__version__, "-V", "--version", prog_name="kinema")
def cli() -> None:
    """Kinema: run BehaviorTree.CPP v4 objectives on a simulated or real robot.

    Every verb has its own --help, e.g. `kinema tree run --help`.
    """


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; handled errors print one line on stderr and exit 1, never a traceback."""
    try:
        # Outside standalone mode click returns (rather than raises) the code of `raise Exit(code)`.
        result = cli.main(args=argv, prog_name="kinema", standalone_mode=False)
        if isinstance(result, int) and not isinstance(result, bool):
            return result
    except click.exceptions.Abort:
        click.echo("Aborted.", err=True)
        return 130
    except click.exceptions.Exit as exit_:
        return exit_.exit_code
    except click.ClickException as error:
        error.show()
        return error.exit_code
    except KinemaError as error:
        click.secho(f"error: {error}", err=True, fg="red")
        return 1
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
