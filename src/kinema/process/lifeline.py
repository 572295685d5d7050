"""A child's lifeline to the ``kinema run`` supervisor: when the supervisor dies, the child ends.

The supervisor holds the write end of one pipe and never writes to it; every child it starts inherits the
read end, named in the ``KINEMA_LIFELINE`` environment variable. The kernel closes the write end when the
supervisor exits — cleanly, by an exception, or by SIGKILL — and a thread in each child, blocked reading,
sees end-of-file at once. The child then stops as if it had received SIGTERM (its own clean shutdown) and,
if it is still there :data:`GRACE_S` later (a shutdown that waits for a router that died with the
supervisor), ends with ``os._exit`` — or, should the interpreter be finalizing or stuck in C code, by an
unhandled SIGALRM the kernel delivers. So a killed launcher never leaves a simulation or an agent running on
the robot's network. This works on every POSIX system; Linux's parent-death signal, which the supervisor
also asks for, is only the faster path.
"""

from __future__ import annotations

import logging
import os
import signal
import stat
import threading
import time

log = logging.getLogger("kinema.lifeline")

ENV = "KINEMA_LIFELINE"
GRACE_S = 1.0


class Lifeline:
    """The supervisor's side: one pipe whose read end every child inherits. Close it after the children."""

    def __init__(self) -> None:
        # os.pipe() makes both ends non-inheritable: only the read end is passed on, by pass_fds.
        self.read_fd, self._write_fd = os.pipe()

    def child_env(self) -> dict[str, str]:
        """Environment entries that hand the lifeline to a child (also pass ``read_fd`` in ``pass_fds``)."""
        return {ENV: f"{self.read_fd}:{os.getpid()}"}

    def close(self) -> None:
        """Close both ends (children still running see the supervisor as gone)."""
        for fd in (self.read_fd, self._write_fd):
            try:
                os.close(fd)
            except OSError:
                pass
        self.read_fd = self._write_fd = -1


def hold(grace: float = GRACE_S) -> bool:
    """In a child: stop this process when the supervisor that started it dies.

    Call it early in the child's ``main`` (before slow imports), once. On the supervisor's death it sends
    this process SIGTERM (so the child's own signal handler stops it cleanly) and ends the process with
    ``os._exit(1)`` if it is still running ``grace`` seconds later.

    Returns:
        True when a lifeline was found and is watched; False when the process was not started by a
        supervisor (run by hand), so nothing is watched.
    """
    value = os.environ.pop(ENV, "")  # not for grandchildren: they do not inherit the descriptor
    fd_text, _, pid_text = value.partition(":")
    try:
        fd, supervisor = int(fd_text), int(pid_text)
        is_pipe = stat.S_ISFIFO(os.fstat(fd).st_mode)
    except (ValueError, OSError):
        is_pipe = False
    if not is_pipe:
        if value:
            log.warning("%s=%r names no open pipe; not watching the supervisor", ENV, value)
        return False

    def watch() -> None:
        try:
            while os.read(fd, 1):  # the supervisor never writes: only end-of-file comes back
                pass
        except OSError as error:
            log.warning("the lifeline to the supervisor broke (%s); stopping", error)
        log.warning("the supervisor (pid %d) is gone; stopping", supervisor)
        if signal.getsignal(signal.SIGALRM) is signal.SIG_DFL:
            # The kernel's backstop: an unhandled SIGALRM ends the process even when the interpreter is
            # finalizing (where this daemon thread may never run again) or a C call holds the GIL.
            signal.setitimer(signal.ITIMER_REAL, grace + 0.2)
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(grace)
        log.error("still running %.1f s after the supervisor died; exiting now", grace)
        for handler in logging.getLogger().handlers:
            try:
                handler.flush()
            except Exception:  # a log that cannot flush must not keep the process alive
                pass
        os._exit(1)

    threading.Thread(target=watch, name="kinema-lifeline", daemon=True).start()
    return True
