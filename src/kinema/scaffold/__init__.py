"""Generating packages from Kinema's cookiecutter templates, with input checked before anything is written.

* :func:`generate` (``generate(template_name, output_dir, context, no_input=..., validate=...)``) renders
  any bundled template; template-specific rules come in through ``validate``.
* :func:`new_config_package` is ``kinema new config``.
* :func:`check_package_name` / :func:`package_name_problem` are the package-name rules.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.scaffold.generate import Template, available_templates, generate, load_template
from kinema.scaffold.names import check_package_name, package_name_problem

if TYPE_CHECKING:
    from kinema.scaffold.config_package import new_config_package

__all__ = [
    "Template",
    "available_templates",
    "check_package_name",
    "generate",
    "load_template",
    "new_config_package",
    "package_name_problem",
]


def __getattr__(name: str) -> Any:
    # Imported on first use: `kinema --help` reaches kinema.scaffold.names (through `kinema new`) and must
    # not load the config stack new_config_package needs (40-100 ms).
    if name == "new_config_package":
        from kinema.scaffold.config_package import new_config_package

        return new_config_package
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
