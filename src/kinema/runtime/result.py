"""The typed outcome of one objective run, shared by the objective server and the SDK."""

from __future__ import annotations

from dataclasses import dataclass

from kinema.runtime.error_codes import MoveItErrorCode, error_code_name


@dataclass(frozen=True)
class ObjectiveResult:
    """How an objective run ended.

    Attributes:
        error_code: a ``MoveItErrorCodes`` value: 1 on success, -7 (PREEMPTED) when cancelled or replaced
            by a newer request, anything else on failure (99999 unless a more precise code applies).
        error_message: empty on success; otherwise what went wrong, naming the failing node path.
        objective_name: the objective that ran (the main tree ID for an XML string).
    """

    error_code: int
    error_message: str = ""
    objective_name: str = ""

    @property
    def succeeded(self) -> bool:
        """True when the objective finished with SUCCESS."""
        return self.error_code == MoveItErrorCode.SUCCESS

    @property
    def cancelled(self) -> bool:
        """True when the objective was cancelled or preempted by a newer one (PREEMPTED)."""
        return self.error_code == MoveItErrorCode.PREEMPTED

    @property
    def failed(self) -> bool:
        """True when the objective neither succeeded nor was cancelled."""
        return not (self.succeeded or self.cancelled)

    @property
    def code_name(self) -> str:
        """The symbolic name of :attr:`error_code`, e.g. ``"PREEMPTED"``."""
        return error_code_name(self.error_code)

    def __str__(self) -> str:
        name = f"{self.objective_name!r} " if self.objective_name else ""
        if self.succeeded:
            return f"objective {name}succeeded"
        if self.cancelled:
            detail = f": {self.error_message}" if self.error_message else ""
            return f"objective {name}was cancelled{detail}"
        # The runtime's messages name the objective already ("objective 'X' failed: node ..."): once will do.
        detail = self.error_message.removeprefix(f"objective {name}failed: ")
        return f"objective {name}failed ({self.code_name}): {detail}"

    @classmethod
    def success(cls, objective_name: str = "") -> ObjectiveResult:
        """A successful run."""
        return cls(MoveItErrorCode.SUCCESS, "", objective_name)

    @classmethod
    def preempted(cls, message: str, objective_name: str = "") -> ObjectiveResult:
        """A run that was cancelled or replaced before it finished."""
        return cls(MoveItErrorCode.PREEMPTED, message, objective_name)

    @classmethod
    def failure(
        cls, message: str, objective_name: str = "", code: int = MoveItErrorCode.FAILURE
    ) -> ObjectiveResult:
        """A run that failed (could not be loaded, or the tree returned FAILURE)."""
        return cls(int(code), message, objective_name)
