"""``<TreeNodesModel>`` export for Groot2 and editors (BT.CPP ``writeTreeNodesModelXML``)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from lxml import etree

from kinema.bt.decorators import SubTreeNode
from kinema.bt.manifest import NodeManifest
from kinema.bt.node import TreeNode, node_children
from kinema.bt.xmlparser import SubtreeModel

if TYPE_CHECKING:
    from kinema.bt.factory import BehaviorTreeFactory
    from kinema.bt.tree import Tree


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


def _node_element(node: TreeNode, subtree_paths: dict[int, str], add_metadata: bool) -> etree._Element:
    config = node.config
    if isinstance(node, SubTreeNode):
        element = etree.Element("SubTree", ID=node.subtree_id)
        element.set("_fullpath", subtree_paths.get(node.uid, ""))
    else:
        element = etree.Element(node.registration_id, name=node.name)
    if add_metadata:
        element.set("_uid", str(node.uid))
    # Read from the slots: NodeConfig makes an empty map on first use, and a tree written for every
    # run need not make four per node (None stands for empty).
    inputs = config._input_ports or _NOTHING
    for port, value in inputs.items():
        if isinstance(value, str):
            element.set(port, value)
    for port, value in (config._output_ports or _NOTHING).items():
        if isinstance(value, str) and port not in inputs:
            element.set(port, value)
    for conditions in (config._pre_conditions, config._post_conditions):
        for key, script in (conditions or _NOTHING).items():
            element.set(key, script.code)
    return element


_NOTHING: dict[str, Any] = {}


def write_tree_to_xml(tree: Tree, add_metadata: bool = True, add_builtin_models: bool = True) -> str:
    """The instantiated tree as XML (BT.CPP ``WriteTreeToXML``, what Groot2 receives).

    One ``<BehaviorTree ID _fullpath>`` per subtree instance, nodes in compact form with their
    instance ``name`` (a ``<SubTree>`` gets ``ID`` and ``_fullpath``), ``_uid`` when
    ``add_metadata``, every port value (declared defaults included) and the pre/post-condition
    scripts, followed by the ``<TreeNodesModel>`` of the node types.
    """
    root = etree.Element("root", BTCPP_format="4")
    # The subtree instance each SubTree node opened: instances are created right after their node.
    subtree_paths: dict[int, str] = {}
    for subtree in tree.subtrees[1:]:
        parent_path, _, _ = subtree.instance_name.rpartition("/")
        for candidate in tree.subtrees:
            if candidate.instance_name != parent_path:
                continue
            for node in candidate.nodes:
                if isinstance(node, SubTreeNode) and node.child is subtree.nodes[0]:
                    subtree_paths[node.uid] = subtree.instance_name
    for subtree in tree.subtrees:
        tree_element = etree.SubElement(root, "BehaviorTree", ID=subtree.tree_id)
        tree_element.set("_fullpath", subtree.instance_name)
        if not subtree.nodes:
            continue
        stack: list[tuple[TreeNode, etree._Element]] = [(subtree.nodes[0], tree_element)]
        while stack:
            node, parent_element = stack.pop()
            element = _node_element(node, subtree_paths, add_metadata)
            parent_element.append(element)
            if not isinstance(node, SubTreeNode):
                for child in reversed(node_children(node)):
                    stack.append((child, element))
    models = etree.SubElement(root, "TreeNodesModel")
    for _, manifest in sorted(tree.manifests.items()):
        if manifest.builtin and not add_builtin_models:
            continue
        models.append(manifest_element(manifest))
    etree.indent(root, space="    ")
    return etree.tostring(root, encoding="unicode") + "\n"
