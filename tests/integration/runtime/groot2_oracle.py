"""Shared by the Groot2 and .btlog tests: the BT.CPP oracle (behaviortreepy), ports, XML comparison."""

from __future__ import annotations

import socket
import struct
from typing import Any

import pytest
from lxml import etree

# Built-in nodes only, so BT.CPP (behaviortreepy) builds the very same tree: a subtree with remapped
# ports, scripts writing ints, doubles and strings, a node that keeps running, and a failing branch.
RUNNING_XML = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="steps">
      <Script code="count:=1; label:='hi'; ratio:=2.5" />
      <SetBlackboard value="1;2;3" output_key="items"/>
      <SubTree ID="AddOne" value="{count}" result="{sum}"/>
      <Fallback name="pick">
        <AlwaysFailure name="first_try"/>
        <KeepRunningUntilFailure name="hold"><AlwaysSuccess/></KeepRunningUntilFailure>
      </Fallback>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="AddOne">
    <Sequence>
      <Script code="result:=value+1; note:='inner'"/>
      <AlwaysSuccess name="done"/>
    </Sequence>
  </BehaviorTree>
</root>"""

FAILING_XML = """<root BTCPP_format="4" main_tree_to_execute="Fails">
  <BehaviorTree ID="Fails">
    <Sequence name="seq">
      <Script code="a:=1; s:='text'" />
      <SubTree ID="Inner" x="{a}" />
      <Inverter><AlwaysSuccess name="ok"/></Inverter>
      <AlwaysSuccess name="never"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Inner"><Sequence><Script code="y:=x+1"/><AlwaysSuccess/></Sequence></BehaviorTree>
</root>"""


def btcpp() -> Any:
    """behaviortreepy with Groot2 support, or skip."""
    module = pytest.importorskip("behaviortreepy", reason="behaviortreepy (BT.CPP) is the oracle")
    if not getattr(module, "GROOT2_AVAILABLE", False):
        pytest.skip("this behaviortreepy build has no Groot2Publisher")
    return module


def btcpp_tree(xml: str, main: str) -> Any:
    factory = btcpp().BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(xml)
    return factory.create_tree(main)


def kinema_tree(xml: str, main: str) -> Any:
    from kinema.bt import BehaviorTreeFactory

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(xml)
    return factory.create_tree(main)


def free_port_pair() -> int:
    """A port p such that p and p + 1 are both free on loopback now (Groot2 uses both)."""
    from kinema.transport import free_endpoint

    for _ in range(50):
        port = int(free_endpoint().rsplit(":", 1)[1])
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", port + 1))
            except OSError:
                continue
        return port
    raise RuntimeError("no two consecutive free ports on 127.0.0.1")


class Groot2Client:
    """What Groot2 does on the wire: REQ socket, 6-byte header, multipart replies."""

    def __init__(self, port: int) -> None:
        import zmq

        self._context = zmq.Context()
        self._socket = self._context.socket(zmq.REQ)
        self._socket.setsockopt(zmq.RCVTIMEO, 10_000)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.connect(f"tcp://127.0.0.1:{port}")
        self._id = 1000

    def request(self, kind: str, *parts: bytes) -> list[bytes]:
        self._id += 1
        self._socket.send_multipart([struct.pack("<BBI", 2, ord(kind), self._id), *parts])
        reply = self._socket.recv_multipart()
        if reply[0] != b"error":
            assert reply[0][:6] == struct.pack("<BBI", 2, ord(kind), self._id), reply[0]
        return reply

    def tree_id(self) -> bytes:
        return self.request("S")[0][6:]

    def close(self) -> None:
        self._socket.close()
        self._context.term()


def tree_shape(xml: str) -> list[Any]:
    """The ``<BehaviorTree>`` elements as nested (tag, sorted attributes, children): attribute order out."""

    def shape(element: Any) -> Any:
        return (element.tag, sorted(element.attrib.items()), [shape(child) for child in element])

    root = etree.fromstring(xml.encode())
    return [shape(tree) for tree in root.iter("BehaviorTree")]


def node_models(xml: str) -> dict[str, tuple[str, set[tuple[str, str, str | None]]]]:
    """``ID -> (category, {(direction, port name, default)})`` of the ``<TreeNodesModel>``."""
    root = etree.fromstring(xml.encode())
    models = {}
    for model in root.find("TreeNodesModel"):
        ports = {(p.tag, p.get("name"), p.get("default")) for p in model if p.tag.endswith("_port")}
        models[model.get("ID")] = (model.tag, ports)
    return models


def assert_same_tree_xml(kinema_xml: str, btcpp_xml: str) -> None:
    """Same trees up to attribute order; every BT.CPP node model present with the same ports."""
    assert tree_shape(kinema_xml) == tree_shape(btcpp_xml), f"kinema:\n{kinema_xml}\nBT.CPP:\n{btcpp_xml}"
    ours, theirs = node_models(kinema_xml), node_models(btcpp_xml)
    missing = sorted(set(theirs) - set(ours))
    assert not missing, f"node models BT.CPP sends and Kinema does not: {missing}"
    different = {i: (ours[i], theirs[i]) for i in theirs if ours[i] != theirs[i]}
    assert not different, f"node models that differ (kinema, BT.CPP): {different}"
