"""Refuse bad input before the config package is generated (cookiecutter runs this first).

Kinema checks the same rules (and more, such as whether the parent package exists) before calling
cookiecutter; this hook keeps the template safe when cookiecutter is run on it directly.
"""

import json
import re
import sys

PACKAGE_NAME = re.compile(r"^[a-z](?:[a-z0-9]|_(?!_))*$")

# tojson escapes single quotes, so the rendered single-quoted raw string holds exactly the JSON text.
# fmt: off
package_name = json.loads(r'{{ cookiecutter.package_name | tojson }}')
based_on_package = json.loads(r'{{ cookiecutter.based_on_package | tojson }}')
# fmt: on


def fail(message: str) -> None:
    print(f"ERROR: {message}", file=sys.stderr)
    sys.exit(1)


for label, value in (("package name", package_name), ("based_on_package", based_on_package)):
    if not PACKAGE_NAME.match(value) or value.endswith("_"):
        fail(
            f"{value!r} is not a valid {label}: use lowercase letters, digits and single underscores, "
            "starting with a letter (e.g. my_robot_config)"
        )
if package_name == based_on_package:
    fail(f"a config package cannot be based on itself ({package_name!r})")
