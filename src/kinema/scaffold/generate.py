"""Generating a package from one of Kinema's cookiecutter templates (``cookiecutters/<name>/``).

Input is checked before anything is written: the context keys must be variables of the template, the
folder to create must not exist, and the caller's ``validate`` hook (a template's own rules: a valid
package name, a known parent, ...) may refuse it with a :class:`~kinema.errors.ScaffoldError`. Each
template's ``hooks/pre_gen_project.py`` checks the same rules again, so the template refuses bad input
even when cookiecutter is run on it directly (it prints ``ERROR: ...`` and exits 1).

Cookiecutter's rendering and hooks are used through its library functions rather than its top-level
entry point, so generating never writes replay files into the user's home directory.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kinema.errors import ScaffoldError, did_you_mean
from kinema.resources import bundled_dir

Validator = Callable[[dict[str, str]], None]
Prompt = Callable[[str, str], str]


@dataclass(frozen=True)
class Template:
    """A cookiecutter template shipped with Kinema.

    Attributes:
        name: the folder name under ``cookiecutters/``.
        path: the template folder.
        variables: the template's variables and their defaults (``cookiecutter.json``, private ``_`` keys
            left out).
    """

    name: str
    path: Path
    variables: dict[str, Any]


def available_templates() -> list[str]:
    """Names of the bundled templates."""
    root = bundled_dir("cookiecutters")
    if not root.is_dir():
        return []
    return sorted(p.name for p in root.iterdir() if (p / "cookiecutter.json").is_file())


def load_template(template_name: str) -> Template:
    """Return the bundled template ``template_name``.

    Raises:
        ScaffoldError: no such template (the message lists the available ones).
    """
    path = bundled_dir("cookiecutters") / template_name
    spec = path / "cookiecutter.json"
    if not spec.is_file():
        raise ScaffoldError(
            f"no template named {template_name!r}; {did_you_mean(template_name, available_templates())}"
        )
    import json  # here, not at the top: `kinema --help` imports this module (through `kinema new`)

    try:
        raw = json.loads(spec.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise ScaffoldError(f"{spec}: the template's cookiecutter.json cannot be read: {error}") from None
    variables = {key: value for key, value in raw.items() if not key.startswith("_")}
    return Template(template_name, path, variables)


def target_folder(template: Template, output_dir: Path, context: Mapping[str, str]) -> Path:
    """The folder generating ``template`` with ``context`` into ``output_dir`` would create."""
    from jinja2 import Environment

    tops = [p for p in template.path.iterdir() if p.is_dir() and "{{" in p.name]
    if len(tops) != 1:
        raise ScaffoldError(
            f"template {template.name!r} must have exactly one top folder named with {{{{ }}}}"
        )
    name = Environment().from_string(tops[0].name).render(cookiecutter=context)
    return output_dir / name


def generate(
    template_name: str,
    output_dir: str | Path,
    context: Mapping[str, str],
    *,
    no_input: bool = True,
    validate: Validator | None = None,
    prompt: Prompt | None = None,
) -> Path:
    """Generate a package from a bundled template.

    Args:
        template_name: folder under ``cookiecutters/`` (e.g. ``"config_package"``).
        output_dir: where the package folder is created (created itself when missing).
        context: template variables; the others take the template's defaults.
        no_input: when False, ask ``prompt(variable, default)`` for each variable not in ``context``.
        validate: called with the full context before anything is written; raises ScaffoldError to refuse.
        prompt: asks the user for one value (default: ``click.prompt``).

    Returns:
        The generated package folder.

    Raises:
        ScaffoldError: unknown template or variable, existing target folder, refused input, or a failure
            of the template itself.
    """
    template = load_template(template_name)
    unknown = sorted(set(context) - set(template.variables))
    if unknown:
        raise ScaffoldError(
            f"template {template_name!r} has no variable {unknown[0]!r}; "
            f"valid: {', '.join(template.variables)}"
        )
    values = _complete_context(template, dict(context), no_input, prompt)
    output_dir = Path(output_dir).expanduser().resolve()
    if output_dir.exists() and not output_dir.is_dir():
        raise ScaffoldError(f"the output folder {output_dir} is a file")
    target = target_folder(template, output_dir, values)
    if target.exists():
        raise ScaffoldError(f"{target} already exists; choose another name or output folder (-o)")
    if validate is not None:
        validate(values)
    output_dir.mkdir(parents=True, exist_ok=True)
    return _render(template, output_dir, values)


def _complete_context(
    template: Template, context: dict[str, str], no_input: bool, prompt: Prompt | None
) -> dict[str, str]:
    from jinja2 import Environment

    environment = Environment()
    values: dict[str, str] = {}
    for key, default in template.variables.items():
        if key in context:
            values[key] = str(context[key])
            continue
        # Defaults may refer to earlier variables ("{{ cookiecutter.package_name }} ..."), as in cookiecutter.
        rendered = (
            environment.from_string(str(default)).render(cookiecutter=values) if default is not None else ""
        )
        if not no_input:
            ask = prompt if prompt is not None else _click_prompt
            rendered = ask(key, rendered)
        values[key] = rendered
    return values


def _click_prompt(name: str, default: str) -> str:
    import click

    return str(click.prompt(name.replace("_", " "), default=default))


def _render(template: Template, output_dir: Path, values: dict[str, str]) -> Path:
    from cookiecutter.exceptions import CookiecutterException, FailedHookException, OutputDirExistsException
    from cookiecutter.generate import generate_context, generate_files

    context = generate_context(context_file=str(template.path / "cookiecutter.json"), extra_context=values)
    context["cookiecutter"].update(values)
    context["cookiecutter"]["_template"] = str(template.path)
    context["cookiecutter"]["_output_dir"] = str(output_dir)
    context["cookiecutter"]["_repo_dir"] = str(template.path)
    context["_cookiecutter"] = {k: v for k, v in context["cookiecutter"].items() if not k.startswith("_")}
    # cookiecutter logs a failing hook with logger.exception; the hook already printed its ERROR line and
    # the ScaffoldError below says the rest, so its traceback must not reach the user.
    import logging

    hook_logger = logging.getLogger("cookiecutter")
    quiet = logging.NullHandler()
    hook_logger.addHandler(quiet)
    propagate, hook_logger.propagate = hook_logger.propagate, False
    try:
        result = generate_files(
            repo_dir=str(template.path),
            context=context,
            overwrite_if_exists=False,
            output_dir=str(output_dir),
            accept_hooks=True,
        )
    except FailedHookException as error:
        raise ScaffoldError(f"template {template.name!r} refused the input ({error})") from None
    except OutputDirExistsException as error:
        raise ScaffoldError(str(error)) from None
    except CookiecutterException as error:
        raise ScaffoldError(f"template {template.name!r} failed: {error}") from None
    finally:
        hook_logger.removeHandler(quiet)
        hook_logger.propagate = propagate
    return Path(result)
