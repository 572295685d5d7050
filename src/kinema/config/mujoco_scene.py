"""The cell's MuJoCo scene as MuJoCo loads it, its includes and assets found where MoveIt Pro finds them.

An ``<include>`` of the scene is looked for beside the including file, then beside the scene (the two
places MuJoCo itself looks), then in the ``mujoco_assets`` folder of each workspace package: MoveIt Pro's
layout, where a config's scene includes ``ur5e/...`` from ``picknik_accessories`` and its build installs
those files beside the scene. Asset files (meshes, textures) follow the same rule after the scene's
folder; files found in a ``mujoco_assets`` folder reach MuJoCo through its in-memory file system.

Every file is checked before MuJoCo parses the scene (found, not a Git LFS pointer, no text STL), so a
problem is reported as Kinema's message with ``file:line`` rather than MuJoCo's parser error. ``kinema
build`` reports them all (:mod:`kinema.config.robot_check`); the simulation driver, ``kinema view`` and
the planning scene load the scene with :func:`load_scene`.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lxml import etree

from kinema.config.robot_files import is_ascii_stl
from kinema.errors import ConfigError, SourceLocation

if TYPE_CHECKING:
    from kinema.config.workspace import Workspace

#: Asset elements of MJCF that name a file, the attributes that do, and the compiler folder they use.
ASSET_FILES: dict[str, tuple[tuple[str, ...], str]] = {
    "mesh": (("file",), "meshdir"),
    "skin": (("file",), "meshdir"),
    "hfield": (("file",), "meshdir"),
    "texture": (
        ("file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback"),
        "texturedir",
    ),
}
#: LFS pointers named one by one before the rest are counted (a fresh clone has dozens).
_POINTERS_SHOWN = 3


class SceneFiles:
    """The files an MJCF scene and its includes name, found and checked before MuJoCo reads them.

    Attributes:
        virtual: files found only in a ``mujoco_assets`` folder, by the name MuJoCo will ask for.
        problems: what :meth:`check` found wrong, each with ``file:line``.
    """

    def __init__(self, main: Path, fallbacks: Sequence[Path]) -> None:
        self.main = main
        self.fallbacks = list(fallbacks)
        self.problems: list[ConfigError] = []
        self.virtual: dict[str, Path] = {}
        self.documents: list[tuple[Path, etree._Element]] = []
        self.pointers: list[tuple[str, Path, SourceLocation]] = []
        self.ok = True

    def check(self) -> bool:
        """Read the scene and its includes and check every file; False when something is wrong."""
        self._read(self.main, set())
        compiler: dict[str, str] = {}
        for _file, root in self.documents:
            for element in root.iter("compiler"):
                if element.get("assetdir"):
                    compiler["meshdir"] = compiler["texturedir"] = element.get("assetdir", "")
                for attribute in ("meshdir", "texturedir"):
                    if element.get(attribute):
                        compiler[attribute] = element.get(attribute, "")
        for file, root in self.documents:
            for element in root.iter(*ASSET_FILES):
                attributes, folder = ASSET_FILES[str(element.tag)]
                for attribute in attributes:
                    if element.get(attribute):
                        self._asset(element, attribute, compiler.get(folder, ""), file)
        self._report_pointers()
        return self.ok

    def model(self) -> Any:
        """The ``mujoco.MjModel`` of the scene, once :meth:`check` found its files.

        Raises:
            ConfigError: MuJoCo cannot load the model (the files are there: the model itself is wrong).
        """
        import mujoco

        assets = {name: file.read_bytes() for name, file in self.virtual.items()}
        try:
            return mujoco.MjModel.from_xml_path(str(self.main), assets or None)
        except (ValueError, RuntimeError) as exc:
            message = f"MuJoCo cannot load the scene: {' '.join(str(exc).split())}"
            raise ConfigError(message, location=SourceLocation(str(self.main))) from None

    def _problem(self, message: str, location: SourceLocation) -> None:
        self.ok = False
        self.problems.append(ConfigError(message, location=location))

    def _read(self, file: Path, stack: set[Path]) -> None:
        try:
            root = etree.parse(str(file), etree.XMLParser(remove_comments=True)).getroot()
        except etree.XMLSyntaxError as exc:
            self._problem(
                f"the MuJoCo scene is not valid XML: {exc.msg}", SourceLocation(str(file), exc.lineno or 0)
            )
            return
        except OSError as exc:
            self._problem(f"cannot read the MuJoCo scene: {exc}", SourceLocation(str(file)))
            return
        self.documents.append((file, root))
        for include in root.iter("include"):
            name = include.get("file", "")
            where = SourceLocation(str(file), include.sourceline or 0)
            places = [file.parent, self.main.parent, *self.fallbacks]
            found = self._find(name, places, where, "include")
            if found is None:
                continue
            if found.resolve() in stack:
                self._problem(f"<include file={name!r}> includes itself ({found})", where)
                continue
            if self._pointer(found):
                self.pointers.append(("include", found, where))
                continue
            if not _under(found, (file.parent, self.main.parent)):
                self.virtual[name] = found
            self._read(found, stack | {file.resolve()})

    def _asset(self, element: etree._Element, attribute: str, folder: str, file: Path) -> None:
        name = element.get(attribute, "")
        relative = os.path.join(folder, name) if folder else name
        where = SourceLocation(str(file), element.sourceline or 0)
        found = self._find(relative, [self.main.parent, *self.fallbacks], where, str(element.tag))
        if found is None:
            return
        if self._pointer(found):
            self.pointers.append((str(element.tag), found, where))
            return
        if element.tag == "mesh" and is_ascii_stl(found):
            self._problem(
                f"mesh {found} is a text STL, which MuJoCo cannot read: save it as binary STL or OBJ", where
            )
        elif not _under(found, (self.main.parent,)):
            self.virtual[relative] = found

    def _find(self, name: str, places: list[Path], where: SourceLocation, kind: str) -> Path | None:
        if not name:
            self._problem(f"<{kind}> without a file name", where)
            return None
        candidates = [Path(name)] if Path(name).is_absolute() else [place / name for place in places]
        for candidate in dict.fromkeys(candidates):
            if candidate.is_file():
                return candidate
        looked = "; ".join(str(c) for c in dict.fromkeys(candidates))
        self._problem(f"{kind} file {name!r} not found (looked for {looked})", where)
        return None

    @staticmethod
    def _pointer(path: Path) -> bool:
        from kinema.config.robot_files import is_lfs_pointer

        return is_lfs_pointer(path)

    def _report_pointers(self) -> None:
        for kind, path, where in self.pointers[:_POINTERS_SHOWN]:
            self._problem(f"{kind} {path} is a Git LFS pointer file (run `git lfs pull`)", where)
        rest = self.pointers[_POINTERS_SHOWN:]
        if rest:
            folders = sorted({str(path.parent) for _, path, _ in rest})
            self._problem(
                f"{len(rest)} more files the MuJoCo scene names are Git LFS pointer files (run `git lfs "
                f"pull`), in {', '.join(folders)}",
                rest[0][2],
            )


def _under(path: Path, folders: Iterable[Path]) -> bool:
    resolved = path.resolve()
    return any(resolved.is_relative_to(folder.resolve()) for folder in folders)


def asset_folders(workspace: Workspace) -> list[Path]:
    """The ``mujoco_assets`` folders of ``workspace``'s packages, where a scene's includes are looked for."""
    return [
        package.path / "mujoco_assets"
        for package in workspace.packages.values()
        if (package.path / "mujoco_assets").is_dir()
    ]


def load_scene(path: Path, folders: Sequence[Path] | None = None) -> Any:
    """The ``mujoco.MjModel`` of the scene at ``path``, its includes and assets also looked for in
    ``folders`` (default: the ``mujoco_assets`` folders of the workspace the scene is in).

    Raises:
        ConfigError: a file it names is missing, a Git LFS pointer or a text STL (the first problem, with
            its file:line, and how many more ``kinema build`` lists), or MuJoCo cannot load the model.
    """
    if folders is None:
        folders = _workspace_folders(path)
    files = SceneFiles(path, folders)
    if not files.check():
        first = files.problems[0]
        more = len(files.problems) - 1
        if more:
            first = ConfigError(
                f"{first.message} (and {more} more problem{'s' if more > 1 else ''}: `kinema build` lists "
                "them)",
                location=first.location,
            )
        raise first
    return files.model()


def _workspace_folders(path: Path) -> list[Path]:
    from kinema.config.workspace import Workspace

    try:
        workspace = Workspace.discover(path.parent)
    except ConfigError:
        return []  # a scene outside any workspace: MuJoCo's own places only
    return asset_folders(workspace)
