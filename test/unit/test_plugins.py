"""The plug-in table: lazy loading by name, and the two errors every plug-in kind shares."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.plugins import PluginTable


@pytest.fixture()
def plugin_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """A throw-away package with one working plug-in and one that needs a missing library."""
    package = tmp_path / "sailor_test_plugins"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "light.py").write_text(
        textwrap.dedent(
            """
            class Greeter:
                def __init__(self, name, punctuation="!"):
                    self.text = f"hello {name}{punctuation}"
            """
        )
    )
    (package / "heavy.py").write_text("import sailor_library_that_is_not_installed\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield package.name
    for module in [name for name in sys.modules if name.startswith(package.name)]:
        del sys.modules[module]


def table(package: str, **options) -> PluginTable:
    return PluginTable(
        "greeter",
        {"light": f"{package}.light:Greeter", "heavy": f"{package}.heavy:Greeter"},
        **options,
    )


def test_names_are_sorted_and_membership_works(plugin_package: str) -> None:
    greeters = table(plugin_package)
    assert greeters.names == ("heavy", "light")
    assert list(greeters) == ["heavy", "light"]
    assert "light" in greeters and "absent" not in greeters


def test_load_imports_only_the_chosen_plugin(plugin_package: str) -> None:
    greeters = table(plugin_package)
    assert f"{plugin_package}.light" not in sys.modules
    greeter_class = greeters.load("light")
    assert greeter_class.__name__ == "Greeter"
    assert f"{plugin_package}.light" in sys.modules
    assert f"{plugin_package}.heavy" not in sys.modules


def test_create_passes_its_arguments(plugin_package: str) -> None:
    assert table(plugin_package).create("light", "robot", punctuation="?").text == "hello robot?"


def test_an_unknown_name_lists_the_known_ones(plugin_package: str) -> None:
    with pytest.raises(ConfigurationError, match=r"Unknown greeter 'lihgt'; choose one of heavy, light\."):
        table(plugin_package).load("lihgt")


def test_a_failed_import_says_what_to_install(plugin_package: str) -> None:
    greeters = table(plugin_package, hint="Install the greeting extras.")
    with pytest.raises(DependencyError) as caught:
        greeters.load("heavy")
    message = str(caught.value)
    assert "greeter 'heavy'" in message
    assert "sailor_library_that_is_not_installed" in message
    assert message.endswith("Install the greeting extras.")
    assert isinstance(caught.value.__cause__, ImportError)


def test_a_per_name_hint_overrides_the_kind_hint(plugin_package: str) -> None:
    greeters = table(plugin_package, hint="generic", hints={"heavy": "pip install heavy-greetings"})
    with pytest.raises(DependencyError, match="pip install heavy-greetings$"):
        greeters.load("heavy")


def test_a_wrong_attribute_names_the_table_entry(plugin_package: str) -> None:
    greeters = PluginTable("greeter", {"typo": f"{plugin_package}.light:Greter"})
    with pytest.raises(AttributeError, match="Greter"):
        greeters.load("typo")


@pytest.mark.parametrize("target", ["no_colon", ":Attribute", "module:"])
def test_malformed_entries_are_refused_at_construction(target: str) -> None:
    with pytest.raises(ValueError, match="module:attribute"):
        PluginTable("greeter", {"bad": target})


def test_hints_for_unknown_names_are_refused() -> None:
    with pytest.raises(ValueError, match="unknown greeter"):
        PluginTable("greeter", {"a": "x:y"}, hints={"b": "install b"})


def test_the_table_is_a_frozen_copy() -> None:
    entries = {"a": "x:y"}
    greeters = PluginTable("greeter", entries)
    entries["b"] = "x:z"
    assert greeters.names == ("a",)
    with pytest.raises(TypeError):
        greeters.entries["c"] = "x:w"  # type: ignore[index]


def test_a_layer_above_extends_a_table_without_changing_it(plugin_package: str) -> None:
    below = PluginTable("greeter", {"light": f"{plugin_package}.light:Greeter"}, hint="below")
    above = below.extended({"heavy": f"{plugin_package}.heavy:Greeter"}, hints={"heavy": "install heavy"})
    assert below.names == ("light",) and above.names == ("heavy", "light")
    assert above.create("light", "robot").text == "hello robot!"
    with pytest.raises(DependencyError, match="install heavy$"):
        above.load("heavy")
    with pytest.raises(ValueError, match="taken"):
        below.extended({"light": f"{plugin_package}.light:Greeter"})
