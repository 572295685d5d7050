"""The physics thread: steps MuJoCo, runs the controllers, paces sim time against wall time.

Only this thread touches ``MjData`` (and the few model fields controllers change). Other threads hand
it work with :meth:`Simulation.submit`: a callable queued in order and run between two steps, whose
result comes back through a future. The queue is drained before every step, so a command (a cancel,
say) takes effect within one physics step of sim time, however fast the simulation runs.

Pacing: with a finite speed factor the loop sleeps after each publish period until wall time catches up
with ``sim time / factor``; when it falls behind by more than :data:`MAX_LAG` it stops trying to catch
up (sim time slows down rather than jumping). With ``max`` it never sleeps.
"""

from __future__ import annotations

import collections
import concurrent.futures
import logging
import math
import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from kinema.errors import DriverError

log = logging.getLogger(__name__)

T = TypeVar("T")

# Wall-time lag (s) beyond which a paced simulation re-anchors instead of racing to catch up.
MAX_LAG = 0.1


class Simulation:
    """Steps ``data`` on a thread of its own.

    Args:
        model: the ``mujoco.MjModel``.
        data: its ``mujoco.MjData`` (owned by the physics thread once started).
        speed: sim seconds per wall second; ``math.inf`` runs as fast as possible.
        publish_period: sim seconds between calls of ``on_publish``.
        before_step: called before every ``mj_step`` (the controllers' update).
        on_publish: called every ``publish_period`` of sim time, after stepping (topics, feedback).
    """

    def __init__(
        self,
        model: Any,
        data: Any,
        *,
        speed: float,
        publish_period: float,
        before_step: Callable[[], None],
        on_publish: Callable[[], None],
    ) -> None:
        self.model = model
        self.data = data
        self.speed = speed
        self.steps_per_publish = max(1, round(publish_period / model.opt.timestep))
        self._before_step = before_step
        self._on_publish = on_publish
        self._commands: collections.deque[tuple[Callable[[], Any], concurrent.futures.Future[Any]]] = (
            collections.deque()
        )
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._failure: BaseException | None = None
        self.sim_time = float(data.time)
        self.steps = 0
        self.wall_started = 0.0

    @property
    def running(self) -> bool:
        """True while the physics thread runs."""
        return self._thread is not None and self._thread.is_alive()

    @property
    def failure(self) -> BaseException | None:
        """The exception that ended the physics thread, if any."""
        return self._failure

    def start(self) -> None:
        """Start the physics thread."""
        if self._thread is not None:
            raise DriverError("the simulation was already started")
        self._thread = threading.Thread(target=self._run, name="kinema-mujoco-physics", daemon=True)
        self.wall_started = time.perf_counter()
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop the physics thread (pending commands fail with a DriverError)."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)
        self._fail_pending(DriverError("the simulation stopped"))

    def submit(self, command: Callable[[], T]) -> concurrent.futures.Future[T]:
        """Run ``command()`` on the physics thread before its next step; the future holds its result.

        Raises:
            DriverError: the simulation is not running.
        """
        future: concurrent.futures.Future[T] = concurrent.futures.Future()
        if not self.running or self._stop.is_set():
            raise DriverError(self._not_running())
        self._commands.append((command, future))
        # The thread may have ended between the check and the append; never leave a future hanging.
        if not self.running:
            self._fail_pending(DriverError(self._not_running()))
        return future

    def call(self, command: Callable[[], T], timeout: float = 5.0) -> T:
        """Run ``command()`` on the physics thread and return its result (or raise its exception).

        Raises:
            DriverError: the simulation is not running or did not answer within ``timeout``.
        """
        future = self.submit(command)
        try:
            return future.result(timeout)
        except concurrent.futures.TimeoutError:
            raise DriverError(f"the simulation did not answer within {timeout:g} s") from None

    # -- the physics thread ------------------------------------------------------------------------

    def _not_running(self) -> str:
        if self._failure is not None:
            return f"the simulation stopped after an error: {self._failure}"
        return "the simulation is not running"

    def _drain(self) -> None:
        commands = self._commands
        while commands:
            command, future = commands.popleft()
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(command())
            except BaseException as error:
                future.set_exception(error)

    def _fail_pending(self, error: BaseException) -> None:
        while self._commands:
            _command, future = self._commands.popleft()
            if future.set_running_or_notify_cancel():
                future.set_exception(error)

    def _run(self) -> None:
        import mujoco

        model, data = self.model, self.data
        step = mujoco.mj_step
        before_step = self._before_step
        drain = self._drain
        commands = self._commands
        wall_anchor = time.perf_counter()
        sim_anchor = float(data.time)
        try:
            while not self._stop.is_set():
                for _ in range(self.steps_per_publish):
                    if commands:
                        drain()
                    before_step()
                    step(model, data)
                self.steps += self.steps_per_publish
                self.sim_time = float(data.time)
                self._on_publish()
                if math.isinf(self.speed):
                    continue
                due = wall_anchor + (self.sim_time - sim_anchor) / self.speed
                delay = due - time.perf_counter()
                if delay > 0.0:
                    # Sleep on the stop event so stop() is prompt; commands wait for the next step.
                    self._stop.wait(delay)
                elif delay < -MAX_LAG:
                    wall_anchor, sim_anchor = time.perf_counter(), self.sim_time
        except BaseException as error:
            self._failure = error
            log.exception("the physics thread stopped after an error")
        finally:
            self._fail_pending(DriverError(self._not_running()))
