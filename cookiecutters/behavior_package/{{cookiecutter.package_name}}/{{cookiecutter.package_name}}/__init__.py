"""{{ cookiecutter.description }}.

Loader: ``{{ cookiecutter.loader_name }}``.
"""

from __future__ import annotations

from kinema.plugins import RegisterBehavior, hookimpl

from .{{ cookiecutter.behavior_name }} import {{ cookiecutter.behavior_id }}


@hookimpl
def register_behaviors(register: RegisterBehavior) -> None:
    """Register this package's behaviors (the class name is the behavior ID unless one is given)."""
    register({{ cookiecutter.behavior_id }})
