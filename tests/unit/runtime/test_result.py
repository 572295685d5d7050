"""ObjectiveResult: the three outcomes a user tells apart."""

from __future__ import annotations

import pytest

from kinema.runtime.error_codes import MoveItErrorCode
from kinema.runtime.result import ObjectiveResult


@pytest.mark.parametrize(
    ("code", "succeeded", "cancelled", "failed"),
    [
        (1, True, False, False),
        (-7, False, True, False),
        (99999, False, False, True),
        (-4, False, False, True),
        (0, False, False, True),
    ],
)
def test_outcome_flags_follow_the_error_code(
    code: int, succeeded: bool, cancelled: bool, failed: bool
) -> None:
    result = ObjectiveResult(code, "msg", "X")
    assert (result.succeeded, result.cancelled, result.failed) == (succeeded, cancelled, failed)


def test_string_form_names_the_objective_and_the_code() -> None:
    assert str(ObjectiveResult.success("Pick")) == "objective 'Pick' succeeded"
    failed = ObjectiveResult.failure(
        "node 'Pick/Seq/Move' returned FAILURE", "Pick", MoveItErrorCode.CONTROL_FAILED
    )
    assert str(failed) == "objective 'Pick' failed (CONTROL_FAILED): node 'Pick/Seq/Move' returned FAILURE"
    assert "cancelled" in str(ObjectiveResult.preempted("by user", "Pick"))
    # The runtime's own message names the objective already: not twice.
    named = ObjectiveResult.failure("objective 'Pick' failed: node 'Move::2' [Move]: too far", "Pick")
    assert str(named) == "objective 'Pick' failed (FAILURE): node 'Move::2' [Move]: too far"
