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


def shipped_tables() -> dict[str, PluginTable]:
    """Every PluginTable the three packages define at module level, found by reading their source."""
    import ast
    import importlib

    roots = {"merlin2_sailor": "merlin2_sailor", "merlin2_sailor_behaviors": "behaviors",
             "merlin2_sailor_demos": "demos"}
    repository = Path(__file__).resolve().parents[2]
    tables = {}
    for package, folder in roots.items():
        for path in sorted((repository / folder).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            if "PluginTable(" not in text and ".extended(" not in text or path.name == "plugins.py":
                continue
            tree = ast.parse(text)
            names = [target.id for node in tree.body if isinstance(node, ast.Assign | ast.AnnAssign)
                     for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
                     if isinstance(target, ast.Name)]
            parts = path.relative_to(repository / folder).with_suffix("").parts
            module = importlib.import_module(".".join([package, *parts]))
            tables.update({f"{module.__name__}.{name}": getattr(module, name) for name in names
                           if isinstance(getattr(module, name, None), PluginTable)})
    return tables


def defines(module_name: str, attribute: str) -> bool:
    """Whether the module's source defines ``attribute`` at top level (read, not imported)."""
    import ast
    import importlib.util

    spec = importlib.util.find_spec(module_name)
    assert spec is not None and spec.origin, f"no module {module_name}"
    tree = ast.parse(Path(spec.origin).read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.ClassDef | ast.FunctionDef) and node.name == attribute:
            return True
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == attribute for t in node.targets):
            return True
    return False


def test_every_shipped_table_names_modules_and_attributes_that_exist() -> None:
    """Read, not imported: a typo in any table fails here, without torch, KANT or ROS installed."""
    tables = shipped_tables()
    kinds = {table.kind for table in tables.values()}
    assert {"knowledge store", "detector backend", "backbone", "data source"} <= kinds, kinds
    for where, table in tables.items():
        for name, target in table.entries.items():
            module_name, _, attribute = target.partition(":")
            assert defines(module_name, attribute), f"{where}[{name!r}] -> {target} does not exist"
