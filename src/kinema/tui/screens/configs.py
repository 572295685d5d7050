"""Configs: the workspace's config packages; the selected one's inheritance chain, resolved config, files."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Label, OptionList, Static, TabbedContent, TabPane, Tree
from textual.widgets.option_list import Option

from kinema.errors import KinemaError
from kinema.tui.config_view import ConfigRow, config_rows, package_files
from kinema.tui.screens.base import KinemaScreen
from kinema.tui.widgets.fitted_table import Column, FittedTable

if TYPE_CHECKING:
    from kinema.config import Package, ResolvedConfig, Workspace


@dataclass
class ConfigDetails:
    """Everything shown about one config package (computed on a worker thread)."""

    name: str
    resolved: ResolvedConfig | None
    rows: list[ConfigRow]
    files: list[str]
    files_cut: bool
    error: str = ""
    folder: Path | None = None


class WorkspaceLoaded(Message):
    """The workspace was scanned."""

    def __init__(self, workspace: Workspace | None, error: str = "") -> None:
        super().__init__()
        self.workspace = workspace
        self.error = error


class ConfigLoaded(Message):
    """A config package was resolved."""

    def __init__(self, details: ConfigDetails) -> None:
        super().__init__()
        self.details = details


class FileOpened(Message):
    """A file of a package was read to be shown."""

    def __init__(self, path: Path, text: str) -> None:
        super().__init__()
        self.path = path
        self.text = text


#: A file larger than this shows only its start (the Files tab is for reading a config, not logs).
MAX_SHOWN_BYTES = 256 * 1024


def read_shown_file(path: Path) -> str:
    """The text of ``path`` to show (its start when large; binary files say so)."""
    with path.open("rb") as handle:
        data = handle.read(MAX_SHOWN_BYTES + 1)
    if b"\0" in data[:4096]:
        return f"({path.name} is a binary file: {path.stat().st_size} bytes)"
    text = data[:MAX_SHOWN_BYTES].decode("utf-8", errors="replace")
    if len(data) > MAX_SHOWN_BYTES:
        text += f"\n… (only the first {MAX_SHOWN_BYTES // 1024} kB are shown)"
    return text


class ConfigsScreen(KinemaScreen):
    """Browse config packages: chain, resolved values with provenance, files."""

    MODE = "configs"
    AUTO_FOCUS = "#config-list"
    BINDINGS = [
        Binding("f5", "reload", "Rescan", id="configs.reload", tooltip="Scan the workspace again"),
        Binding("c", "tab('chain')", "Chain", id="configs.chain", tooltip="The inheritance chain"),
        Binding("v", "tab('resolved')", "Resolved", id="configs.resolved", tooltip="Merged config values"),
        Binding("i", "tab('files')", "Files", id="configs.files", tooltip="The package's files"),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.workspace: Workspace | None = None
        self.details: ConfigDetails | None = None

    def compose_body(self) -> ComposeResult:
        with Horizontal(classes="split"):
            with Vertical(classes="sidebar"):
                yield Label("Config packages", classes="pane-title")
                yield OptionList(id="config-list")
                yield Static("", id="workspace-info", classes="muted")
            with Vertical(classes="main"):
                yield Static("", id="config-title", classes="pane-title")
                with TabbedContent(initial="chain", id="config-tabs"):
                    with TabPane("Chain", id="chain"):
                        yield Tree("inheritance", id="chain-tree")
                    with TabPane("Resolved config", id="resolved"):
                        yield FittedTable(
                            (
                                Column("key", "Key", min_width=14, weight=1),
                                Column("value", "Value", min_width=16, weight=3),
                                Column("package", "Set by", min_width=14, weight=0),
                            ),
                            id="resolved-table",
                        )
                    with TabPane("Files", id="files"):
                        yield Tree("files", id="file-tree")

    def on_mount(self) -> None:
        super().on_mount()
        self.action_reload()

    def action_reload(self) -> None:
        """Scan the workspace (on a worker thread: it touches the file system)."""
        self.call_runtime(
            "Scan the workspace", self.kinema.connection.workspace, lambda ws: WorkspaceLoaded(ws)
        )

    def action_tab(self, tab: str) -> None:
        self.query_one(TabbedContent).active = tab

    def on_tree_node_selected(self, event: Tree.NodeSelected[object]) -> None:
        """Enter (or a click) on a file of the Files tab opens it, read-only."""
        details = self.details
        relative = event.node.data
        if event.control.id != "file-tree" or not isinstance(relative, str) or details is None:
            return
        if details.folder is None:
            return
        path = details.folder / relative
        self.call_runtime(
            f"Open {relative}", lambda: read_shown_file(path), lambda text: FileOpened(path, text)
        )

    def on_file_opened(self, message: FileOpened) -> None:
        from kinema.tui.dialogs.file_view import FileViewDialog

        self.app.push_screen(FileViewDialog(message.path, message.text))

    def on_workspace_loaded(self, message: WorkspaceLoaded) -> None:
        self.workspace = message.workspace
        options = self.query_one("#config-list", OptionList)
        options.clear_options()
        if message.workspace is None:
            return
        packages = message.workspace.config_packages()
        preferred = self.kinema.connection.config_name
        for package in packages:
            options.add_option(Option(_package_label(package, package.name == preferred), id=package.name))
        info = message.workspace.describe()
        self.query_one("#workspace-info", Static).update(Text(f"{len(packages)} config packages in {info}"))
        names = [p.name for p in packages]
        if names:
            index = names.index(preferred) if preferred in names else 0
            options.highlighted = index
            self._load(names[index])

    def on_option_list_option_highlighted(self, event: OptionList.OptionHighlighted) -> None:
        if event.option.id and (self.details is None or self.details.name != event.option.id):
            self._load(event.option.id)

    def _load(self, name: str) -> None:
        workspace = self.workspace
        if workspace is None:
            return
        self.query_one("#config-title", Static).update(Text(f"{name} …", style="bold"))
        self.call_runtime(f"Resolve config {name!r}", lambda: _details(name, workspace), ConfigLoaded)

    def on_config_loaded(self, message: ConfigLoaded) -> None:
        details = message.details
        self.details = details
        title = Text(details.name, style="bold")
        if details.error:
            title.append(f"  {details.error}", style="red")
        self.query_one("#config-title", Static).update(title)
        self._show_chain(details)
        self.query_one("#resolved-table", FittedTable).set_rows(
            [
                (
                    Text(row.key),
                    Text(row.value),
                    Text(row.package, style="bold" if row.package == details.name else "dim"),
                )
                for row in details.rows
            ]
        )
        self._show_files(details)

    def _show_chain(self, details: ConfigDetails) -> None:
        tree = self.query_one("#chain-tree", Tree)
        tree.clear()
        resolved = details.resolved
        if resolved is None:
            tree.root.set_label(Text(details.error or "not resolved", style="red"))
            return
        tree.root.set_label(Text("based_on_package chain (root first)", style="dim"))
        node = tree.root
        for name in resolved.chain:
            package = resolved.workspace.package(name)
            label = Text(name, style="bold" if name == details.name else "")
            label.append(f"  {_where(package, resolved.workspace)}", style="dim")
            node = node.add(label, expand=True)
        node.allow_expand = False
        tree.root.expand_all()

    def _show_files(self, details: ConfigDetails) -> None:
        tree = self.query_one("#file-tree", Tree)
        tree.clear()
        tree.root.set_label(Text(f"{details.name}/"))
        folders: dict[str, object] = {"": tree.root}
        for path in details.files:
            parent_key = ""
            parent = tree.root
            parts = path.split("/")
            for part in parts[:-1]:
                parent_key = f"{parent_key}/{part}"
                if parent_key not in folders:
                    folders[parent_key] = parent.add(Text(f"{part}/"), expand=parent is tree.root)
                parent = folders[parent_key]  # type: ignore[assignment]
            parent.add_leaf(Text(parts[-1]), data=path)
        if details.files_cut:
            tree.root.add_leaf(Text(f"… (only the first {len(details.files)} files are listed)", style="dim"))
        tree.root.expand()


def _where(package: Package, workspace: Workspace) -> str:
    """Where a package lives: ``bundled``, or its folder relative to the workspace."""
    if package.origin == "bundled" or workspace.root is None:
        return package.origin
    try:
        return f"workspace: {package.path.relative_to(workspace.root)}"
    except ValueError:
        return f"workspace: {package.path}"


def _package_label(package: Package, active: bool) -> Text:
    """The package's name, marked ``*`` when it is the config this UI shows (as `kinema config list`)."""
    label = Text("* " if active else "  ", style="bold green")
    label.append(package.name)
    if package.origin == "bundled":
        label.append("  bundled", style="dim")
    return label


def _details(name: str, workspace: Workspace) -> ConfigDetails:
    from kinema.config import resolve_config  # after the first frame: it is not needed to draw it

    package = workspace.package(name)
    files, cut = package_files(package.path)
    try:
        resolved = resolve_config(name, workspace, check_files=False)
    except KinemaError as error:  # a broken config is shown with its file:line, next to its files
        return ConfigDetails(name, None, [], files, cut, str(error), package.path)
    return ConfigDetails(name, resolved, config_rows(resolved), files, cut, folder=package.path)
