"""The tutorial's behaviors, loaded by ``kinema::ExampleBehaviorsLoader``."""

from __future__ import annotations

from kinema.plugins import RegisterBehavior, hookimpl

from .my_add_two_ints_service_client import MyAddTwoIntsServiceClient
from .my_behavior import MyBehavior


@hookimpl
def register_behaviors(register: RegisterBehavior) -> None:
    """Register MyBehavior and MyServiceClient."""
    register(MyBehavior)
    register(MyAddTwoIntsServiceClient, "MyServiceClient")
