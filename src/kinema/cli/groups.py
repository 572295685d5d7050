"""The click group every ``kinema`` verb group uses: a mistyped subcommand gets the closest names."""

from __future__ import annotations

import click


class VerbGroup(click.Group):
    """A group that answers an unknown subcommand with ``did you mean ...? Valid: ...``."""

    def resolve_command(
        self, ctx: click.Context, args: list[str]
    ) -> tuple[str | None, click.Command | None, list[str]]:
        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            from kinema.errors import did_you_mean

            ctx.fail(f"No such command {name!r}; {did_you_mean(name, self.list_commands(ctx))}")
        return super().resolve_command(ctx, args)
