"""The objective library of a resolved config: every objective XML under its ``objective_library_paths``.

Every ``*.xml`` file under each library folder (sub-folders included, hidden files skipped) is read.
A file that cannot be read or parsed is recorded in :attr:`ObjectiveLibrary.errors` as
``file:line: message`` and the other files still load.

When several libraries define the same objective ID, the one from the most-derived package wins: a
library folder ranks by the position of its owning package in the inheritance chain (packages outside
the chain, such as the core objective library, rank below all of it), and among folders of equal rank
the one declared later in config.yaml wins. The winner lists the files it shadows; the notices say so
(verbose output).

Saving (:meth:`ObjectiveLibrary.save`) writes into the most-derived package's own library, atomically,
and carries over the metadata of the objective it replaces when the new XML leaves it out.
"""

from __future__ import annotations

import copy
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from kinema.bt.xmlsource import parse_xml
from kinema.config.atomic_write import atomic_write_text
from kinema.config.inheritance import LibraryPath, ResolvedConfig
from kinema.config.objective_file import ObjectiveInfo, ObjectivePort, objectives_of, parse_objective_file
from kinema.errors import ObjectiveError, SourceLocation, did_you_mean

__all__ = ["ObjectiveInfo", "ObjectiveLibrary", "ObjectivePort", "objective_file_name"]

_UNSAFE_IN_FILE_NAME = re.compile(r"[^\w\-.]+")
#: MoveIt Pro's example workspace lint: "if everything is favorited, nothing is favorited".
MAX_FAVORITES_PER_PACKAGE = 8
_KEPT_TREE_ATTRIBUTES = ("_description", "_favorite", "_subtreeOnly", "_hardcoded")


def objective_file_name(objective_id: str) -> str:
    """MoveIt Pro's file name for an objective: ``"Scan Scene - Two"`` -> ``scan_scene_-_two.xml``."""
    stem = _UNSAFE_IN_FILE_NAME.sub("_", objective_id.strip().lower()).strip("._") or "objective"
    return f"{stem}.xml"


@dataclass
class ObjectiveLibrary:
    """The objectives a config can run or use as subtrees.

    Attributes:
        libraries: the library folders, least-derived first (the order they were loaded in).
        objectives: objective ID -> the winning :class:`ObjectiveInfo`.
        errors: files that could not be read, as ObjectiveErrors (``str()`` gives ``file:line: message``).
        notices: shadowed objectives and soft problems (verbose output).
        warnings: problems worth saying always: an objective ID defined in two files of one library folder.
        resolved: the config the library was built for (None for a library built from folders).
    """

    libraries: list[LibraryPath]
    objectives: dict[str, ObjectiveInfo] = field(default_factory=dict)
    errors: list[ObjectiveError] = field(default_factory=list)
    notices: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    resolved: ResolvedConfig | None = None
    # file -> when it was first read: files() registers them in this order
    _load_order: dict[Path, int] = field(default_factory=dict, repr=False)

    @classmethod
    def load(cls, resolved: ResolvedConfig) -> ObjectiveLibrary:
        """Load every objective of ``resolved``'s merged ``objective_library_paths``."""
        library = cls.from_libraries(resolved.objective_library_paths, resolved.chain)
        library.resolved = resolved
        return library

    @classmethod
    def from_libraries(cls, libraries: list[LibraryPath], chain: list[str]) -> ObjectiveLibrary:
        """Load the given library folders; ``chain`` (root first) ranks them for duplicate IDs."""
        ranked = sorted(
            enumerate(libraries),
            key=lambda item: (chain.index(item[1].package) if item[1].package in chain else -1, item[0]),
        )
        by_folder: dict[Path, LibraryPath] = {}
        for _, library_path in ranked:
            # A folder listed twice (MoveIt Pro's sub-libraries folded into Kinema's one) loads once, at
            # its highest rank.
            by_folder.pop(library_path.path.resolve(), None)
            by_folder[library_path.path.resolve()] = library_path
        library = cls(libraries=list(by_folder.values()))
        for library_path in library.libraries:
            for xml_file in _xml_files(library_path.path):
                library._add_file(xml_file, library_path.package, folder=library_path.path)
        library._note_favorites()
        return library

    def _note_favorites(self) -> None:
        """Note MoveIt Pro's favorite rules: never on a subtree-only objective, at most 8 per package."""
        per_package: dict[str, int] = {}
        for info in self.objectives.values():
            if info.favorite:
                per_package[info.package] = per_package.get(info.package, 0) + 1
                if not info.runnable:
                    self.notices.append(f"{info.location}: {info.id!r} is a favorite but not runnable")
        for package, count in sorted(per_package.items()):
            if count > MAX_FAVORITES_PER_PACKAGE:
                self.notices.append(
                    f"package {package} has {count} favorite objectives; "
                    f"more than {MAX_FAVORITES_PER_PACKAGE} makes favorites meaningless"
                )

    def get(self, objective_id: str) -> ObjectiveInfo:
        """Return the objective ``objective_id``.

        Raises:
            ObjectiveError: unknown ID; the message lists the closest IDs.
        """
        found = self.objectives.get(objective_id)
        if found is None:
            raise ObjectiveError(
                f"no objective named {objective_id!r}; {did_you_mean(objective_id, self.objectives)}"
            )
        return found

    def __contains__(self, objective_id: object) -> bool:
        return objective_id in self.objectives

    def __len__(self) -> int:
        return len(self.objectives)

    def sorted(self) -> list[ObjectiveInfo]:
        """The objectives sorted by ID (case-insensitively)."""
        return sorted(self.objectives.values(), key=lambda info: info.id.lower())

    def files(self) -> list[Path]:
        """The files that define at least one winning objective, in load order (least-derived first).

        Registering them in this order lets each file's trees replace those of the files before it, so a
        BehaviorTree factory ends up with every winning definition even when a parent's file that still
        wins for another objective also defines one its child overrides.
        """
        winning = dict.fromkeys(info.file for info in self.objectives.values())
        order = self._load_order
        return sorted(winning, key=lambda path: order.get(path, len(order)))

    def unreadable(self, path: Path) -> bool:
        """True when ``path`` is one of the files this library could not read (see :attr:`errors`)."""
        where = str(path)
        return any(error.location is not None and error.location.file == where for error in self.errors)

    def keep(self, path: Path, infos: list[ObjectiveInfo]) -> list[ObjectiveInfo]:
        """Take back ``infos``, the objectives ``path`` defined when it last read, for a file that no
        longer reads (its error stays in :attr:`errors`); an ID another file now defines is left to it.
        Returns the objectives taken back."""
        kept = [info for info in infos if info.id not in self.objectives]
        for info in kept:
            self.objectives[info.id] = info
        if kept:
            self._load_order.setdefault(path, len(self._load_order))
        return kept

    def own_library(self) -> LibraryPath:
        """The first library folder owned by the most-derived config package (where saves go).

        Raises:
            ObjectiveError: the config has no library folder of its own.
        """
        if self.resolved is None:
            raise ObjectiveError(
                "this objective library was not built for a config, so it has no place to save to"
            )
        name = self.resolved.name
        for library_path in self.resolved.objective_library_paths:
            if library_path.package == name:
                return library_path
        raise ObjectiveError(
            f"config {name!r} has no objective library of its own, so there is nowhere to save "
            "objectives; add "
            f"`{name}_objectives: {{package_name: {name}, relative_path: objectives}}` under "
            "objectives.objective_library_paths",
            location=self.resolved.location_of("objectives.objective_library_paths"),
        )

    def save(self, objective_id: str, xml_text: str) -> ObjectiveInfo:
        """Save an objective into the most-derived package's library, atomically.

        The objective keeps the metadata of the one it replaces (``_description``, ``_favorite``, its
        TreeNodesModel entry with ports and ``MetadataFields``) when ``xml_text`` leaves them out. An
        objective already in the package's own library is overwritten in place; one inherited from
        another package is shadowed by a new file named after the ID.

        Args:
            objective_id: the objective's name (``<BehaviorTree ID>``).
            xml_text: a whole objective document (``<root>``) or a single ``<BehaviorTree>`` element.

        Returns:
            The saved objective as now loaded.

        Raises:
            ObjectiveError: invalid XML, the ID is not defined in ``xml_text``, or the config has no
                library of its own.
        """
        target_library = self.own_library()
        root = parse_xml(xml_text, f"<objective {objective_id!r}>")
        if root.tag == "BehaviorTree":
            wrapper = etree.Element("root", BTCPP_format="4")
            wrapper.append(root)
            root = wrapper
        trees = [element for element in root if element.tag == "BehaviorTree"]
        tree = next((element for element in trees if element.get("ID") == objective_id), None)
        if tree is None:
            if len(trees) == 1 and not trees[0].get("ID"):
                tree = trees[0]
                tree.set("ID", objective_id)
            else:
                found = ", ".join(repr(element.get("ID")) for element in trees) or "no <BehaviorTree>"
                raise ObjectiveError(
                    f"the XML to save does not define the objective {objective_id!r} (it has {found})"
                )
        previous = self.objectives.get(objective_id)
        if previous is not None:
            _carry_metadata(previous, tree, root, objective_id)
        root.set("BTCPP_format", root.get("BTCPP_format", "4"))
        if root.get("main_tree_to_execute") is None:
            root.set("main_tree_to_execute", objective_id)
        objectives_of(root, Path(f"<objective {objective_id!r}>"))  # same checks as loading, before writing
        if (
            previous is not None
            and previous.package == target_library.package
            and _inside(previous.file, target_library.path)
        ):
            destination = previous.file
            # A file holding other objectives too keeps them: only this objective's trees are replaced.
            root = _merged_into_file(previous, root)
        else:
            destination = self._free_file_name(target_library.path, objective_id)
        etree.indent(root, space="  ")
        text = '<?xml version="1.0" encoding="UTF-8" ?>\n' + etree.tostring(root, encoding="unicode") + "\n"
        try:
            destination.parent.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise ObjectiveError(
                f"cannot create the folder: {error.strerror}",
                location=SourceLocation(str(destination.parent)),
            ) from None
        atomic_write_text(destination, text, error=ObjectiveError)
        for info in self._add_file(destination, target_library.package, replace=True):
            if info.id == objective_id:
                return info
        raise ObjectiveError(
            f"{destination} was written but does not load back", location=SourceLocation(str(destination))
        )

    def _free_file_name(self, folder: Path, objective_id: str) -> Path:
        name = objective_file_name(objective_id)
        candidate = folder / name
        taken = {info.file.resolve() for info in self.objectives.values() if info.id != objective_id}
        counter = 2
        while candidate.resolve() in taken or (
            candidate.exists() and not self._defines(candidate, objective_id)
        ):
            candidate = folder / f"{Path(name).stem}_{counter}.xml"
            counter += 1
        return candidate

    @staticmethod
    def _defines(path: Path, objective_id: str) -> bool:
        try:
            return any(info.id == objective_id for info in parse_objective_file(path).objectives)
        except ObjectiveError:
            return False

    def _add_file(
        self, path: Path, package: str, *, replace: bool = False, folder: Path | None = None
    ) -> list[ObjectiveInfo]:
        """Read ``path`` (of library ``folder``, in ``package``) into the library; its objectives."""
        try:
            parsed = parse_objective_file(path)
        except ObjectiveError as error:
            self.errors.append(error)
            return []
        self.notices.extend(parsed.warnings)
        self._load_order.setdefault(path, len(self._load_order))
        for info in parsed.objectives:
            info.package = package
            previous = self.objectives.get(info.id)
            if previous is not None and previous.file != path:
                info.shadows = [*previous.shadows, previous.file]
                if folder is not None and previous.file.resolve().is_relative_to(folder.resolve()):
                    # Two files of one library folder, not a library overriding another's: a copy that
                    # kept its ID, most of the time. Files load in name order; the last one wins.
                    self.warnings.append(
                        f"{info.location}: objective {info.id!r} is defined again in the library "
                        f"{folder} (first at {previous.location}); this one is used. Give each objective "
                        "its own ID"
                    )
                elif not replace:
                    self.notices.append(
                        f"{info.location}: objective {info.id!r} from {package} shadows the one in "
                        f"{previous.package} ({previous.location})"
                    )
            elif previous is not None:
                info.shadows = previous.shadows
            self.objectives[info.id] = info
        return parsed.objectives


def _xml_files(folder: Path) -> list[Path]:
    """Every ``*.xml`` file under ``folder``, sorted, leaving out hidden files and folders."""
    found: list[Path] = []
    # os.walk reads file types from the directory entries, so listing costs no stat per file.
    for current, folders, files in os.walk(folder):
        folders[:] = [name for name in folders if not name.startswith(".")]
        base = Path(current)
        found.extend(base / name for name in files if name.endswith(".xml") and not name.startswith("."))
    return sorted(found)


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
    except ValueError:
        return False
    return True


def _merged_into_file(previous: ObjectiveInfo, new_root: etree._Element) -> etree._Element:
    """Return the document of ``previous.file`` with the trees and models of ``new_root`` put in place
    of those with the same IDs; ``new_root`` itself when that file holds nothing else."""
    try:
        old_root = parse_xml(previous.read_xml(), str(previous.file))
    except ObjectiveError:
        return new_root  # the old file is unreadable: the new document replaces it
    new_trees = {e.get("ID"): e for e in new_root if e.tag == "BehaviorTree"}
    if all(e.get("ID") in new_trees for e in old_root if e.tag == "BehaviorTree"):
        return new_root
    for tree_id, tree in new_trees.items():
        old = next((e for e in old_root if e.tag == "BehaviorTree" and e.get("ID") == tree_id), None)
        if old is None:
            old_root.append(tree)
        else:
            old_root.replace(old, tree)
    new_models = [s for m in new_root.iter("TreeNodesModel") for s in m if s.tag == "SubTree"]
    if new_models:
        models = next(iter(old_root.iter("TreeNodesModel")), None)
        if models is None:
            models = etree.SubElement(old_root, "TreeNodesModel")
        for model in new_models:
            old = next(
                (
                    s
                    for m in old_root.iter("TreeNodesModel")
                    for s in m
                    if s.tag == "SubTree" and s.get("ID") == model.get("ID")
                ),
                None,
            )
            if old is None:
                models.append(model)
            else:
                old.getparent().replace(old, model)
    return old_root


def _carry_metadata(
    previous: ObjectiveInfo, tree: etree._Element, root: etree._Element, objective_id: str
) -> None:
    """Copy the previous version's metadata into the new document where the new one has none."""
    try:
        old_root = parse_xml(previous.read_xml(), str(previous.file))
    except ObjectiveError:
        return  # the old file became unreadable; the new XML stands on its own
    old_tree = next((e for e in old_root if e.tag == "BehaviorTree" and e.get("ID") == objective_id), None)
    if old_tree is not None:
        for attribute in _KEPT_TREE_ATTRIBUTES:
            if attribute in old_tree.attrib and attribute not in tree.attrib:
                tree.set(attribute, old_tree.get(attribute))
    old_model = next(
        (
            s
            for m in old_root.iter("TreeNodesModel")
            for s in m
            if s.tag == "SubTree" and s.get("ID") == objective_id
        ),
        None,
    )
    if old_model is None:
        return
    new_model = next(
        (
            s
            for m in root.iter("TreeNodesModel")
            for s in m
            if s.tag == "SubTree" and s.get("ID") == objective_id
        ),
        None,
    )
    if new_model is None:
        models = next(iter(root.iter("TreeNodesModel")), None)
        if models is None:
            models = etree.SubElement(root, "TreeNodesModel")
        models.append(copy.deepcopy(old_model))
        return
    if not any(child.tag == "MetadataFields" for child in new_model):
        for child in old_model:
            if child.tag == "MetadataFields":
                new_model.append(copy.deepcopy(child))
