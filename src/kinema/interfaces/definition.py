"""Typed handles on service and action interfaces: what ``create_client`` and the client behaviors key on.

``kinema.interfaces.typed`` declares one class per bundled service and action, derived from
:class:`ServiceDefinition` or :class:`ActionDefinition` with its message classes as type arguments,
so a type checker follows a call from the interface to the fields of its response::

    from kinema.interfaces.typed import AddTwoInts

    client = node.create_client(AddTwoInts, "/add_two_ints")
    response = client.call(AddTwoInts.Request(a=1, b=2))  # an AddTwoInts.Response
    print(response.sum)

The message classes are the ones the transport builds messages with, so ``isinstance`` agrees with
the annotations. An interface of a behavior package gets the same typing by declaring such a class
(``type_name`` plus ``Request``/``Response`` aliases) next to its ``.srv`` file.
"""

from __future__ import annotations

from typing import Any, ClassVar, Generic, TypeVar

RequestT = TypeVar("RequestT")
ResponseT = TypeVar("ResponseT")
GoalT = TypeVar("GoalT")
ResultT = TypeVar("ResultT")
FeedbackT = TypeVar("FeedbackT")


class ServiceDefinition(Generic[RequestT, ResponseT]):
    """A service interface: derive with its request and response classes and set :attr:`type_name`.

    Subclasses alias the message classes as ``Request`` and ``Response`` (``Request: TypeAlias = ...``)
    so authors can write ``AddTwoInts.Response`` in annotations. Never instantiated.
    """

    type_name: ClassVar[str] = ""
    """The ROS type name, ``pkg/srv/Name``."""


class ActionDefinition(Generic[GoalT, ResultT, FeedbackT]):
    """An action interface: derive with its goal, result and feedback classes; set :attr:`type_name`.

    Subclasses alias the message classes as ``Goal``, ``Result`` and ``Feedback``. Never instantiated.
    """

    type_name: ClassVar[str] = ""
    """The ROS type name, ``pkg/action/Name``."""


def interface_type_name(interface: Any, kind: str) -> str:
    """The ROS type name of ``interface``: a ``pkg/<kind>/Name`` string or a definition class.

    Raises:
        TypeError: ``interface`` is neither (the caller turns it into its own error).
    """
    if isinstance(interface, str):
        return interface
    base = ServiceDefinition if kind == "srv" else ActionDefinition
    if isinstance(interface, type) and issubclass(interface, base) and interface.type_name:
        return interface.type_name
    raise TypeError(f"expected a 'pkg/{kind}/Name' string or a {base.__name__} class, got {interface!r}")
