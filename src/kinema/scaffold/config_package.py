"""``kinema new config``: a config package based on another one, from ``cookiecutters/config_package``.

The generated package is what the MoveIt Pro tutorial builds by hand for ``example_config``: a
``config/config.yaml`` with ``based_on_package`` and its own ``objectives/`` folder registered under
``objective_library_paths``, plus ``package.xml`` metadata. It resolves at once with
``kinema config show``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from kinema.config.workspace import Workspace, select_workspace_hint
from kinema.errors import ScaffoldError, did_you_mean
from kinema.scaffold.generate import Prompt, Validator, generate
from kinema.scaffold.names import check_package_name

TEMPLATE = "config_package"


def default_output_dir(workspace: Workspace) -> Path:
    """The active workspace's ``src/`` (where new packages go unless ``-o`` says otherwise).

    Raises:
        ScaffoldError: no workspace is selected.
    """
    if workspace.root is None:
        raise ScaffoldError(
            "no workspace is selected, so there is no src/ to create the package in (-o DIR names a "
            f"folder instead); {select_workspace_hint()}"
        )
    return workspace.root / "src"


def config_package_validator(workspace: Workspace) -> Validator:
    """The check run on the template's context before anything is written."""

    def validate(values: dict[str, str]) -> None:
        name, parent = values["package_name"], values["based_on_package"]
        check_package_name(name)
        if name == parent:
            raise ScaffoldError(f"{name!r} cannot be based on itself; choose another name or parent")
        # A bundled package of the same name is fine: the new workspace package overlays it.
        if workspace.has_package(name) and workspace.package(name).origin != "bundled":
            existing = workspace.package(name)
            raise ScaffoldError(
                f"a package named {name!r} already exists ({existing.path}); choose another name"
            )
        configs = [p.name for p in workspace.config_packages(include_hidden=True)]
        if not workspace.has_package(parent) or not workspace.package(parent).is_config:
            raise ScaffoldError(
                f"cannot base {name!r} on {parent!r}: no config package of that name in "
                f"{workspace.describe()}; "
                f"{did_you_mean(parent, configs)}"
            )

    return validate


def new_config_package(
    name: str,
    based_on: str,
    output_dir: str | Path | None = None,
    *,
    workspace: Workspace | None = None,
    no_input: bool = True,
    extra_context: Mapping[str, str] | None = None,
    prompt: Prompt | None = None,
) -> Path:
    """Generate config package ``name`` based on ``based_on``.

    Args:
        name: the new package's name (a valid ROS package name not used by another workspace package;
            a bundled package of that name is overlaid by the new one).
        based_on: the parent config package (must be visible from ``workspace``).
        output_dir: where to create it; default: the workspace's ``src/``.
        workspace: where names are checked; default: the active workspace.
        no_input: False to be asked for the other template variables (description, maintainer, ...).
        extra_context: values for the other template variables.
        prompt: asks for one value when ``no_input`` is False (default: ``click.prompt``).

    Returns:
        The new package folder.

    Raises:
        ScaffoldError: invalid or taken name, unknown parent, existing folder; nothing is written then.
    """
    workspace = workspace if workspace is not None else Workspace.discover()
    target_dir = Path(output_dir) if output_dir is not None else default_output_dir(workspace)
    check_package_name(name)
    context = {**(extra_context or {}), "package_name": name, "based_on_package": based_on}
    validate = config_package_validator(workspace)
    return generate(TEMPLATE, target_dir, context, no_input=no_input, validate=validate, prompt=prompt)
