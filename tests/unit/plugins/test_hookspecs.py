"""Every hook a plugin can implement is documented, and hook typos are caught when a plugin loads."""

from __future__ import annotations

import inspect
import types

import pytest

from kinema.errors import PluginError
from kinema.plugins import hookimpl, hookspecs
from kinema.plugins.manager import KinemaPluginManager


def _hookspecs() -> list[types.FunctionType]:
    return [
        value
        for value in vars(hookspecs).values()
        if inspect.isfunction(value) and hasattr(value, f"{hookspecs.PROJECT_NAME}_spec")
    ]


def test_there_are_hooks_and_each_has_a_one_line_docstring() -> None:
    specs = _hookspecs()
    assert [spec.__name__ for spec in specs] == KinemaPluginManager().hook_names()
    assert "register_behaviors" in [spec.__name__ for spec in specs]
    for spec in specs:
        doc = inspect.getdoc(spec)
        assert doc, f"hook {spec.__name__} has no docstring"
        assert "\n" not in doc.strip(), f"hook {spec.__name__}: the docstring should be one line"


def test_a_misspelled_hook_is_rejected_with_the_plugin_name() -> None:
    plugin = types.ModuleType("typo_plugin")

    @hookimpl
    def register_behavior(register):  # the hook is register_behaviors
        register(object)

    plugin.register_behavior = register_behavior  # type: ignore[attr-defined]
    manager = KinemaPluginManager()
    with pytest.raises(PluginError, match=r"typo_pkg::TypoBehaviorsLoader.*register_behaviors"):
        manager.add("typo_pkg::TypoBehaviorsLoader", plugin)
    assert manager.names() == []


def test_a_hook_with_unknown_arguments_is_rejected() -> None:
    plugin = types.ModuleType("bad_args")

    @hookimpl
    def register_behaviors(register, factory):
        pass

    plugin.register_behaviors = register_behaviors  # type: ignore[attr-defined]
    with pytest.raises(PluginError, match="bad::Loader"):
        KinemaPluginManager().add("bad::Loader", plugin)
