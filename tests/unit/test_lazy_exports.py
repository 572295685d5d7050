"""Packages that import their names on first use: every listed name resolves, unknown ones fail clearly."""

from __future__ import annotations

import importlib

import pytest

LAZY_PACKAGES = [
    "kinema.motion",
    "kinema.perception",
    "kinema.runtime",
    "kinema.sdk",
    "kinema.drivers.mujoco",
]


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_every_exported_name_resolves_and_is_kept(package: str) -> None:
    module = importlib.import_module(package)
    assert module.__all__, package
    for name in module.__all__:
        value = getattr(module, name)
        assert value is not None
        assert vars(module)[name] is value  # imported once, then found without the lookup


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_an_unknown_name_is_an_attribute_error_naming_the_package(package: str) -> None:
    module = importlib.import_module(package)
    with pytest.raises(AttributeError, match=f"module '{package}' has no attribute 'Nope'"):
        _ = module.Nope
