"""The active workspace and config package: what ``kinema configure`` stores and every verb uses.

Precedence, highest first: the command's own ``-w``/``-c`` flags, the environment variables
``KINEMA_WORKSPACE`` / ``KINEMA_CONFIG``, and the selection stored by ``kinema configure`` in
``<user config dir>/kinema/selection.yaml`` (``platformdirs``; on Linux ``$XDG_CONFIG_HOME/kinema``,
default ``~/.config/kinema``). With none of these, the config is the bundled ``lab_sim``, so a fresh
install runs the simulated robot cell with no set-up step.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import platformdirs
import yaml

from kinema.config.atomic_write import atomic_write_text
from kinema.config.yamlsource import load_yaml_file
from kinema.errors import ConfigError, SourceLocation

WORKSPACE_ENV = "KINEMA_WORKSPACE"
CONFIG_ENV = "KINEMA_CONFIG"
DEFAULT_CONFIG = "lab_sim"
_SELECTION_FILE = "selection.yaml"


@dataclass(frozen=True)
class Selection:
    """The workspace and config package in effect, and where each came from.

    Attributes:
        workspace: the workspace folder, or None (only bundled packages are visible).
        config: the config package name, or None when none is selected.
        workspace_source / config_source: ``"flag"``, ``"environment"``, ``"stored"``, ``"default"``
            (config only: the bundled lab_sim) or ``"unset"``.
    """

    workspace: Path | None
    config: str | None
    workspace_source: str = "unset"
    config_source: str = "unset"

    def require_config(self) -> str:
        """Return the config package name, or raise a ConfigError that says how to choose one."""
        if not self.config:
            raise ConfigError(
                f"no config package is selected; pass -c NAME, set {CONFIG_ENV}, "
                "or run `kinema configure -c NAME` "
                "(`kinema config list` shows the choices)"
            )
        return self.config


def user_config_dir() -> Path:
    """Kinema's folder in the user's config directory (honours ``XDG_CONFIG_HOME`` on Linux)."""
    return Path(platformdirs.user_config_dir("kinema", appauthor=False))


def selection_file() -> Path:
    """The file ``kinema configure`` writes."""
    return user_config_dir() / _SELECTION_FILE


def stored_selection() -> tuple[Path | None, str | None]:
    """Return the workspace and config stored by ``kinema configure`` (None for what is not stored).

    Raises:
        ConfigError: the stored file exists but is not the mapping ``kinema configure`` writes.
    """
    path = selection_file()
    if not path.is_file():
        return None, None
    document = load_yaml_file(path, max_bytes=1024 * 1024)
    data = document.data or {}
    if not isinstance(data, dict):
        raise ConfigError(
            "the stored selection is not a mapping; run `kinema configure` again",
            location=SourceLocation(str(path)),
        )
    workspace, config = data.get("workspace"), data.get("config")
    if workspace is not None and not isinstance(workspace, str):
        raise ConfigError("'workspace' must be a path", location=document.location(("workspace",)))
    if config is not None and not isinstance(config, str):
        raise ConfigError("'config' must be a package name", location=document.location(("config",)))
    return (Path(workspace) if workspace else None), (config or None)


def store_selection(workspace: Path | None, config: str | None) -> Path:
    """Write the active workspace and config for later commands; return the file written."""
    data = {"workspace": str(workspace) if workspace is not None else None, "config": config}
    path = selection_file()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise ConfigError(
            f"cannot create Kinema's config folder: {error.strerror}",
            location=SourceLocation(str(path.parent)),
        ) from None
    atomic_write_text(path, "# Written by `kinema configure`.\n" + yaml.safe_dump(data, sort_keys=False))
    return path


def active_selection(workspace: str | Path | None = None, config: str | None = None) -> Selection:
    """Return the workspace and config in effect.

    Args:
        workspace: a ``-w`` flag value (wins over everything else when given).
        config: a ``-c`` flag value (wins over everything else when given).
    """
    stored_workspace, stored_config = stored_selection()
    ws_value, ws_source = _pick(
        workspace, os.environ.get(WORKSPACE_ENV), str(stored_workspace) if stored_workspace else None
    )
    cfg_value, cfg_source = _pick(config, os.environ.get(CONFIG_ENV), stored_config)
    if cfg_value is None:
        cfg_value, cfg_source = DEFAULT_CONFIG, "default"
    return Selection(
        workspace=Path(ws_value).expanduser() if ws_value else None,
        config=cfg_value or None,
        workspace_source=ws_source,
        config_source=cfg_source,
    )


def _pick(flag: str | Path | None, env: str | None, stored: str | None) -> tuple[str | None, str]:
    if flag is not None and str(flag) != "":
        return str(flag), "flag"
    if env:
        return env, "environment"
    if stored:
        return stored, "stored"
    return None, "unset"
