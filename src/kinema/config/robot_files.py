"""Where a robot's files are, and making them loadable by MuJoCo, pinocchio and the view.

A robot description arrives as a URDF or a xacro file whose meshes are named by ``package://pkg/rel``
URIs, ``file://`` URIs or paths relative to the URDF. :class:`PackageIndex` finds ROS package folders
the way ROS would (the caller's own folders first, then ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH`` and
pip-installed ``cmeel.prefix/share`` trees such as example-robot-data's); :func:`resolve_robot` runs
xacro, resolves and checks every mesh, and returns a :class:`ResolvedRobot` that can write a copy of the
URDF with absolute mesh paths. :func:`convert_mesh` turns the formats MuJoCo cannot read (COLLADA,
mostly) into OBJ once, cached by content.

Every problem is a :class:`~kinema.errors.ConfigError` naming the file (and line where known): an unknown
package lists where it was looked for; a mesh checked out as a Git LFS pointer says to run
``git lfs pull``.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import site
import sysconfig
import threading
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import unquote, urlparse

from lxml import etree

from kinema.errors import ConfigError, SourceLocation, did_you_mean

LFS_POINTER_PREFIX = b"version https://git-lfs.github.com/spec/v1"

# Formats MuJoCo's mesh decoders read; everything else goes through trimesh (see convert_mesh).
MUJOCO_MESH_SUFFIXES = frozenset({".stl", ".obj", ".msh"})


# -- finding packages ---------------------------------------------------------------------------------


def _package_name(folder: Path) -> str | None:
    """The ``<name>`` a ``package.xml`` in ``folder`` declares, or None."""
    manifest = folder / "package.xml"
    if not manifest.is_file():
        return None
    try:
        root = etree.parse(str(manifest)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return folder.name
    name = root.findtext("name")
    return name.strip() if name and name.strip() else folder.name


def _scan_for_packages(root: Path, found: dict[str, Path], *, max_depth: int = 4) -> None:
    """Add every folder under ``root`` holding a package.xml (not descending into packages, as catkin)."""
    if not root.is_dir():
        return
    pending = [(root, 0)]
    while pending:
        folder, depth = pending.pop()
        name = _package_name(folder)
        if name is not None:
            found.setdefault(name, folder)
            continue
        if depth >= max_depth:
            continue
        try:
            children = sorted(
                (c for c in folder.iterdir() if c.is_dir() and not c.name.startswith(".")), reverse=True
            )
        except OSError:
            continue
        if (folder / "COLCON_IGNORE").exists() or (folder / "CATKIN_IGNORE").exists():
            continue
        pending.extend((child, depth + 1) for child in children)


def _site_package_folders() -> list[Path]:
    folders: list[str] = []
    for key in ("purelib", "platlib"):
        with contextlib.suppress(KeyError):
            folders.append(sysconfig.get_paths()[key])
    with contextlib.suppress(AttributeError):
        folders.extend(site.getsitepackages())
    with contextlib.suppress(AttributeError):
        folders.append(site.getusersitepackages())
    unique: list[Path] = []
    for folder in folders:
        path = Path(folder)
        if path not in unique:
            unique.append(path)
    return unique


@dataclass
class PackageIndex:
    """Finds ROS package folders by name.

    Looks, in this order, in: ``packages`` (name → folder, e.g. the workspace's and Kinema's bundled
    packages), the folders in ``package_roots`` (scanned for ``package.xml``), each folder of
    ``ROS_PACKAGE_PATH`` (scanned; a folder named like the package also counts), each
    ``AMENT_PREFIX_PATH`` entry's ``share/<pkg>``, and every ``cmeel.prefix/share`` under the
    environment's site-packages (pip-installed description packages: example-robot-data's URIs are
    ``package://example-robot-data/robots/...``: that package is ``cmeel.prefix/share/example-robot-data``).

    Args:
        packages: package name → folder, consulted first.
        package_roots: folders to scan for ``package.xml`` (a workspace's ``src``).
        environ: the environment to read ``ROS_PACKAGE_PATH``/``AMENT_PREFIX_PATH`` from (``os.environ``).
        site_packages: site-packages folders to look for ``cmeel.prefix/share`` in (this interpreter's).
    """

    packages: Mapping[str, str | Path] = field(default_factory=dict)
    package_roots: Iterable[str | Path] = ()
    environ: Mapping[str, str] | None = None
    site_packages: Iterable[str | Path] | None = None

    def __post_init__(self) -> None:
        self._explicit = {name: Path(folder) for name, folder in self.packages.items()}
        self._roots = [Path(r) for r in self.package_roots]
        env = os.environ if self.environ is None else self.environ
        self._ros_package_path = [Path(p) for p in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        self._ament_prefixes = [Path(p) for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        sites = (
            _site_package_folders() if self.site_packages is None else [Path(p) for p in self.site_packages]
        )
        self._cmeel_shares: list[Path] = []
        for folder in sites:
            share = folder / "cmeel.prefix" / "share"
            if share.is_dir() and share not in self._cmeel_shares:
                self._cmeel_shares.append(share)
        self._scanned: dict[str, Path] | None = None

    def _scan(self) -> dict[str, Path]:
        if self._scanned is None:
            found: dict[str, Path] = {}
            for root in self._roots:
                _scan_for_packages(root, found)
            for root in self._ros_package_path:
                _scan_for_packages(root, found)
            self._scanned = found
        return self._scanned

    def find(self, name: str) -> Path | None:
        """The folder of package ``name`` (absolute), or None when no source has it."""
        if not name:
            return None
        if name in self._explicit and self._explicit[name].is_dir():
            return self._explicit[name].resolve()
        scanned = self._scan()
        if name in scanned:
            return scanned[name].resolve()
        for root in self._ros_package_path:
            if (root / name).is_dir():
                return (root / name).resolve()
            if root.name == name and root.is_dir():
                return root.resolve()
        for prefix in self._ament_prefixes:
            candidate = prefix / "share" / name
            if candidate.is_dir():
                return candidate.resolve()
        for share in self._cmeel_shares:
            candidate = share / name
            if candidate.is_dir():
                return candidate.resolve()
        return None

    def known_packages(self) -> list[str]:
        """Names of the packages this index can list without guessing (for did-you-mean hints)."""
        names = set(self._explicit) | set(self._scan())
        for share in [*(p / "share" for p in self._ament_prefixes), *self._cmeel_shares]:
            with contextlib.suppress(OSError):
                names.update(c.name for c in share.iterdir() if c.is_dir())
        return sorted(names)

    def package_dirs(self) -> list[Path]:
        """Folders to hand pinocchio's ``buildGeomFromUrdf(package_dirs=...)``.

        Pinocchio resolves ``package://pkg/rel`` as ``<dir>/pkg/rel`` for each dir, so these are the
        *parents* of the package folders (a package whose folder is not named like the package cannot be
        reached this way: :meth:`ResolvedRobot.write_urdf` with absolute paths always works).
        """
        dirs: list[Path] = []

        def add(path: Path) -> None:
            path = path.resolve()
            if path.is_dir() and path not in dirs:
                dirs.append(path)

        for folder in [*self._explicit.values(), *self._scan().values()]:
            add(folder.parent)
        for root in self._ros_package_path:
            add(root)
        for prefix in self._ament_prefixes:
            add(prefix / "share")
        for share in self._cmeel_shares:
            add(share)
        return dirs

    def searched(self) -> list[str]:
        """Where :meth:`find` looks, in order, as sentences for an error message."""
        places: list[str] = []
        if self._explicit:
            places.append("the config's packages (" + ", ".join(sorted(self._explicit)) + ")")
        places.extend(f"{root} (scanned for package.xml)" for root in self._roots)
        if self._ros_package_path:
            places.extend(f"{p} (ROS_PACKAGE_PATH)" for p in self._ros_package_path)
        else:
            places.append("ROS_PACKAGE_PATH (not set)")
        if self._ament_prefixes:
            places.extend(f"{p / 'share'} (AMENT_PREFIX_PATH)" for p in self._ament_prefixes)
        else:
            places.append("AMENT_PREFIX_PATH (not set)")
        places.extend(f"{share} (pip-installed description packages)" for share in self._cmeel_shares)
        return places

    def not_found_message(self, name: str) -> str:
        """``package 'x' not found; looked in: ...; did you mean ...`` for an error."""
        return (
            f"ROS package {name!r} not found; looked in: {'; '.join(self.searched())}; "
            f"{did_you_mean(name, self.known_packages())}"
        )


# -- URIs ----------------------------------------------------------------------------------------------


def resolve_uri(
    uri: str,
    *,
    base_dir: str | Path,
    index: PackageIndex,
    location: SourceLocation | None = None,
) -> Path:
    """The absolute path a mesh or include URI names.

    Accepts ``package://pkg/rel``, ``file:///abs``, absolute paths and paths relative to ``base_dir``
    (the URDF's folder). Does not check that the file exists (see :func:`check_mesh`).

    Raises:
        ConfigError: an unknown package (naming it, the URI, ``location`` and where it looked) or a URI
            scheme other than package and file.
    """
    uri = uri.strip()
    if uri.startswith("package://"):
        rest = uri[len("package://") :]
        name, _, relative = rest.partition("/")
        folder = index.find(name)
        if folder is None:
            raise ConfigError(f"{uri}: {index.not_found_message(name)}", location=location)
        return (folder / unquote(relative)).resolve()
    if uri.startswith("file://"):
        return Path(unquote(urlparse(uri).path)).resolve()
    if "://" in uri:
        raise ConfigError(
            f"cannot resolve {uri!r}: only package://, file:// and file paths are supported",
            location=location,
        )
    path = Path(uri).expanduser()
    return (path if path.is_absolute() else Path(base_dir) / path).resolve()


# -- xacro -----------------------------------------------------------------------------------------------

# xacro keeps its file stack and substitution table in module globals: one expansion at a time.
_XACRO_LOCK = threading.Lock()


@contextlib.contextmanager
def _xacro_find_through(index: PackageIndex, source: Path) -> Iterator[None]:
    """Make xacro's ``$(find pkg)`` (and ``${find('pkg')}``) answer from ``index``.

    xacro looks packages up with ``ament_index_python``, which is absent or unaware of the workspace
    outside a sourced ROS install; its lookup function is swapped for the duration.
    """
    import xacro.substitution_args as substitution_args

    def find(name: str) -> str:
        folder = index.find(name)
        if folder is None:
            raise ConfigError(
                f"$(find {name}): {index.not_found_message(name)}", location=SourceLocation(str(source))
            )
        return str(folder)

    saved_function = substitution_args._eval_find
    saved_symbol = substitution_args._eval_dict.get("find")
    substitution_args._eval_find = find
    substitution_args._eval_dict["find"] = find
    try:
        yield
    finally:
        substitution_args._eval_find = saved_function
        substitution_args._eval_dict["find"] = saved_symbol


def _is_xacro(path: Path, text: str) -> bool:
    """A ``.xacro`` file, or one that declares the xacro namespace and uses it."""
    return path.name.endswith(".xacro") or ("xmlns:xacro" in text[:4000] and "<xacro:" in text)


def process_xacro(
    path: str | Path, args: Mapping[str, str] | None = None, *, index: PackageIndex | None = None
) -> str:
    """The URDF text of ``path``: xacro-expanded with ``args`` when it is a xacro file, else as it is.

    A file is xacro when its name ends in ``.xacro`` or its root element declares the xacro namespace.

    Raises:
        ConfigError: the file is missing, or xacro fails (naming the file being expanded, and the line
            for XML syntax errors).
    """
    path = Path(path).resolve()
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(
            f"cannot read robot description: {exc.strerror or exc}", location=SourceLocation(str(path))
        ) from None
    if not _is_xacro(path, text):
        return text
    import xml.parsers.expat

    import xacro

    index = index if index is not None else PackageIndex()
    mappings = {str(k): str(v) for k, v in (args or {}).items()}
    given = ", ".join(sorted(mappings)) or "none"  # xacro adds the <xacro:arg> defaults to mappings
    with _XACRO_LOCK, _xacro_find_through(index, path):
        try:
            document = xacro.process_file(str(path), mappings=mappings)
        except ConfigError:
            raise
        except xml.parsers.expat.ExpatError as exc:
            where = (xacro.filestack or [str(path)])[-1] or str(path)
            raise ConfigError(
                f"xacro: not valid XML: {exc}", location=SourceLocation(str(where), exc.lineno)
            ) from None
        except Exception as exc:  # xacro raises XacroException, NameError, KeyError, ... for bad input
            cause = exc.exc if isinstance(exc, xacro.XacroException) and exc.exc is not None else exc
            if isinstance(cause, ConfigError):
                raise cause from None
            where = (xacro.filestack or [str(path)])[-1] or str(path)
            message = " ".join(str(exc).split()) or type(exc).__name__  # xacro breaks lines oddly
            if isinstance(exc, KeyError) or "Undefined substitution argument" in message:
                message += f" (xacro arguments given: {given})"
            raise ConfigError(f"xacro failed: {message}", location=SourceLocation(str(where))) from None
        return str(document.toprettyxml(indent="  "))


# -- meshes ------------------------------------------------------------------------------------------------


def is_lfs_pointer(path: str | Path) -> bool:
    """True when ``path`` is a Git LFS pointer file (a clone without ``git lfs pull``), not the file itself;
    False when it is anything else or cannot be read."""
    try:
        with Path(path).open("rb") as handle:
            return handle.read(len(LFS_POINTER_PREFIX)) == LFS_POINTER_PREFIX
    except OSError:
        return False


def check_mesh(path: str | Path, *, location: SourceLocation | None = None) -> Path:
    """``path`` if it is a readable mesh file.

    Raises:
        ConfigError: ``mesh not found``, or ``mesh <path> is a Git LFS pointer file (run `git lfs pull`)``.
    """
    path = Path(path)
    try:
        with path.open("rb") as handle:
            head = handle.read(len(LFS_POINTER_PREFIX))
    except FileNotFoundError:
        raise ConfigError(f"mesh not found: {path}", location=location) from None
    except IsADirectoryError:
        raise ConfigError(f"mesh not found: {path} is a folder", location=location) from None
    except OSError as exc:
        raise ConfigError(f"cannot read mesh {path}: {exc.strerror or exc}", location=location) from None
    if head == LFS_POINTER_PREFIX:
        raise ConfigError(f"mesh {path} is a Git LFS pointer file (run `git lfs pull`)", location=location)
    return path


def is_ascii_stl(path: str | Path) -> bool:
    """An STL file in the text format, which MuJoCo's decoder refuses (it reads binary STL only).

    A binary STL is 84 bytes of header and count plus 50 bytes a triangle; its 80-byte header may itself
    begin with ``solid``, so the size decides, and the ``solid`` keyword only when the size does not fit.
    """
    path = Path(path)
    if path.suffix.lower() != ".stl":
        return False
    try:
        size = path.stat().st_size
        with path.open("rb") as handle:
            head = handle.read(84)
    except OSError:
        return False
    if len(head) == 84 and size == 84 + 50 * int.from_bytes(head[80:84], "little"):
        return False
    return head.lstrip().startswith(b"solid")


def _file_digest(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()[:24]


def convert_mesh(path: str | Path, cache_dir: str | Path) -> Path:
    """A mesh file MuJoCo can read with the same geometry as ``path``.

    Binary STL and OBJ come back as they are. Other formats (COLLADA ``.dae`` above all, which MuJoCo
    refuses, and text STL, which it refuses too) are loaded with trimesh, their scene graph flattened into
    one mesh in the file's own frame and units, and written as ``<cache_dir>/<stem>-<content hash>.obj``,
    so a file is converted once however often it is asked for. The sub-meshes' colours, averaged by area,
    are kept beside it (see :func:`converted_mesh_rgba`) for the MJCF's ``rgba``: MuJoCo reads no
    materials from an OBJ.

    Raises:
        ConfigError: the file is missing, an LFS pointer, or trimesh cannot read it.
    """
    path = check_mesh(path)
    if path.suffix.lower() in MUJOCO_MESH_SUFFIXES and not is_ascii_stl(path):
        return path
    cache_dir = Path(cache_dir)
    target = cache_dir / f"{path.stem}-{_file_digest(path)}.obj"
    if target.is_file():
        return target
    import trimesh

    try:
        loaded = trimesh.load_scene(str(path))
    except Exception as exc:  # trimesh/pycollada raise anything from ValueError to KeyError on bad files
        raise ConfigError(f"cannot read mesh {path}: {exc}") from None
    meshes: list[trimesh.Trimesh] = []
    colours: list[tuple[float, list[float]]] = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry.get(geometry_name)
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue
        mesh = geometry.copy()
        mesh.apply_transform(transform)
        rgba = _mesh_rgba(mesh)
        if rgba is not None:
            colours.append((float(mesh.area), rgba))
        mesh.visual = trimesh.visual.ColorVisuals(mesh)  # geometry only: MuJoCo ignores .mtl colours
        meshes.append(mesh)
    if not meshes:
        raise ConfigError(f"mesh {path} holds no triangles")
    combined = trimesh.util.concatenate(meshes)
    cache_dir.mkdir(parents=True, exist_ok=True)
    from kinema.config.atomic_write import atomic_write_bytes, atomic_write_text

    text = trimesh.exchange.obj.export_obj(
        combined, include_normals=True, include_color=False, include_texture=False
    )
    atomic_write_bytes(target, text.encode("utf-8"))
    total = sum(area for area, _ in colours)
    if colours and total > 0:
        average = [sum(area * c[i] for area, c in colours) / total for i in range(4)]
        atomic_write_text(target.with_suffix(".json"), json.dumps({"rgba": [round(v, 4) for v in average]}))
    return target


def _mesh_rgba(mesh: object) -> list[float] | None:
    visual = getattr(mesh, "visual", None)
    material = getattr(visual, "material", None)
    colour = getattr(material, "main_color", None)
    if colour is None and getattr(visual, "kind", None) in ("face", "vertex"):
        colour = visual.face_colors.mean(axis=0)  # type: ignore[union-attr]
    if colour is None:
        return None
    values = [float(v) for v in list(colour)[:4]]
    if len(values) == 3:
        values.append(255.0)
    return [v / 255.0 for v in values]


def default_mesh_cache() -> Path:
    """Where converted meshes are kept between runs: ``<user cache dir>/kinema/meshes``."""
    import platformdirs

    return platformdirs.user_cache_path("kinema") / "meshes"


def converted_mesh_rgba(converted: str | Path) -> tuple[float, float, float, float] | None:
    """The colour :func:`convert_mesh` recorded for a converted mesh, or None."""
    sidecar = Path(converted).with_suffix(".json")
    try:
        rgba = json.loads(sidecar.read_text(encoding="utf-8"))["rgba"]
        return (float(rgba[0]), float(rgba[1]), float(rgba[2]), float(rgba[3]))
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return None


# -- the resolved robot -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MeshReference:
    """One ``<mesh filename>`` of the URDF.

    Attributes:
        uri: the filename as written.
        path: the absolute path it resolves to (checked to exist and not be an LFS pointer).
        link: the link it belongs to.
        role: ``"visual"`` or ``"collision"``.
        location: the URDF file and the line of the ``<mesh>`` element.
    """

    uri: str
    path: Path
    link: str
    role: str
    location: SourceLocation


@dataclass(frozen=True)
class UrdfJoint:
    """A URDF joint, as the scene generator and planning-group guess need it.

    ``kind`` is the URDF type (revolute, continuous, prismatic, fixed, floating, planar); limits are None
    when the URDF gives none; ``mimic`` is ``(leader, multiplier, offset)``.
    """

    name: str
    kind: str
    parent: str
    child: str
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    damping: float = 0.0
    mimic: tuple[str, float, float] | None = None
    line: int = 0

    @property
    def movable(self) -> bool:
        """Revolute, continuous or prismatic (the joints with one coordinate)."""
        return self.kind in ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class ResolvedRobot:
    """A robot description with every file it names found.

    Attributes:
        source: the URDF or xacro file it came from.
        urdf_text: the URDF (xacro expanded), mesh URIs as written.
        name: the ``<robot name>``.
        meshes: every visual and collision ``<mesh>``, in document order.
    """

    source: Path
    urdf_text: str
    name: str
    meshes: tuple[MeshReference, ...]

    def _tree(self) -> etree._Element:
        return etree.fromstring(self.urdf_text.encode("utf-8"), etree.XMLParser(remove_blank_text=False))

    def urdf_with_paths(self, paths: Mapping[str, str | Path] | None = None) -> str:
        """The URDF text with each mesh's filename replaced.

        ``paths`` maps an absolute mesh path (as in :attr:`meshes`) to the filename to write; by default
        each mesh gets its absolute path.
        """
        root = self._tree()
        references = iter(self.meshes)
        for element in _mesh_elements(root):
            reference = next(references)
            replacement = (
                paths.get(str(reference.path), reference.path) if paths is not None else reference.path
            )
            element.set("filename", str(replacement))
        return etree.tostring(root, encoding="unicode")

    def write_urdf(self, path: str | Path) -> Path:
        """Write a copy of the URDF with absolute mesh paths (loadable by MuJoCo and pinocchio as it is)."""
        from kinema.config.atomic_write import atomic_write_text

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, '<?xml version="1.0"?>\n' + self.urdf_with_paths())
        return path

    def joints(self) -> list[UrdfJoint]:
        """Every joint of the URDF, in document order."""
        return parse_joints(self.urdf_text)

    def movable_joints(self) -> list[str]:
        """Names of the revolute, continuous and prismatic joints, mimic followers included."""
        return [joint.name for joint in self.joints() if joint.movable]

    def root_link(self) -> str:
        """The link that is no joint's child."""
        return root_link(self.urdf_text)


def _mesh_elements(root: etree._Element) -> list[etree._Element]:
    return [
        mesh
        for link in root.iter("link")
        for role in ("visual", "collision")
        for element in link.findall(role)
        for mesh in element.findall("geometry/mesh")
    ]


def _float(value: str | None) -> float | None:
    if value is None:
        return None
    try:
        return float(value)
    except ValueError:
        return None


def _float_or(value: str | None, default: float) -> float:
    number = _float(value)
    return default if number is None else number


def _parse(urdf_text: str) -> etree._Element:
    return etree.fromstring(urdf_text.encode("utf-8"))


def parse_joints(urdf_text: str) -> list[UrdfJoint]:
    """The joints of a URDF text, in document order (top-level ``<joint>`` elements only)."""
    joints = []
    for element in _parse(urdf_text).findall("joint"):
        limit = element.find("limit")
        dynamics = element.find("dynamics")
        mimic = element.find("mimic")
        parent, child = element.find("parent"), element.find("child")
        joints.append(
            UrdfJoint(
                name=element.get("name", ""),
                kind=element.get("type", ""),
                parent=parent.get("link", "") if parent is not None else "",
                child=child.get("link", "") if child is not None else "",
                lower=_float(limit.get("lower")) if limit is not None else None,
                upper=_float(limit.get("upper")) if limit is not None else None,
                effort=_float(limit.get("effort")) if limit is not None else None,
                velocity=_float(limit.get("velocity")) if limit is not None else None,
                damping=_float_or(dynamics.get("damping"), 0.0) if dynamics is not None else 0.0,
                mimic=(
                    (
                        mimic.get("joint", ""),
                        _float_or(mimic.get("multiplier"), 1.0),
                        _float_or(mimic.get("offset"), 0.0),
                    )
                    if mimic is not None
                    else None
                ),
                line=element.sourceline or 0,
            )
        )
    return joints


def root_link(urdf_text: str) -> str:
    """The URDF's root link: the one link that is no joint's child."""
    root = _parse(urdf_text)
    children = {c.get("link") for c in root.iterfind("joint/child")}
    roots = [link.get("name", "") for link in root.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise ConfigError(
            f"a URDF has one root link; this one has {len(roots)}: {', '.join(roots) or 'none'}"
        )
    return roots[0]


def resolve_robot(
    path: str | Path,
    *,
    xacro_args: Mapping[str, str] | None = None,
    index: PackageIndex | None = None,
) -> ResolvedRobot:
    """Read a URDF or xacro file and find every mesh it names.

    Raises:
        ConfigError: the file is missing or not a URDF, xacro fails, a package is unknown, a mesh is
            missing or an LFS pointer — each naming the file and, for meshes, the line of ``<mesh>``
            (in the source URDF; for xacro input, in the expanded text, whose file is the xacro's).
    """
    path = Path(path).resolve()
    index = index if index is not None else PackageIndex()
    return resolve_robot_text(path, process_xacro(path, xacro_args, index=index), index=index)


def resolve_robot_text(path: str | Path, text: str, *, index: PackageIndex) -> ResolvedRobot:
    """:func:`resolve_robot` for a description already read (xacro expanded) from ``path``.

    Raises:
        ConfigError: as :func:`resolve_robot`, xacro failures aside.
    """
    path = Path(path).resolve()
    try:
        root = _parse(text)
    except etree.XMLSyntaxError as exc:
        raise ConfigError(
            f"not valid XML: {exc.msg}", location=SourceLocation(str(path), exc.lineno or 0)
        ) from None
    if root.tag != "robot":
        raise ConfigError(
            f"not a URDF: the root element is <{root.tag}>, not <robot>", location=SourceLocation(str(path))
        )
    expanded = _is_xacro(path, text)
    meshes = []
    problems: list[tuple[SourceLocation, str]] = []
    missing_packages: dict[str, list[tuple[SourceLocation, str, str]]] = {}
    for link in root.iter("link"):
        for role in ("visual", "collision"):
            for element in link.findall(role):
                for mesh in element.findall("geometry/mesh"):
                    # Lines of xacro output are not lines of any file the user wrote.
                    where = SourceLocation(str(path), 0 if expanded else (mesh.sourceline or 0))
                    what = f"link {link.get('name')!r} ({role})"
                    uri = mesh.get("filename", "")
                    if not uri:
                        problems.append((where, f"{what}: <mesh> without a filename"))
                        continue
                    if uri.startswith("package://"):
                        package = uri[len("package://") :].partition("/")[0]
                        if index.find(package) is None:
                            missing_packages.setdefault(package, []).append((where, what, uri))
                            continue
                    try:
                        resolved = resolve_uri(uri, base_dir=path.parent, index=index, location=where)
                        check_mesh(resolved, location=where)
                    except ConfigError as exc:
                        problems.append((where, f"{what}: {exc.message}"))
                        continue
                    meshes.append(MeshReference(uri, resolved, link.get("name", ""), role, where))
    if problems or missing_packages:
        raise _mesh_problems(problems, missing_packages, index)
    return ResolvedRobot(source=path, urdf_text=text, name=root.get("name", path.stem), meshes=tuple(meshes))


def _mesh_problems(
    problems: list[tuple[SourceLocation, str]],
    missing_packages: dict[str, list[tuple[SourceLocation, str, str]]],
    index: PackageIndex,
) -> ConfigError:
    """One error for every mesh that cannot be used: a user fixes them all in one go."""
    uses = sum(len(u) for u in missing_packages.values())
    if len(problems) + uses == 1:
        if problems:
            where, message = problems[0]
            return ConfigError(message, location=where)
        ((package, [(where, what, uri)]),) = missing_packages.items()
        return ConfigError(f"{what}: {uri}: {index.not_found_message(package)}", location=where)
    lines = [f"{where}: {message}" for where, message in problems]
    for package, places in missing_packages.items():
        first_where, _, first_uri = places[0]
        lines.append(
            f"ROS package {package!r} not found, needed by {len(places)} mesh(es), first {first_uri} "
            f"at {first_where}; {did_you_mean(package, index.known_packages())}"
        )
    if missing_packages:
        lines.append(f"packages were looked for in: {'; '.join(index.searched())}")
    first = problems[0][0] if problems else next(iter(missing_packages.values()))[0][0]
    count = len(problems) + uses
    return ConfigError(
        f"{count} meshes of the robot cannot be used:\n  " + "\n  ".join(lines), location=first
    )
