from __future__ import annotations

from pathlib import Path

import pytest

from kinema.config.yamlsource import load_yaml_file, parse_yaml
from kinema.errors import ConfigError


def test_every_key_and_list_item_has_its_line():
    document = parse_yaml("a:\n  b:\n    - x\n    - y: 1\nc: 2\n", "f.yaml")
    assert document.data == {"a": {"b": ["x", {"y": 1}]}, "c": 2}
    assert document.line(("a",)) == 1
    assert document.line(("a", "b")) == 2
    assert document.line(("a", "b", 1)) == 4
    assert document.line(("a", "b", 1, "y")) == 4
    assert document.line(("c",)) == 5
    # an unknown path falls back to its longest known prefix
    assert document.line(("a", "b", 1, "missing")) == 4
    assert str(document.location(("c",))) == "f.yaml:5"


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("a: [1,\nb: 2\n", 3, "began on line 1"),
        ("a: 1\nb:\n  c: 1\n  c: 2\n", 4, "appears twice"),
        ("a: 'unterminated\n", 2, "invalid YAML"),
    ],
)
def test_bad_yaml_is_an_error_with_file_and_line(text: str, line: int, words: str):
    with pytest.raises(ConfigError) as caught:
        parse_yaml(text, "broken.yaml")
    assert caught.value.location is not None
    assert caught.value.location.file == "broken.yaml"
    assert caught.value.location.line == line
    assert words in str(caught.value)


def test_non_utf8_file_names_the_line_of_the_bad_byte(tmp_path: Path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes("a: 1\nb: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ConfigError) as caught:
        load_yaml_file(path)
    assert "not UTF-8" in str(caught.value)
    assert str(caught.value).startswith(f"{path}:2:")


def test_too_large_file_is_refused_before_parsing(tmp_path: Path):
    path = tmp_path / "huge.yaml"
    path.write_text("a: " + "x" * 5000 + "\n")
    with pytest.raises(ConfigError, match="larger than the limit"):
        load_yaml_file(path, max_bytes=1000)


def test_missing_file_is_a_clear_error(tmp_path: Path):
    with pytest.raises(ConfigError, match="does not exist"):
        load_yaml_file(tmp_path / "nope.yaml")


def test_deeply_nested_yaml_does_not_crash():
    text = "a: " + "[" * 3000 + "]" * 3000 + "\n"
    try:
        document = parse_yaml(text, "deep.yaml")
    except ConfigError as error:
        assert "deep.yaml" in str(error)
    else:
        assert document.data is not None


def test_moveit_pro_angle_tags_are_radians() -> None:
    import math

    from kinema.config.yamlsource import parse_yaml

    document = parse_yaml("a: !degrees 180\nb: !radians 0.5\nc: !degrees  30.0\n", "limits.yaml")
    assert document.data == {"a": math.pi, "b": 0.5, "c": math.radians(30.0)}
    assert document.line(("c",)) == 3


def test_an_angle_tag_without_a_number_names_the_line() -> None:
    import pytest

    from kinema.config.yamlsource import parse_yaml
    from kinema.errors import ConfigError

    with pytest.raises(ConfigError, match=r"limits.yaml:2.*!degrees needs a number"):
        parse_yaml("a: 1\nb: !degrees fast\n", "limits.yaml")


def test_moveit_pro_joint_limits_with_degrees_load(tmp_path) -> None:
    import math

    from kinema.motion.joint_limits import parse_joint_limits

    path = tmp_path / "joint_limits.yaml"
    path.write_text("joint_limits:\n  j1:\n    has_velocity_limits: true\n    max_velocity: !degrees 90\n")
    assert parse_joint_limits(path).joints["j1"]["max_velocity"] == math.pi / 2
