"""What the ``kinema`` command itself costs a person at a terminal, against ``python -c pass``.

Starts ``kinema run --headless`` (lab_sim: the agent and the MuJoCo driver) on a free loopback port with
private user folders, then times cold commands, each a new interpreter, in interleaved rounds (so a busy
moment of the machine hits every command alike), median over rounds:

* ``python -c pass``: the peer, the interpreter's own start;
* ``kinema --help`` (target: within 2x of the peer);
* ``kinema objective list`` (lab_sim's objectives, with the check of which cannot load; target 5x);
* ``kinema objective run "Close Gripper"`` on the running cell. Its own cost is its wall time less the
  objective's: the same objective run through the SDK from a warm process against the same cell, timed in
  the same rounds (the gripper is already closed after the first run, so each run is short). Target: that
  difference within 5x of the peer.

The bytecode cache is on as the user has it (``PYTHONDONTWRITEBYTECODE`` as in the environment; Kinema keeps
its compiled code in the user's cache folder either way, :mod:`kinema.bytecode`); the first round is a
warm-up and not counted.
Run: ``python benchmarks/cli_start.py [--rounds N] [--smoke]``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from headless_cell import headless_lab_sim

from kinema.sdk import ObjectiveClient

OBJECTIVE = "Close Gripper"


def _kinema() -> list[str]:
    """The console script a user types, next to this interpreter when installed; else ``python -m kinema``."""
    script = Path(sys.executable).with_name("kinema")
    if script.is_file():
        return [str(script)]
    found = shutil.which("kinema")
    return [found] if found else [sys.executable, "-m", "kinema"]


def _timed(argv: list[str], env: dict[str, str]) -> float:
    start = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, env=env, timeout=120)
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({done.returncode}): {done.stderr.decode()[-2000:]}")
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=9, help="timed rounds (after one warm-up round)")
    parser.add_argument("--smoke", action="store_true", help="one timed round (the test suite)")
    args = parser.parse_args()
    rounds = 1 if args.smoke else args.rounds
    kinema = _kinema()
    with headless_lab_sim("kinema-cli-start-", kinema) as cell:
        env, endpoint = cell.env, cell.endpoint
        commands = {
            "python -c pass": [sys.executable, "-c", "pass"],
            "kinema --help": [*kinema, "--help"],
            "kinema objective list": [*kinema, "objective", "list"],
            f'kinema objective run "{OBJECTIVE}"': [*kinema, "objective", "run", OBJECTIVE],
        }
        times: dict[str, list[float]] = {name: [] for name in commands}
        times["the objective alone (SDK, warm)"] = []
        with ObjectiveClient(endpoint, timeout=30) as client:
            for number in range(rounds + 1):
                for name, argv in commands.items():
                    elapsed = _timed(argv, env)
                    if number:
                        times[name].append(elapsed)
                start = time.perf_counter()
                result = client.execute(OBJECTIVE)
                if not result.succeeded:
                    raise SystemExit(f"{OBJECTIVE!r} failed through the SDK: {result}")
                if number:
                    times["the objective alone (SDK, warm)"].append(time.perf_counter() - start)

    median = {name: statistics.median(values) * 1000 for name, values in times.items()}
    peer = median["python -c pass"]
    run_name = f'kinema objective run "{OBJECTIVE}"'
    own = median[run_name] - median["the objective alone (SDK, warm)"]
    print(f"cold commands, median of {rounds} rounds (load {os.getloadavg()[0]:.1f})")
    print(f"{'command':<44} {'ms':>7} {'ratio to python -c pass':>24}")
    for name, value in median.items():
        print(f"{name:<44} {value:7.0f} {value / peer:23.2f}x")
    print(f"{'  objective run, its own cost (difference)':<44} {own:7.0f} {own / peer:23.2f}x")
    for name, value, target in (
        ("kinema --help", median["kinema --help"], 2),
        ("kinema objective list", median["kinema objective list"], 5),
        (f"{run_name}, own cost", own, 5),
    ):
        verdict = "met" if value <= target * peer else "NOT met"
        print(f"{name}: within {target}x of python -c pass: {verdict} ({value / peer:.2f}x)")


if __name__ == "__main__":
    main()
