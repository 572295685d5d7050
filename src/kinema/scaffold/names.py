"""Which package names Kinema accepts: ROS package names (REP 144), which are also Python identifiers.

Lowercase letters, digits and single underscores, starting with a letter and not ending with an
underscore: ``my_robot_config``, ``lab_sim2``. The same rule is repeated in each template's
``hooks/pre_gen_project.py``.
"""

from __future__ import annotations

import importlib.util
import keyword
import re
import sys

from kinema.errors import ScaffoldError

#: The kinds of behavior ``kinema new behavior --type`` makes (a template folder each; the template's own
#: hook lists them again, for cookiecutter run on it directly).
BEHAVIOR_TYPES = (
    "sync",
    "stateful",
    "async",
    "service_client",
    "action_client",
    "topic_subscriber",
    "topic_publisher",
)

_PACKAGE_NAME = re.compile(r"^[a-z](?:[a-z0-9]|_(?!_))*$")
MAX_NAME_LENGTH = 100
_NAME_RULE = (
    "use lowercase letters, digits and single underscores, starting with a letter (e.g. my_robot_config)"
)


def package_name_problem(name: str) -> str | None:
    """Return why ``name`` is not a valid package name, or None when it is valid."""
    if not name:
        return "the name is empty"
    if len(name) > MAX_NAME_LENGTH:
        return f"the name is longer than {MAX_NAME_LENGTH} characters"
    if not _PACKAGE_NAME.match(name) or name.endswith("_"):
        return _NAME_RULE
    if keyword.iskeyword(name):
        return "the name is a Python keyword"
    return None


def module_name_problem(name: str) -> str | None:
    """Return why a Python package called ``name`` would clash with a module Python already has, or None.

    A behavior package is a Python package of its own name: called ``os`` or ``numpy`` it would shadow
    the standard-library or installed module in its own tests and in everything imported after it.
    """
    if name in sys.stdlib_module_names or name in sys.builtin_module_names:
        return f"{name!r} is a module of Python's standard library; a package of that name would shadow it"
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        spec = None
    # A namespace spec is only a folder on sys.path (the current folder included), not a module.
    if spec is not None and spec.origin is not None:
        where = spec.origin
        return f"{name!r} is an installed Python module ({where}); a package of that name would shadow it"
    return None


def check_package_name(name: str, *, what: str = "package name") -> None:
    """Raise a ScaffoldError when ``name`` is not a valid package name."""
    problem = package_name_problem(name)
    if problem is not None:
        raise ScaffoldError(f"{name!r} is not a valid {what}: {problem}")
