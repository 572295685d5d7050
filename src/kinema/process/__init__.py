"""What every process of a Kinema run shares, below the runtime and the drivers that both use it.

* :mod:`kinema.process.lifeline` — a child's lifeline to the ``kinema run`` supervisor (it ends when the
  supervisor dies);
* :mod:`kinema.process.log_files` — one log format for every process, read back merged and filtered.

A process's presence on the network (agent or driver of a cell) is :mod:`kinema.transport.presence`.
Importing this package imports nothing else.
"""
