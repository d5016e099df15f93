"""The import graph: no cycles between packages or modules, and the layers point one way.

Every module of merlin2_sailor, merlin2_sailor_behaviors (behaviors/) and merlin2_sailor_demos
(demos/) is parsed with ``ast``, never imported, so the test needs no optional dependency and
cannot be fooled by an import that only happens at run time: imports inside functions count, and
so does a plug-in named by string (``"merlin2_sailor.x.y:Class"``, the form every plug-in table
uses, or ``importlib.import_module("merlin2_sailor.x.y")``), because choosing that plug-in imports
it. A package is ``merlin2_sailor.<child>`` (``merlin2_sailor.ros``, ``merlin2_sailor.errors``);
subpackages deeper down belong to their package.
"""

from __future__ import annotations

import ast
import dataclasses
import re
import textwrap
from collections import defaultdict
from collections.abc import Iterable, Iterator, Mapping
from functools import cache
from pathlib import Path

import pytest

REPOSITORY_ROOT = Path(__file__).resolve().parents[2]

#: Installed top-level package -> its folder in the checkout.
ROOTS = {
    "merlin2_sailor": REPOSITORY_ROOT / "merlin2_sailor",
    "merlin2_sailor_behaviors": REPOSITORY_ROOT / "behaviors",
    "merlin2_sailor_demos": REPOSITORY_ROOT / "demos",
}

#: Folders of the checkout that are not installed: installed code must not import them, neither by
#: their names nor by what they hold once put on ``sys.path`` (bench/harness as ``harness``).
CHECKOUT_FOLDERS = ("bench", "test", "scripts")

#: The ROS-free core and what it must never depend on.
CORE = tuple(f"merlin2_sailor.{name}" for name in ("contract", "anchoring", "perception", "knowledge", "training"))
ABOVE_CORE = ("merlin2_sailor.ros", "merlin2_sailor.cli", "merlin2_sailor_behaviors", "merlin2_sailor_demos")

#: Leaves and the only modules of ours each may import: the shared contract between perception and
#: anchoring (it may raise our errors, nothing more), the error family, and the plug-in tables' helper.
LEAVES = {
    "merlin2_sailor.contract": ("merlin2_sailor.errors",),
    "merlin2_sailor.errors": (),
    "merlin2_sailor.plugins": ("merlin2_sailor.errors",),
}

PLUGIN_STRING = re.compile(r"^((?:merlin2_sailor|merlin2_sailor_behaviors|merlin2_sailor_demos)(?:\.\w+)*):\w+$")


@dataclasses.dataclass(frozen=True)
class Import:
    """One dependency of a module on another, and where it is written."""

    source: str
    target: str
    path: Path
    line: int
    how: str  # "import", "import in a function", "names by string"

    def __str__(self) -> str:
        return f"{self.path.relative_to(REPOSITORY_ROOT)}:{self.line} {self.how} {self.target}"


def module_name(root_name: str, root: Path, path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join([root_name, *parts])


@cache
def modules() -> Mapping[str, Path]:
    """Every module of the three installed packages, by dotted name."""
    found = {}
    for root_name, root in ROOTS.items():
        for path in sorted(root.rglob("*.py")):
            if "__pycache__" not in path.parts:
                found[module_name(root_name, root, path)] = path
    return found


def package_of(module: str) -> str:
    """``merlin2_sailor.ros.conversions.perception`` -> ``merlin2_sailor.ros``."""
    return ".".join(module.split(".")[:2])


def resolve(name: str) -> str | None:
    """The longest known module that ``name`` (a dotted name, maybe ``module.attribute``) lies in."""
    parts = name.split(".")
    while parts:
        candidate = ".".join(parts)
        if candidate in modules():
            return candidate
        parts.pop()
    return None


def absolute(module: str, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    is_package = modules()[module].name == "__init__.py"
    base = module.split(".")
    base = base[: len(base) - node.level + (1 if is_package else 0)]
    return ".".join(base + ([node.module] if node.module else []))


def inside_function(tree: ast.AST) -> set[int]:
    """The ids of every node that lies inside a function body (a lazy import)."""
    lazy: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            lazy.update(id(child) for child in ast.walk(node) if child is not node)
    return lazy


def imports_of(module: str) -> Iterator[Import]:
    path = modules()[module]
    yield from imports_in(module, ast.parse(path.read_text(encoding="utf-8"), filename=str(path)), path)


def imports_in(module: str, tree: ast.AST, path: Path) -> Iterator[Import]:
    """What ``module`` (parsed as ``tree`` from ``path``) depends on, among the parsed modules."""
    lazy = inside_function(tree)

    def edge(target_name: str, node: ast.AST, how: str | None = None) -> Iterator[Import]:
        target = resolve(target_name)
        if target is not None and target != module:
            kind = how or ("import in a function" if id(node) in lazy else "import")
            yield Import(module, target, path, node.lineno, kind)

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield from edge(alias.name, node)
        elif isinstance(node, ast.ImportFrom):
            base = absolute(module, node)
            for alias in node.names:
                # ``from package import submodule`` depends on the submodule, not on all of the package.
                yield from edge(f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules() else base, node)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            match = PLUGIN_STRING.match(node.value)
            if match:
                yield from edge(match.group(1), node, "names by string")
        elif (isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) == "import_module"
              and node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            yield from edge(node.args[0].value, node, "imports by name")


@cache
def all_imports() -> tuple[Import, ...]:
    return tuple(found for module in modules() for found in imports_of(module))


def strongly_connected(graph: Mapping[str, Iterable[str]]) -> list[list[str]]:
    """Tarjan's components of more than one node, each sorted (iterative: the graph may be deep)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    components: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        components.append(sorted(component))
            elif child not in index:
                index[child] = low[child] = len(index)
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph.get(child, ())))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return components


def one_cycle(graph: Mapping[str, Iterable[str]], component: list[str]) -> list[str]:
    """A shortest cycle through the component's first node, for the failure message."""
    members = set(component)
    start = component[0]
    paths = {start: [start]}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for child in sorted(graph.get(node, ())):
                if child == start:
                    return [*paths[node], start]
                if child in members and child not in paths:
                    paths[child] = [*paths[node], child]
                    following.append(child)
        frontier = following
    raise AssertionError(f"{component} is not strongly connected")


def describe_cycles(edges: Mapping[tuple[str, str], list[Import]]) -> list[str]:
    graph: dict[str, set[str]] = defaultdict(set)
    for source, target in edges:
        graph[source].add(target)
    described = []
    for component in strongly_connected(graph):
        cycle = one_cycle(graph, component)
        steps = [f"    {edges[(a, b)][0]}" for a, b in zip(cycle, cycle[1:], strict=False)]
        described.append(" -> ".join(cycle) + "\n" + "\n".join(steps))
    return described


def test_the_parser_sees_the_whole_code_base() -> None:
    """Guards the other tests against passing because they looked at nothing."""
    assert len(modules()) > 100
    assert "merlin2_sailor.knowledge.stores" in modules()
    assert "merlin2_sailor_behaviors.catalogue" in modules()
    assert "merlin2_sailor_demos.world.world" in modules()
    hows = {found.how for found in all_imports()}
    assert {"import", "import in a function", "names by string"} <= hows


def test_no_cycle_between_packages() -> None:
    edges: dict[tuple[str, str], list[Import]] = defaultdict(list)
    for found in all_imports():
        source, target = package_of(found.source), package_of(found.target)
        if source != target:
            edges[(source, target)].append(found)
    cycles = describe_cycles(edges)
    assert not cycles, "Packages import each other (put what both need one level down, or invert the dependency):\n" + (
        "\n".join(cycles)
    )


def test_no_cycle_between_modules() -> None:
    edges: dict[tuple[str, str], list[Import]] = defaultdict(list)
    for found in all_imports():
        edges[(found.source, found.target)].append(found)
    cycles = describe_cycles(edges)
    assert not cycles, "Modules import each other:\n" + "\n".join(cycles)


def within(module: str, packages: Iterable[str]) -> bool:
    """Whether ``module`` is one of ``packages`` or lies inside one."""
    return any(module == package or module.startswith(package + ".") for package in packages)


def violations(sources: Iterable[str], forbidden: Iterable[str]) -> list[str]:
    sources, forbidden = tuple(sources), tuple(forbidden)
    return [str(found) for found in all_imports() if within(found.source, sources) and within(found.target, forbidden)]


@pytest.mark.parametrize("core", CORE)
def test_the_core_never_depends_on_the_layers_above(core: str) -> None:
    found = violations([core], ABOVE_CORE)
    assert not found, f"{core} is ROS-free core and must not depend on {', '.join(ABOVE_CORE)}:\n" + "\n".join(found)


@pytest.mark.parametrize("leaf", sorted(LEAVES))
def test_the_leaves_import_almost_nothing_of_ours(leaf: str) -> None:
    allowed = LEAVES[leaf]
    found = [str(found) for found in all_imports() if within(found.source, [leaf])
             and not within(found.target, [leaf]) and found.target not in allowed]
    assert not found, f"{leaf} may import only {', '.join(allowed) or 'nothing of ours'}:\n" + "\n".join(found)


def checkout_only_names() -> set[str]:
    """The folders' names and every module or package directly inside them."""
    names = set(CHECKOUT_FOLDERS)
    for folder in CHECKOUT_FOLDERS:
        for child in (REPOSITORY_ROOT / folder).iterdir():
            if child.suffix == ".py" or (child / "__init__.py").is_file():
                names.add(child.stem)
    return names


def test_installed_code_never_imports_the_checkout() -> None:
    """bench/, test/ and scripts/ are not installed: importing them works only in a source checkout,
    so installed code neither imports them nor puts them on ``sys.path``."""
    checkout = checkout_only_names()
    assert "harness" in checkout  # bench/harness, as bench's scripts import it
    found = []
    for path in modules().values():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = [alias.name for alias in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            found += [f"{path.relative_to(REPOSITORY_ROOT)}:{node.lineno} imports {name}"
                      for name in names if name.split(".")[0] in checkout]
            if isinstance(node, ast.Attribute) and node.attr == "path" and getattr(node.value, "id", "") == "sys":
                found.append(f"{path.relative_to(REPOSITORY_ROOT)}:{node.lineno} uses sys.path")
    assert not found, "\n".join(found)


def test_the_cycle_finder_finds_a_cycle() -> None:
    """The finder itself, on a graph made for it: a three-step cycle, a two-step one and a tail."""
    here = Path(__file__)
    edges = {
        (a, b): [Import(a, b, here, 1, "import")]
        for a, b in [("a", "b"), ("b", "c"), ("c", "a"), ("c", "d"), ("d", "e"), ("e", "d"), ("f", "a")]
    }
    cycles = describe_cycles(edges)
    assert sorted(cycle.splitlines()[0] for cycle in cycles) == ["a -> b -> c -> a", "d -> e -> d"]
    assert all(line.startswith("    test/unit/test_import_graph.py:1 import ") for line in cycles[0].splitlines()[1:])


def test_the_parser_resolves_relative_lazy_and_named_imports(tmp_path: Path) -> None:
    """Each kind of import the graph relies on, in a module written for it."""
    module = "merlin2_sailor.knowledge.stores"
    source = ast.parse(textwrap.dedent('''
        from . import naming
        from ..errors import ConfigurationError
        def later():
            from merlin2_sailor.ros import stores
        TABLE = {"x": "merlin2_sailor.perception.detector:Detector"}
        importlib.import_module("merlin2_sailor.training.trainer")
    '''))
    found = {(found.target, found.how) for found in imports_in(module, source, modules()[module])}
    assert found == {
        ("merlin2_sailor.knowledge.naming", "import"),
        ("merlin2_sailor.errors", "import"),
        ("merlin2_sailor.ros.stores", "import in a function"),
        ("merlin2_sailor.perception.detector", "names by string"),
        ("merlin2_sailor.training.trainer", "imports by name"),
    }
