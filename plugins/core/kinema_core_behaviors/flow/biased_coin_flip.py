"""BiasedCoinFlip: succeed with a given probability."""

from __future__ import annotations

import math
import random

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.ports import fails_on_bad_input, port_error, read_input


class BiasedCoinFlip(SyncBehavior):
    """Succeeds with probability ``success_probability``, else fails; e.g. to pick one of two branches
    of a Fallback at random.

    0 always fails and 1 always succeeds. Each tick draws anew from Python's ``random`` module (seed it
    with ``random.seed`` for a repeatable run). A value outside [0, 1] fails with a failure message.
    """

    subcategory = "Miscellaneous"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "success_probability",
                float,
                0.5,
                "Probability of SUCCESS, in [0, 1] (default 0.5: a fair coin).",
            )
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        probability = float(read_input(self, "success_probability"))
        if not (math.isfinite(probability) and 0.0 <= probability <= 1.0):
            raise port_error(
                self,
                "success_probability",
                f"= {probability:g} is not a probability",
                "give a value in [0, 1]",
            )
        # random() is in [0, 1): 0 never succeeds, 1 always does.
        return NodeStatus.SUCCESS if random.random() < probability else NodeStatus.FAILURE
