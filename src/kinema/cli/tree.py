"""``kinema tree``: run, validate and describe BehaviorTree.CPP v4 objective files."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from kinema.cli.groups import VerbGroup
from kinema.cli.options import selection_options

if TYPE_CHECKING:
    from kinema.bt import BehaviorTreeFactory, NodeStatus, TreeNode
    from kinema.config import ResolvedConfig

_COLORS = {"SUCCESS": "green", "FAILURE": "red", "RUNNING": "yellow", "SKIPPED": "blue", "IDLE": "cyan"}


def _styled(status: NodeStatus, color: bool) -> str:
    return click.style(status.name, fg=_COLORS[status.name]) if color else status.name


behaviors_option = click.option(
    "--behaviors",
    is_flag=True,
    help="Also register the bundled behavior plugins (core, mujoco, examples), offline: no robot.",
)


def _factory(with_behaviors: bool) -> BehaviorTreeFactory:
    """The built-in nodes, plus the bundled behaviors when asked (their load errors are printed)."""
    from kinema.bt import BehaviorTreeFactory

    if not with_behaviors:
        return BehaviorTreeFactory()
    from kinema.plugins.discovery import bundled_plugins
    from kinema.plugins.host import BehaviorHost

    specs = bundled_plugins()
    host = BehaviorHost([spec.name for spec in specs])
    report = host.load_specs(specs)
    for error in report.errors:
        click.echo(f"warning: {error}", err=True)
    return host.registry.create_factory()


@click.group(cls=VerbGroup)
def tree() -> None:
    """Run, validate and describe behavior-tree objectives (BT.CPP v4 XML)."""


@tree.command()
@click.argument("file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("-t", "--tree", "tree_id", metavar="ID", help="Tree to run (default: the file's main tree).")
@click.option(
    "-r", "--rate", type=click.FloatRange(min=0.1), default=100.0, show_default=True, help="Tick rate in Hz."
)
@click.option("--timeout", type=click.FloatRange(min=0.0), help="Halt the tree after this many seconds.")
@click.option("-q", "--quiet", is_flag=True, help="Print only the final status, not every status change.")
@click.option("-b", "--blackboard", "show_blackboard", is_flag=True, help="Print the blackboard at the end.")
@behaviors_option
def run(
    file: Path,
    tree_id: str | None,
    rate: float,
    timeout: float | None,
    quiet: bool,
    show_blackboard: bool,
    behaviors: bool,
) -> None:
    """Tick the objective in FILE until it finishes; print status changes and the final status.

    Uses the built-in nodes (and the bundled behaviors with --behaviors). Exits 0 only if the tree
    ends in SUCCESS; Ctrl-C halts the tree.
    """
    from kinema.bt import NodeStatus

    factory = _factory(behaviors)
    if tree_id is None:
        behavior_tree = factory.create_tree_from_file(file)
    else:
        factory.register_behavior_tree_from_file(file)
        behavior_tree = factory.create_tree(tree_id)
    clock = factory.clock
    start = clock.now()
    color = sys.stdout.isatty()

    def on_change(timestamp: float, node: TreeNode, prev: NodeStatus, new: NodeStatus) -> None:
        click.echo(
            f"[{timestamp - start:8.3f}] {node.full_path:<32} {_styled(prev, color)} -> {_styled(new, color)}"
        )

    if not quiet:
        behavior_tree.add_status_observer(on_change)
    period = 1.0 / rate
    status = NodeStatus.IDLE
    try:
        status = behavior_tree.tick_once()
        while status is NodeStatus.RUNNING:
            if timeout is not None and clock.now() - start >= timeout:
                behavior_tree.halt_tree()
                click.echo(f"timeout: halted after {timeout:g} s", err=True)
                break
            behavior_tree.sleep(period)
            status = behavior_tree.tick_once()
    except KeyboardInterrupt:
        behavior_tree.halt_tree()
        click.echo("interrupted: tree halted", err=True)
        sys.exit(130)
    if show_blackboard:
        for scope, values in behavior_tree.blackboard_snapshot().items():
            for key, (type_name, value) in sorted(values.items()):
                click.echo(f"  {scope}: {key} ({type_name}) = {value!r}")
    click.echo(f"final status: {_styled(status, color)}")
    if status is not NodeStatus.SUCCESS:
        sys.exit(1)


@tree.command()
@click.argument(
    "files", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path)
)
@click.option("--json", "as_json", is_flag=True, help="Print the problems as a JSON list.")
@behaviors_option
@click.option(
    "--no-config",
    is_flag=True,
    help="Inside a workspace too, check against the built-in nodes only (plus --behaviors).",
)
@selection_options
def validate(
    files: tuple[Path, ...],
    as_json: bool,
    behaviors: bool,
    no_config: bool,
    workspace: Path | None,
    config: str | None,
) -> None:
    """Check objective FILES together: node IDs, ports, scripts, subtrees.

    Inside a workspace (FILES under its src/, or one chosen with -w, $KINEMA_WORKSPACE or `kinema
    configure`), or with -c, the files are checked against the active config's behaviors and the
    subtrees of its objective libraries, as `kinema build` and the runtime load them, and a waypoint the
    files name that the config has not saved is a warning. Elsewhere, or with --no-config, against the
    built-in nodes (and the bundled behaviors with --behaviors).

    Every problem is printed as file:line: message. A SubTree may call a tree defined in another of
    the FILES. A node written in a former spelling (MoveIt Pro's CreateStampedPose, say) is checked as
    today's and named in a warning on stderr. Exits 1 if any problem was found.
    """
    import json

    from kinema.bt.validation import Problem, count_trees, validate_files
    from kinema.cli.options import print_warnings

    chosen = None if no_config else _config_factory(files, workspace, config)
    built_in_only = chosen is None and not behaviors
    factory = chosen[0] if chosen is not None else _factory(behaviors)
    spelled: list[Problem] = []
    problems = validate_files(list(files), factory, warnings=spelled)
    print_warnings(str(note) for note in spelled)
    if chosen is not None:
        from kinema.config.waypoint_uses import config_waypoint_warnings

        print_warnings(config_waypoint_warnings(files, chosen[1]))
    if built_in_only and any("Node not recognized" in p.message for p in problems):
        click.echo(
            "note: only the built-in nodes were known; -c NAME (or a file inside a workspace) checks "
            "against a config's behaviors and subtrees, --behaviors adds the bundled behaviors",
            err=True,
        )
    if as_json:
        rows: list[dict[str, Any]] = [
            {"file": p.location.file, "line": p.location.line, "message": p.message} for p in problems
        ]
        click.echo(json.dumps(rows, indent=2))
    else:
        for problem in problems:
            click.echo(str(problem))
        bad = {p.location.file for p in problems}
        for file in files:
            if str(file) not in bad:
                click.echo(f"{file}: OK ({count_trees(file)} trees)")
    if problems:
        sys.exit(1)


def _config_factory(
    files: tuple[Path, ...], workspace: Path | None, config: str | None
) -> tuple[BehaviorTreeFactory, ResolvedConfig] | None:
    """The active config's behaviors and library subtrees in one factory, and the config, when a workspace
    or a config is chosen (see ``validate``); None otherwise. Says on stderr which config it is."""
    from kinema.bt.xmlsource import parse_xml_file
    from kinema.config import ObjectiveLibrary, Workspace, active_selection, resolve_config
    from kinema.config.workspace import find_workspace_root
    from kinema.errors import ConfigError, KinemaError
    from kinema.plugins import BehaviorHost

    selection = active_selection(workspace, config)
    root = selection.workspace
    if root is None:
        for file in files:
            try:
                root = find_workspace_root(file.parent)
                break
            except ConfigError:
                continue
    if root is None and selection.config_source not in ("flag", "environment", "stored"):
        return None
    found = Workspace.discover(root) if root is not None else Workspace.bundled_only()
    name = selection.require_config()
    resolved = resolve_config(name, found)
    library = ObjectiveLibrary.load(resolved)
    host = BehaviorHost.for_config(resolved)
    for error in host.load().errors:
        click.echo(f"warning: {error}", err=True)
    factory = host.registry.create_factory()

    def tree_ids(path: Path) -> set[str]:
        try:
            return {str(node.get("ID")) for node in parse_xml_file(path).iter("BehaviorTree")}
        except KinemaError:
            return set()

    own_files = {file.resolve() for file in files}
    own_ids = set().union(*(tree_ids(file) for file in files))
    for path in library.files():
        # The files being checked stand for themselves: a library file that is one of them, or defines
        # one of their trees (an edited copy), is left out.
        if path.resolve() in own_files or tree_ids(path) & own_ids:
            continue
        try:
            factory.register_behavior_tree_from_file(path)
        except KinemaError:
            pass  # `kinema build` and `kinema objective list` report the library's own problems
    # Where the config package is: a workspace's, or Kinema's own (lab_sim stays bundled in a workspace).
    origin = getattr(resolved.package, "origin", "")
    where = f" (workspace {found.root})" if found.root is not None and origin != "bundled" else ""
    where = " (bundled with Kinema)" if origin == "bundled" else where
    click.echo(
        f"checking against config {name}{where}: its behaviors and objective libraries (--no-config: "
        "built-in nodes only)",
        err=True,
    )
    return factory, resolved


@tree.command()
@click.option("--builtin", is_flag=True, help="Include the built-in nodes (Sequence, Retry, ...).")
@behaviors_option
def nodes(builtin: bool, behaviors: bool) -> None:
    """Print the TreeNodesModel XML (Groot2 format) of the registered node types."""
    from kinema.bt import write_tree_nodes_model_xml

    click.echo(write_tree_nodes_model_xml(_factory(behaviors), include_builtin=builtin), nl=False)
