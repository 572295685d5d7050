"""Refuse bad input before the behavior package is generated (cookiecutter runs this first).

Kinema checks the same rules before calling cookiecutter (``kinema new behavior``); this hook keeps the
template safe when cookiecutter is run on it directly.
"""

import json
import keyword
import re
import sys

SNAKE = re.compile(r"^[a-z](?:[a-z0-9]|_(?!_))*$")
CAMEL = re.compile(r"^[A-Z][A-Za-z0-9]*$")
TYPES = (
    "sync",
    "stateful",
    "async",
    "service_client",
    "action_client",
    "topic_subscriber",
    "topic_publisher",
)

# tojson escapes single quotes, so the rendered single-quoted raw string holds exactly the JSON text.
# fmt: off
package_name = json.loads(r'{{ cookiecutter.package_name | tojson }}')
behavior_name = json.loads(r'{{ cookiecutter.behavior_name | tojson }}')
behavior_id = json.loads(r'{{ cookiecutter.behavior_id | tojson }}')
behavior_type = json.loads(r'{{ cookiecutter.behavior_type | tojson }}')
loader_name = json.loads(r'{{ cookiecutter.loader_name | tojson }}')
# fmt: on


def fail(message: str) -> None:
    print(f"ERROR: {message}", file=sys.stderr)
    sys.exit(1)


for label, value in (("package name", package_name), ("behavior name", behavior_name)):
    if not SNAKE.match(value) or value.endswith("_") or keyword.iskeyword(value):
        fail(
            f"{value!r} is not a valid {label}: use lowercase letters, digits and single underscores, "
            "starting with a letter (e.g. my_behavior)"
        )
if not CAMEL.match(behavior_id):
    fail(f"{behavior_id!r} is not a valid behavior ID: use CamelCase letters and digits (e.g. MyBehavior)")
if behavior_type not in TYPES:
    fail(f"{behavior_type!r} is not a behavior type; valid: {', '.join(TYPES)}")
if not loader_name.startswith(f"{package_name}::"):
    fail(f"the loader name {loader_name!r} must start with '{package_name}::'")
