"""``python -m kinema.viz``: the 3D view as a process of its own (what ``kinema run`` starts).

With ``--ready-fd N`` it writes the page's URL (one line) to that file descriptor once it serves, or
``error: <message>`` when it cannot start.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from kinema.errors import KinemaError


def main(argv: list[str] | None = None) -> int:
    """Parse the arguments, serve the view until SIGTERM/Ctrl-C; returns the exit code."""
    parser = argparse.ArgumentParser(prog="python -m kinema.viz", description=__doc__)
    parser.add_argument("--connect", help="the runtime's zenoh endpoint")
    parser.add_argument("--config", help="the config package whose MuJoCo scene is drawn")
    parser.add_argument("--workspace", type=Path, help="the workspace folder")
    parser.add_argument("--port", type=int, help="HTTP port on 127.0.0.1 (default: first free from 7000)")
    parser.add_argument("--no-browser", action="store_true", help="do not open a browser")
    parser.add_argument("--log-file", type=Path, help="write the log here")
    parser.add_argument("--ready-fd", type=int, help="write the URL to this file descriptor when serving")
    args = parser.parse_args(argv)

    from kinema.process import lifeline
    from kinema.process.log_files import configure_process_logging

    configure_process_logging(args.log_file)
    lifeline.hold()  # before the slow imports: a view whose supervisor died while it started ends too
    from kinema.viz.view import ViewerOptions, run_viewer

    def report(line: str) -> None:
        if args.ready_fd is not None:
            with os.fdopen(args.ready_fd, "w") as ready:
                ready.write(line + "\n")

    options = ViewerOptions(
        endpoint=args.connect,
        config=args.config,
        workspace=args.workspace,
        port=args.port,
        open_browser=not args.no_browser,
        echo=lambda text: print(text, flush=True),
    )
    try:
        return run_viewer(options, ready=report)
    except KinemaError as error:
        report(f"error: {error}")
        print(f"error: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
