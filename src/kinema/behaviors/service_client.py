"""Behaviors that call a service and act on the response (MoveIt Pro's ``ServiceClientBehaviorBase``)."""

from __future__ import annotations

from typing import Any, ClassVar, Generic

from kinema.behaviors.asynchronous import AsyncBehavior
from kinema.behaviors.faults import BehaviorExecutionError, behavior_fault
from kinema.behaviors.interface_type import parametrize
from kinema.errors import TransportError
from kinema.interfaces.definition import RequestT, ResponseT


class ServiceClientBehavior(AsyncBehavior, Generic[RequestT, ResponseT]):
    """Calls one service per run: ``create_request`` → call → ``process_response``.

    Derive from ``ServiceClientBehavior[AddTwoInts.Request, AddTwoInts.Response]`` (the interface's
    classes from ``kinema.interfaces.typed``: ``process_response`` then gets a typed response that
    ``mypy --strict`` and editors know the fields of), or from ``ServiceClientBehavior["pkg/srv/Name"]``
    (untyped), or set :attr:`service_type`; override
    :meth:`create_request` and :meth:`process_response`; :meth:`get_service_name` reads the
    ``service_name`` port by default. The call runs off the tick thread; halting the node abandons it.
    A call that fails (no server, timeout, server error) publishes a failure toast and returns FAILURE.
    """

    __slots__ = ()

    service_type: ClassVar[str] = ""
    """The ROS service type, e.g. ``example_interfaces/srv/AddTwoInts``."""

    def __class_getitem__(cls, service_type: Any) -> Any:
        return parametrize(cls, "service_type", "srv", service_type, ("Request", "Response"))

    def get_service_name(self) -> str:
        """The service to call; default: the ``service_name`` input port.

        Called at the start of each run, off the tick thread. Must not block.
        """
        return str(self.get_input("service_name"))

    def create_request(self) -> RequestT | dict[str, Any]:
        """Build the request: a message, or a dict of its fields (missing fields take defaults).

        Called at the start of each run, off the tick thread, after :meth:`get_service_name`.
        """
        raise NotImplementedError(f"{type(self).__name__}.create_request() is not implemented")

    def process_response(self, response: ResponseT) -> bool:
        """Act on the response (write outputs, publish a toast); return True for SUCCESS.

        Called once per successful call, off the tick thread. Must not block for long.
        """
        raise NotImplementedError(f"{type(self).__name__}.process_response() is not implemented")

    def get_response_timeout(self) -> float:
        """Seconds to wait for the response (including for a server to appear); default 10."""
        return 10.0

    async def do_work(self) -> bool:
        """Call the service and process the response (no need to override)."""
        import asyncio

        if not self.service_type:
            raise BehaviorExecutionError(
                f"behavior '{self.registration_id}' does not say which service type it calls; derive "
                "from ServiceClientBehavior['pkg/srv/Name'] or set service_type"
            )
        node = self.context.require_node(self.registration_id)
        name = self.get_service_name()
        request = self.create_request()
        timeout = self.get_response_timeout()
        client = self.context.service_client(node, self.service_type, name)
        try:
            response = await asyncio.wrap_future(client.call_async(request, timeout))
        except TransportError as error:
            self.logger.publish_failure(f"Failed to call service {name}: {error}")
            return False
        try:
            return self.process_response(response)
        except Exception as error:
            raise behavior_fault(self, error, "process_response") from error
