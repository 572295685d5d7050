"""Objectives: the library with search and filters, an objective's ports, live tree, XML; Run and Cancel.

While PlanMTCTask plans a task, a panel above the tree shows its stages live (state, time, why one failed).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, cast

from rich.table import Table
from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.widgets import (
    Checkbox,
    Input,
    OptionList,
    Select,
    Static,
    TabbedContent,
    TabPane,
)
from textual.widgets.option_list import Option

from kinema.errors import KinemaError
from kinema.tui.connection import (
    ConnectionState,
    NodeStatusBatch,
    ObjectiveSummary,
    RuntimeConnection,
    TaskPlanning,
)
from kinema.tui.messages import ObjectiveOutlineLoaded, ObjectiveRunRequested, ObjectivesLoaded
from kinema.tui.run_outcome import RunOutcome
from kinema.tui.screens.base import LOAD_ATTEMPTS, KinemaScreen
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView
from kinema.tui.widgets.objective_list import ObjectiveList, ObjectiveSearch
from kinema.tui.widgets.task_panel import TaskPanel

# What only a tab or a dialog shows is imported when first shown: not before the first frame.
if TYPE_CHECKING:
    from textual.widgets import TextArea

    from kinema.tui.widgets.fitted_table import FittedTable
    from kinema.tui.widgets.override_form import OverrideForm

ALL = "__all__"


def filter_objectives(
    objectives: list[ObjectiveSummary],
    text: str = "",
    subcategory: str = ALL,
    favorites_only: bool = False,
    runnable_only: bool = False,
) -> list[ObjectiveSummary]:
    """The objectives that pass the search text and filters, favorites first, then by name."""
    needle = text.strip().lower()
    chosen = [
        o
        for o in objectives
        if (not needle or needle in o.name.lower() or needle in o.description.lower())
        and (subcategory == ALL or o.subcategory == subcategory)
        and (not favorites_only or o.favorite)
        and (not runnable_only or o.runnable)
    ]
    return sorted(chosen, key=lambda o: (not o.favorite, o.name.lower()))


class ObjectivesScreen(KinemaScreen):
    """Browse, inspect and run objectives."""

    MODE = "objectives"
    AUTO_FOCUS = "#objective-list"
    # No printable key acts here: letters typed on the list search (ObjectiveList), and running moves the
    # robot, so it is Enter on the highlighted objective or ctrl+r, both naming what will run.
    BINDINGS = [
        # Shown under the list ("Enter or ctrl+r runs ..."); the footer has Enter's "Run".
        Binding(
            "ctrl+r", "run", "Run", id="objectives.run", tooltip="Run the selected objective", show=False
        ),
        Binding("slash", "search", "Search", id="objectives.search", tooltip="Search objectives by name"),
        Binding("f2", "tab('tree')", "Tree", id="objectives.tree", tooltip="The behavior tree"),
        Binding("f3", "tab('xml')", "XML", id="objectives.xml", tooltip="The objective's XML"),
        Binding("f4", "tab('parameters')", "Params", id="objectives.parameters", tooltip="Overrides"),
        Binding(
            "f5", "reload", "Reload", id="objectives.reload", tooltip="List the objectives again", show=False
        ),
        Binding(
            "ctrl+o",
            "show_failure",
            "Failure",
            id="objectives.failure",
            tooltip="The whole message of the last failed or cancelled run",
            show=False,  # shown on the failure box itself, while there is one
        ),
        Binding(
            "escape",
            "dismiss_failure",
            "Dismiss",
            id="objectives.dismiss",
            tooltip="Leave the search box; else hide the failure explanation of the last run",
            show=False,  # the failure panel says so; the footer has no room to spare
        ),
        Binding(
            "ctrl+f",
            "toggle_filter('favorites')",
            "Favorites",
            id="objectives.favorites",
            tooltip="Only favorites",
            show=False,
        ),
        Binding(
            "ctrl+u",
            "toggle_filter('runnable')",
            "Runnable",
            id="objectives.runnable",
            tooltip="Only runnable",
            show=False,
        ),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.objectives: list[ObjectiveSummary] = []
        self.shown_objectives: list[ObjectiveSummary] = []
        self.selected: ObjectiveSummary | None = None
        self.failure_shown: RunOutcome | None = None
        # Outcomes the user hid (Esc): they stay hidden when the objective is selected again.
        self._dismissed: set[int] = set()
        # The selected objective's XML, for the XML tab (whose editor is made when the tab is first shown).
        self._xml = ""
        # F4 asked for the first parameter's field, and the form was not there yet.
        self._focus_form_when_filled = False

    def compose_body(self) -> ComposeResult:
        with Horizontal(classes="split"):
            with Vertical(classes="sidebar"):
                yield ObjectiveSearch(
                    objectives="objective-list",
                    placeholder="type to search objectives",
                    id="objective-search",
                )
                yield Select([], prompt="All subcategories", id="subcategory", allow_blank=True)
                with Horizontal(classes="checks"):
                    yield Checkbox(
                        "Favorites", id="favorites", compact=True, tooltip="Only favorites (ctrl+f)"
                    )
                    yield Checkbox(
                        "Runnable",
                        id="runnable",
                        compact=True,
                        tooltip="Only runnable objectives (ctrl+u); ◦ marks a subtree-only one",
                    )
                yield ObjectiveList(search="objective-search", id="objective-list")
                yield Static("", id="objective-count", classes="muted")
                yield Static("", id="run-hint")
            with Vertical(classes="main"):
                yield Static("", id="objective-title", classes="pane-title")
                yield Static("", id="objective-description")
                yield Static("", id="failure-panel")
                yield TaskPanel("", id="task-panel")
                with TabbedContent(initial="tree", id="objective-tabs"):
                    with TabPane("Tree", id="tree"):
                        yield BehaviorTreeView(id="behavior-tree")
                    # Filled when first shown (_fill_tab): the first frame needs only the tree.
                    yield TabPane("XML", id="xml")
                    yield TabPane("Parameters", id="parameters")
                    yield TabPane("Ports", id="ports")

    def on_mount(self) -> None:
        super().on_mount()
        self.set_focus(self.query_one("#objective-list", OptionList))
        self.query_one(TaskPanel).show_task(self.kinema.task_planning)
        if self.kinema.status.state is ConnectionState.CONNECTED:
            self.action_reload()

    # -- loading -----------------------------------------------------------------------------------

    def action_reload(self) -> None:
        self.call_runtime(
            "List objectives",
            self.kinema.connection.list_objectives,
            ObjectivesLoaded,
            attempts=LOAD_ATTEMPTS,
        )

    def runtime_connected(self) -> None:
        self.action_reload()

    def runtime_objectives_changed(self) -> None:
        self.action_reload()

    def on_objectives_loaded(self, message: ObjectivesLoaded) -> None:
        self.objectives = message.objectives
        subcategories = sorted({o.subcategory for o in self.objectives if o.subcategory})
        select = self.query_one("#subcategory", Select)
        current = select.value
        select.set_options([(name, name) for name in subcategories])
        if current in subcategories:
            select.value = current
        self._refilter()

    def _refilter(self) -> None:
        select = self.query_one("#subcategory", Select)
        subcategory = select.value if isinstance(select.value, str) else ALL
        self.shown_objectives = filter_objectives(
            self.objectives,
            self.query_one("#objective-search", Input).value,
            subcategory,
            self.query_one("#favorites", Checkbox).value,
            self.query_one("#runnable", Checkbox).value,
        )
        options = self.query_one("#objective-list", OptionList)
        options.clear_options()
        for objective in self.shown_objectives:
            options.add_option(Option(_objective_row(objective), id=objective.name))
        self.query_one("#objective-count", Static).update(
            f"{len(self.shown_objectives)} of {len(self.objectives)} objectives"
        )
        names = [o.name for o in self.shown_objectives]
        if self.selected is not None and self.selected.name in names:
            options.highlighted = names.index(self.selected.name)
        elif names:
            options.highlighted = 0

    def on_input_changed(self, event: Input.Changed) -> None:
        if event.input.id == "objective-search":
            self._refilter()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        if event.input.id == "objective-search":
            pass  # the search box gave the list the focus itself (ObjectiveSearch)
        elif (form := self._override_form()) is not None and event.input in form.query(Input):
            # Enter in a parameter runs the objective with the form's values. The keys are the list's
            # again (Enter runs again): the field the run hides must not keep the focus.
            self.set_focus(self.query_one("#objective-list", OptionList))
            self.action_run()

    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        if event.option_list.id == "objective-list":  # Enter on the list (a click only highlights)
            self.action_run()

    def on_select_changed(self, event: Select.Changed) -> None:
        self._refilter()

    def on_checkbox_changed(self, event: Checkbox.Changed) -> None:
        self._refilter()

    def on_option_list_option_highlighted(self, event: OptionList.OptionHighlighted) -> None:
        found = next((o for o in self.shown_objectives if o.name == event.option.id), None)
        if found is not None and found != self.selected:
            self.select_objective(found)

    def select_objective(self, objective: ObjectiveSummary) -> None:
        """Show ``objective``: description, ports, parameter form; load its XML and tree."""
        self.selected = objective
        title = Text(objective.name, style="bold")
        if objective.favorite:
            title.append("  ★", style="yellow")
        if objective.subcategory:
            title.append(f"  {objective.subcategory}", style="dim")
        if not objective.runnable:
            title.append("  (subtree only)", style="dim italic")
        self.query_one("#objective-title", Static).update(title)
        where = _location(objective)
        description = Text(objective.description or "(no description)")
        if where:
            description.append(f"\n{where}", style="dim")
        self.query_one("#objective-description", Static).update(description)
        hint = Text()
        if objective.runnable:
            hint.append("Enter", style="bold")
            hint.append(" or ")
            hint.append("ctrl+r", style="bold")
            hint.append(" runs ")
            hint.append(objective.name, style="bold")
        else:
            hint.append(f"{objective.name} is a subtree: run an objective that uses it", style="dim")
        self.query_one("#run-hint", Static).update(hint)
        self._show_outcome_of_selected()
        for table in self.query("#port-table"):  # the Ports tab's, once it was shown
            cast("FittedTable", table).set_rows(port_rows(objective))
        form = self._override_form()
        if form is not None:
            self.run_worker(form.show_objective(objective), group="override-form")
        self.query_one(BehaviorTreeView).show_outline(None, "loading …")
        connection = self.kinema.connection
        self.call_runtime(
            f"Read objective {objective.name!r}",
            lambda: _load_outline(connection, objective.name),
            lambda loaded: loaded,
        )

    def on_objective_outline_loaded(self, message: ObjectiveOutlineLoaded) -> None:
        if self.selected is None or message.name != self.selected.name:
            return
        self._xml = message.xml
        for area in self.query("#objective-xml"):  # the XML tab's, once it was shown
            cast("TextArea", area).load_text(message.xml)
        view = self.query_one(BehaviorTreeView)
        view.show_outline(message.outline, message.error)
        latest = self.kinema.node_statuses.get(message.name)
        if latest:
            view.apply_statuses(latest.values())
        outcome = self.kinema.outcomes.get(message.name)
        if outcome is not None:
            view.finish_run(outcome.outcome, outcome.message)

    # -- running -----------------------------------------------------------------------------------

    def action_run(self) -> None:
        if self.selected is None:
            self.notify("Select an objective first.", severity="warning")
            return
        if not self.selected.runnable:
            self.app.notify(
                f"{self.selected.name!r} is a subtree only; run an objective that uses it.",
                severity="warning",
            )
            return
        form = self._override_form()
        overrides = form.overrides() if form is not None else {}  # no form shown: nothing typed
        self.post_message(ObjectiveRunRequested(self.selected.name, overrides))

    def run_by_name(self, name: str) -> None:
        """Run objective ``name`` with its defaults (the command palette's "Run ..." commands)."""
        self.post_message(ObjectiveRunRequested(name, {}))

    def on_objective_run_requested(self, message: ObjectiveRunRequested) -> None:
        connection = self.kinema.connection
        self.query_one(TabbedContent).active = "tree"
        self.query_one(BehaviorTreeView).reset_statuses()
        what = f"Run {message.name!r}"
        if message.overrides:
            what += " with " + ", ".join(f"{k}={v}" for k, v in message.overrides.items())
        self.call_runtime(
            what, lambda: connection.start_objective(message.name, message.overrides), announce=True
        )

    def action_cancel(self) -> None:
        self.call_runtime("Cancel the objective", self.kinema.connection.cancel_objective, announce=True)

    def action_search(self) -> None:
        self.set_focus(self.query_one("#objective-search", Input))

    def action_toggle_filter(self, which: str) -> None:
        self.query_one(f"#{which}", Checkbox).toggle()

    def action_tab(self, tab: str) -> None:
        self.query_one(TabbedContent).active = tab
        if tab == "parameters":
            # Typing goes into the form at once: a value's letters are not the screen's keys (x cancels).
            form = self._override_form()
            if form is None:
                self._focus_form_when_filled = True  # the tab is being filled (on_tabbed_content_...)
            else:
                self._focus_first_field(form)

    def _focus_first_field(self, form: OverrideForm) -> None:
        fields = form.query(Input)
        if fields:
            self.set_focus(fields.first())

    def _override_form(self) -> OverrideForm | None:
        """The Parameters tab's form, or None while that tab was never shown."""
        return cast("OverrideForm | None", next(iter(self.query("#override-form")), None))

    async def on_tabbed_content_tab_activated(self, event: TabbedContent.TabActivated) -> None:
        if event.tabbed_content.id == "objective-tabs":
            await self._fill_tab(event.pane)

    async def _fill_tab(self, pane: TabPane) -> None:
        """Make the widgets of a tab shown for the first time, showing the selected objective.

        Only the Tree tab's are made with the screen: the XML editor, the parameter form and the port
        table were a sixth of the widgets of the first frame, and none of them is seen in it.
        """
        if pane.children or pane.id == "tree":
            return
        objective = self.selected
        if pane.id == "xml":
            from textual.widgets import TextArea

            await pane.mount(TextArea(self._xml, language="xml", read_only=True, id="objective-xml"))
        elif pane.id == "parameters":
            from kinema.tui.widgets.override_form import OverrideForm

            form = OverrideForm(id="override-form")
            await pane.mount(form)
            if objective is not None:
                await form.show_objective(objective)
            if self._focus_form_when_filled:
                self._focus_form_when_filled = False
                self._focus_first_field(form)
        elif pane.id == "ports":
            from kinema.tui.widgets.fitted_table import PORT_COLUMNS, FittedTable

            table = FittedTable(PORT_COLUMNS, id="port-table")
            await pane.mount(table)
            if objective is not None:
                table.set_rows(port_rows(objective))

    # -- live status -------------------------------------------------------------------------------

    def runtime_run_started(self, objective_name: str) -> None:
        self.query_one(TaskPanel).show_task(None)
        # The app forgot the last outcome of objective_name: its box goes (another objective's stays).
        self._show_outcome_of_selected()
        if self.selected is not None and self.selected.name == objective_name:
            self.query_one(BehaviorTreeView).reset_statuses()

    def runtime_run_ended(self, outcome: RunOutcome) -> None:
        self._show_outcome_of_selected()
        if self.selected is not None and self.selected.name == outcome.objective_name:
            self.query_one(BehaviorTreeView).finish_run(outcome.outcome, outcome.message)

    def _show_outcome_of_selected(self) -> None:
        """The result box belongs to the selected objective: its last failed or cancelled run, if any."""
        outcome = self.kinema.outcomes.get(self.selected.name) if self.selected is not None else None
        panel = self.query_one("#failure-panel", Static)
        if outcome is None or id(outcome) in self._dismissed:
            panel.set_class(False, "shown")
            self.failure_shown = None
            return
        failed = outcome.outcome == "Failure"
        text = Text()
        text.append("✘ failed" if failed else "◼ cancelled", style="bold red" if failed else "bold yellow")
        text.append("  ctrl+o whole message · Esc hides\n", style="dim")
        from kinema.tui.dialogs.failure import outcome_text

        text.append_text(outcome_text(outcome))
        panel.update(text)
        panel.set_class(True, "shown")
        panel.set_class(not failed, "cancelled")
        self.failure_shown = outcome

    def action_dismiss_failure(self) -> None:
        search = self.query_one("#objective-search", Input)
        if search.has_focus:
            # Esc leaves the search box (its filter stays) for the list, where keys act again.
            self.set_focus(self.query_one("#objective-list", OptionList))
            return
        if self.failure_shown is not None:
            self._dismissed.add(id(self.failure_shown))
        self.query_one("#failure-panel", Static).set_class(False, "shown")
        self.failure_shown = None

    def action_show_failure(self) -> None:
        outcome = self.kinema.outcomes.get(self.selected.name) if self.selected is not None else None
        if outcome is None:
            self.notify("The selected objective has no failed or cancelled run to show.")
            return
        from kinema.tui.dialogs.failure import FailureDialog

        self.app.push_screen(FailureDialog(outcome))

    def runtime_task_planning(self, task: TaskPlanning) -> None:
        self.query_one(TaskPanel).show_task(task)

    def runtime_node_statuses(self, batch: NodeStatusBatch) -> None:
        if self.selected is not None and self.selected.name == batch.objective_name:
            self.query_one(BehaviorTreeView).apply_statuses(batch.updates)


def port_rows(objective: ObjectiveSummary) -> list[tuple[str, str, str, str, str]]:
    """The Ports tab's rows: name, direction, type, default, description."""
    return [(p.name, p.direction, p.type_name, p.default, p.description) for p in objective.ports]


def _load_outline(connection: RuntimeConnection, name: str) -> ObjectiveOutlineLoaded:
    from kinema.tui.tree_outline import build_outline  # imports the BT engine: after the first frame

    xml = connection.objective_xml(name)

    def load_subtree(subtree_id: str) -> str | None:
        try:
            return connection.objective_xml(subtree_id)
        except KinemaError:
            return None

    try:
        outline = build_outline(xml, name, filename=f"<objective {name!r}>", load_subtree=load_subtree)
    except KinemaError as error:
        return ObjectiveOutlineLoaded(name, xml, None, str(error))
    return ObjectiveOutlineLoaded(name, xml, outline)


def _objective_row(objective: ObjectiveSummary) -> Table:
    """One entry of the objective list: its mark, then its name, which wraps under itself (a narrow list
    cut 'Execute MTC Solution' and 'Execute MTC Solution JTC' to the same 'Execute MTC S…', and a wrapped
    name without the indent read as another objective)."""
    row = Table.grid(padding=0)
    row.add_column(width=2, no_wrap=True)
    row.add_column()
    if objective.favorite:
        mark = Text("★ ", style="yellow")
    else:
        # A subtree-only objective is marked before its name (a tag after it wrapped out of sight).
        mark = Text("  " if objective.runnable else "◦ ", style="dim")
    row.add_row(mark, Text(objective.name, style="" if objective.runnable else "dim italic"))
    return row


def _location(objective: ObjectiveSummary) -> str:
    """Where the objective's file is, short enough for the pane's one line at 80 columns: the package and
    the file's last two parts (``lab_sim: objectives/pick_object.xml``); the full path was cut off."""
    parts = Path(objective.file_path).parts if objective.file_path else ()
    short = "/".join(parts[-2:])
    return f"{objective.package}: {short}" if objective.package else short
