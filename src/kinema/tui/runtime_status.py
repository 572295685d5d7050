"""What the status bar shows, kept up to date from heartbeats, ``/clock`` samples and connection changes.

Elapsed time is measured on the runtime's own clock (heartbeat process time), so it is right even when
the terminal is slow to draw, and deterministic in tests.
"""

from __future__ import annotations

from dataclasses import dataclass

from kinema.tui.connection import ClockSample, ConnectionChanged, ConnectionState, Heartbeat

ACTIVE_STATUSES = frozenset({"Loading", "Running"})
ENDED_STATUSES = frozenset({"Success", "Failure", "Cancelled"})


@dataclass
class RuntimeStatus:
    """The runtime as the status bar describes it."""

    state: ConnectionState = ConnectionState.CONNECTING
    endpoint: str = ""
    detail: str = ""
    objective: str = ""
    status: str = "Unknown"
    elapsed: float | None = None
    sim_time: float | None = None
    real_time_factor: float | None = None
    warnings: tuple[str, ...] = ()
    #: How the last run of :attr:`objective` ended, kept once the server says Idle again (a couple of
    #: seconds after the end): "" while it runs or before any run.
    last_outcome: str = ""
    _started_at: float | None = None
    _interrupted: tuple[str, float] | None = None

    @property
    def running(self) -> bool:
        """True while an objective is loading or running."""
        return self.status in ACTIVE_STATUSES

    def apply_connection(self, event: ConnectionChanged) -> None:
        """Take a connection change; a lost runtime forgets its objective and clock."""
        self.state = event.state
        self.endpoint = event.endpoint
        self.detail = event.detail
        if event.state is not ConnectionState.CONNECTED:
            if self.running and self._started_at is not None:
                # Heartbeats may only have been late: the same run resuming keeps its start time.
                self._interrupted = (self.objective, self._started_at)
            self.status = "Unknown"
            self.warnings = ()
            self.sim_time = None
            self.real_time_factor = None
            self._started_at = None

    def apply_heartbeat(self, beat: Heartbeat) -> bool:
        """Take a heartbeat; returns True when a new run started (so per-run views reset)."""
        started = beat.status in ACTIVE_STATUSES and (
            self.status not in ACTIVE_STATUSES or beat.objective_name != self.objective
        )
        if started and self._interrupted is not None and self._interrupted[0] == beat.objective_name:
            started = False
            self._started_at = self._interrupted[1]
        elif started:
            self._started_at = beat.process_time
        self._interrupted = None
        if self._started_at is not None and (
            beat.status in ACTIVE_STATUSES or self.status in ACTIVE_STATUSES
        ):
            self.elapsed = max(0.0, beat.process_time - self._started_at)
        if started or beat.objective_name != self.objective:
            self.last_outcome = ""
        if beat.status in ENDED_STATUSES:
            self.last_outcome = beat.status
        self.objective = beat.objective_name
        self.status = beat.status
        self.warnings = beat.warnings
        if self.state is not ConnectionState.CONNECTED:
            self.state = ConnectionState.CONNECTED
        return started

    def apply_clock(self, sample: ClockSample) -> None:
        """Take a ``/clock`` sample."""
        self.sim_time = sample.sim_time
        self.real_time_factor = sample.real_time_factor
