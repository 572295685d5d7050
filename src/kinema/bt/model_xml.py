"""``<TreeNodesModel>`` export for Groot2 and editors (BT.CPP ``writeTreeNodesModelXML``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lxml import etree

from kinema.bt.manifest import NodeManifest
from kinema.bt.xmlparser import SubtreeModel

if TYPE_CHECKING:
    from kinema.bt.factory import BehaviorTreeFactory


def manifest_element(manifest: NodeManifest) -> etree._Element:
    """One model element: ``<Action ID="X"><input_port .../>...<MetadataFields/></Action>``."""
    element = etree.Element(manifest.category.value, ID=manifest.id)
    for port in manifest.ports.values():
        port_element = etree.SubElement(element, port.direction.xml_tag, name=port.name, type=port.type_name)
        if port.default_str is not None:
            port_element.set("default", port.default_str)
        if port.description:
            port_element.text = port.description
    if manifest.metadata:
        fields = etree.SubElement(element, "MetadataFields")
        for key, value in manifest.metadata:
            etree.SubElement(fields, "Metadata", {key: value})
    return element


def write_tree_nodes_model_xml(factory: BehaviorTreeFactory, include_builtin: bool = False) -> str:
    """The ``<root BTCPP_format="4"><TreeNodesModel>`` document of the factory's node types, sorted by ID."""
    root = etree.Element("root", BTCPP_format="4")
    models = etree.SubElement(root, "TreeNodesModel")
    for _, manifest in sorted(factory.manifests().items()):
        if manifest.builtin and not include_builtin:
            continue
        models.append(manifest_element(manifest))
    for tree_id in factory.registered_behavior_trees():
        model = factory.library.subtree_models.get(tree_id)
        if model is not None:
            models.append(subtree_model_element(model))
    etree.indent(root, space="    ")
    return etree.tostring(root, encoding="unicode") + "\n"


def subtree_model_element(model: SubtreeModel) -> etree._Element:
    """``<SubTree ID="X">`` with its ports (defaults, descriptions) and ``<MetadataFields>``."""
    element = etree.Element("SubTree", ID=model.id)
    for port in model.ports.values():
        port_element = etree.SubElement(element, port.direction.xml_tag, name=port.name)
        if port.default_str is not None:
            port_element.set("default", port.default_str)
        if port.description:
            port_element.set("description", port.description)
    if model.metadata:
        fields = etree.SubElement(element, "MetadataFields")
        for key, value in model.metadata:
            etree.SubElement(fields, "Metadata", {key: value})
    return element


def write_objective_xml(
    factory: BehaviorTreeFactory, tree_ids: list[str], main_tree: str | None = None
) -> str:
    """An objective file holding the loaded trees ``tree_ids``, written back with their metadata.

    Every attribute of each ``<BehaviorTree>`` and of its nodes (``_description``, ``_favorite``,
    ``_collapsed``, ...) is kept, as are comments inside the trees, and the ``<TreeNodesModel>``
    entries of those trees (ports, defaults, ``<MetadataFields>``). Loading the result gives the same
    trees and models.
    """
    import copy

    root = etree.Element("root", BTCPP_format="4")
    if main_tree is not None:
        root.set("main_tree_to_execute", main_tree)
    for tree_id in tree_ids:
        root.append(copy.deepcopy(factory.tree_definition(tree_id).element))
    models = [factory.library.subtree_models[t] for t in tree_ids if t in factory.library.subtree_models]
    if models:
        models_element = etree.SubElement(root, "TreeNodesModel")
        for model in models:
            models_element.append(subtree_model_element(model))
    for element in root.iter():
        element.tail = None
        if len(element) and element.text is not None and not element.text.strip():
            element.text = None
    etree.indent(root, space="  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + etree.tostring(root, encoding="unicode") + "\n"
