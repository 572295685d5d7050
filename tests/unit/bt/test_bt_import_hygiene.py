"""``kinema.bt`` stands alone: importing it pulls in none of the robotics or UI packages."""

from __future__ import annotations

import subprocess
import sys


def test_importing_kinema_bt_imports_no_robotics_or_ui_modules() -> None:
    code = (
        "import sys, kinema.bt\n"
        "heavy = {'mujoco', 'pinocchio', 'zenoh', 'textual', 'rich', 'meshcat', 'ompl', 'toppra', 'numpy'}\n"
        "print(sorted(heavy & {name.split('.')[0] for name in sys.modules}))\n"
        # kinema.bytecode is the package's own import machinery (its compiled-code cache)
        "print(sorted(n for n in sys.modules if n.startswith('kinema.') and not n.startswith('kinema.bt')\n"
        "             and n != 'kinema.bytecode'))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    heavy, other_kinema = out.strip().splitlines()
    assert heavy == "[]"
    assert other_kinema == "['kinema.errors']"
