"""``<TreeNodesModel>`` export for Groot2 and editors (BT.CPP ``writeTreeNodesModelXML``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lxml import etree

from kinema.bt.manifest import NodeManifest

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
        if model is None:
            continue
        element = etree.SubElement(models, "SubTree", ID=tree_id)
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
    etree.indent(root, space="    ")
    return etree.tostring(root, encoding="unicode") + "\n"
