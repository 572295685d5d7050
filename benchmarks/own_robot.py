"""Your own robot: how long `kinema new config --from-urdf` takes for the Panda, and how long the new cell
takes to start against lab_sim's, measured in the same run.

Measured, each as whole commands a user types (cold Python processes), in a temporary workspace with its
own user folders and a free loopback port:

* ``kinema new config panda_bench --from-urdf package://example-robot-data/.../panda.urdf --srdf ...``:
  the first run converts the DAE meshes, later ones find them in the mesh cache; the peer is the import
  floor of the libraries it uses (``python -c "import mujoco, pinocchio, trimesh, xacro"``);
* ``kinema run -c panda_bench --headless`` until it prints "Kinema is running", against the same for
  lab_sim (the peer), then ``kinema down``.

It prints the medians and the ratios. Run: ``python benchmarks/own_robot.py [--repeat N]``;
``--smoke`` runs each once (the test suite does, so the script cannot rot).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PANDA = "package://example-robot-data/robots/panda_description"
READY = "Kinema is running"


def _environment(home: Path) -> dict[str, str]:
    from kinema.transport import free_endpoint

    env = dict(os.environ)
    for name in ("CONFIG", "STATE", "CACHE", "DATA"):
        env[f"XDG_{name}_HOME"] = str(home / name.lower())
    env["KINEMA_ZENOH_CONNECT"] = free_endpoint()
    env.pop("KINEMA_WORKSPACE", None)
    env.pop("KINEMA_CONFIG", None)
    return env


def _timed(command: list[str], env: dict[str, str], cwd: Path) -> float:
    started = time.perf_counter()
    subprocess.run(command, env=env, cwd=cwd, check=True, capture_output=True, timeout=600)
    return time.perf_counter() - started


def _start_time(config: str, workspace: Path, env: dict[str, str]) -> float:
    """Seconds from `kinema run` to its "Kinema is running" line; the run is stopped after."""
    kinema = [sys.executable, "-m", "kinema.cli.main"]
    started = time.perf_counter()
    process = subprocess.Popen(
        [*kinema, "run", "-w", str(workspace), "-c", config, "--headless"],
        env=env,
        cwd=workspace,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        assert process.stdout is not None
        for line in process.stdout:
            if READY in line:
                return time.perf_counter() - started
        raise RuntimeError(f"kinema run -c {config} ended without saying {READY!r}")
    finally:
        subprocess.run([*kinema, "down"], env=env, cwd=workspace, capture_output=True, timeout=60)
        try:
            process.wait(30)
        except subprocess.TimeoutExpired:
            process.kill()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs of each command (default 5)")
    parser.add_argument("--smoke", action="store_true", help="one run of each, to check the script works")
    args = parser.parse_args()
    repeat = 1 if args.smoke else max(1, args.repeat)

    from kinema.config.robot_files import PackageIndex

    if PackageIndex().find("example-robot-data") is None:
        sys.exit("example-robot-data is not installed (pip install example-robot-data)")
    home = Path(tempfile.mkdtemp(prefix="kinema-bench-own-robot-"))
    try:
        env = _environment(home)
        workspace = home / "ws"
        (workspace / "src").mkdir(parents=True)
        kinema = [sys.executable, "-m", "kinema.cli.main"]
        floor = [
            _timed([sys.executable, "-c", "import mujoco, pinocchio, trimesh, xacro"], env, home)
            for _ in range(repeat)
        ]
        generate = []
        for _ in range(repeat + 1):
            target = workspace / "src" / "panda_bench"
            shutil.rmtree(target, ignore_errors=True)
            generate.append(
                _timed(
                    [
                        *kinema,
                        "new",
                        "config",
                        "panda_bench",
                        "-w",
                        str(workspace),
                        "--from-urdf",
                        f"{PANDA}/urdf/panda.urdf",
                        "--srdf",
                        f"{PANDA}/srdf/panda.srdf",
                    ],
                    env,
                    workspace,
                )
            )
        cold, warm = generate[0], generate[1:]
        panda_start = [_start_time("panda_bench", workspace, env) for _ in range(repeat)]
        lab_sim_start = [_start_time("lab_sim", workspace, env) for _ in range(repeat)]
    finally:
        shutil.rmtree(home, ignore_errors=True)

    def row(label: str, values: list[float], peer: list[float] | None = None, peer_label: str = "") -> None:
        text = f"{label:<48} median {statistics.median(values) * 1000:8.0f} ms"
        if peer:
            ratio = statistics.median(values) / statistics.median(peer)
            text += f"   {ratio:5.2f}x {peer_label}"
        print(text)

    print(f"own robot: the Panda of example-robot-data, {repeat} run(s) each")
    row("import floor (mujoco, pinocchio, trimesh, xacro)", floor)
    row("new config --from-urdf, meshes converted", [cold], floor, "the import floor")
    row("new config --from-urdf, mesh cache warm", warm, floor, "the import floor")
    row("kinema run lab_sim until ready", lab_sim_start)
    row("kinema run panda_bench until ready", panda_start, lab_sim_start, "lab_sim's start")


if __name__ == "__main__":
    main()
