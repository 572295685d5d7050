"""What every process of a Kinema run shares, below the runtime and the drivers that both use it.

* :mod:`kinema.process.lifeline` — a child's lifeline to the ``kinema run`` supervisor (it ends when the
  supervisor dies);
* :mod:`kinema.process.log_files` — one log format for every process, read back merged and filtered
  (``SIGUSR1`` appends every thread's stack to the process's log);
* :mod:`kinema.process.memory_probe` — with ``KINEMA_DEBUG_MEMORY`` set, ``SIGUSR2`` logs a memory report
  (what grew and where it sits), for finding what grows in a long-running process;
* :mod:`kinema.process.stop` — the stop a signal (SIGTERM, Ctrl-C) or a thread asks for, without a lock in
  the signal handler (one that took the lock of the Event it set could wait for itself forever).

A process's presence on the network (agent or driver of a cell) is :mod:`kinema.transport.presence`.
Importing this package imports nothing else.
"""
