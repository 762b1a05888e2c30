"""The layer rule, read from the source: arrows run one way and no import hides a circle.

core ← symbolic (with io.py and models/) ← numeric ← design ← plots, sweep, codegen ← cli.
A module imports from its own layer or the layers to its left.  Imports inside functions
are allowed for start-up time (a downward import, e.g. the CLI loading the numeric layer
for the commands that need it) and for a result's one-line ``.plot()`` / ``.write()``
delegation to plots/ or codegen/; never to hide a circle.  Imports under
``if TYPE_CHECKING:`` are for the type checker and do not run.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

import pytest
from paths import ROOT

PACKAGE = ROOT / "phdesign"
LAYERS = {
    "core": 0,
    "symbolic": 1,
    "io": 1,
    "models": 1,
    "numeric": 2,
    "design": 3,
    "plots": 4,
    "sweep": 4,
    "codegen": 4,
    "cli": 5,
    "proofcheck": 0,  # the independent checker: imports nothing of phdesign but itself
    "__main__": 5,
}
DELEGATES = ("phdesign.plots", "phdesign.codegen")  # where a result's .plot()/.write() goes


def _module(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module(p): p for p in PACKAGE.rglob("*.py")}


def layer(module: str) -> int | None:
    parts = module.split(".")
    return LAYERS.get(parts[1]) if len(parts) > 1 else None


def _resolve(name: str) -> str | None:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _targets(node: ast.AST) -> list[str]:
    if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("phdesign"):
        found = (_resolve(f"{node.module}.{a.name}") or _resolve(node.module) for a in node.names)
        return [t for t in found if t]
    if isinstance(node, ast.Import):
        return [t for a in node.names if a.name.startswith("phdesign") if (t := _resolve(a.name))]
    return []


@cache
def imports() -> tuple[dict[str, set[str]], list[tuple[str, str, int]]]:
    """Module-level import arrows, and (module, target, line) of imports inside functions."""
    top: dict[str, set[str]] = {}
    inner: list[tuple[str, str, int]] = []
    for module, path in MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        typing_only: set[int] = set()
        at_top: set[int] = set()
        for node in tree.body:
            inside = list(ast.walk(node)) if isinstance(node, ast.If | ast.Try) else [node]
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                typing_only.update(id(n) for n in inside)
            else:
                at_top.update(id(n) for n in inside)
        for node in ast.walk(tree):
            if id(node) in typing_only:
                continue
            for target in _targets(node):
                if target == module:
                    continue
                if id(node) in at_top:
                    top.setdefault(module, set()).add(target)
                else:
                    inner.append((module, target, node.lineno))  # type: ignore[attr-defined]
    return top, inner


def _reaches(start: str, goal: str, arrows: dict[str, set[str]]) -> bool:
    seen, todo = set(), [start]
    while todo:
        node = todo.pop()
        if node == goal:
            return True
        if node not in seen:
            seen.add(node)
            todo.extend(arrows.get(node, ()))
    return False


def test_module_level_imports_run_down_the_layers():
    top, _ = imports()
    upward = [
        f"{m} -> {t}"
        for m, targets in top.items()
        for t in targets
        if (layer(m) is not None and layer(t) is not None and layer(t) > layer(m))
    ]
    assert not upward, upward


def test_no_module_level_circle():
    top, _ = imports()
    circles = [m for m in top for t in top[m] if _reaches(t, m, top)]
    assert not circles, sorted(set(circles))


def test_no_import_inside_a_function_hides_a_circle():
    top, inner = imports()
    hidden = [f"{m}:{line} -> {t}" for m, t, line in inner if _reaches(t, m, top)]
    assert not hidden, hidden


def test_imports_inside_functions_go_down_or_delegate_a_result():
    _, inner = imports()
    upward = [
        f"{m}:{line} -> {t}"
        for m, t, line in inner
        if layer(m) is not None and layer(t) is not None and layer(t) > layer(m)
        if not t.startswith(DELEGATES)
    ]
    assert not upward, upward


@pytest.mark.parametrize(("folder", "below"), [("core", 0), ("symbolic", 1)])
def test_the_base_layers_never_import_up_even_lazily(folder, below):
    top, inner = imports()
    arrows = [(m, t) for m, ts in top.items() for t in ts] + [(m, t) for m, t, _ in inner]
    up = [
        f"{m} -> {t}"
        for m, t in arrows
        if m.startswith(f"phdesign.{folder}")
        if (layer(t) or 0) > below
    ]
    assert not up, up


def test_the_proof_checker_imports_nothing_of_phdesign_but_itself():
    # an independent re-check: no arrow, even lazy, leaves phdesign.proofcheck
    top, inner = imports()
    arrows = [(m, t) for m, ts in top.items() for t in ts] + [(m, t) for m, t, _ in inner]
    out = [
        f"{m} -> {t}"
        for m, t in arrows
        if m.startswith("phdesign.proofcheck") and not t.startswith("phdesign.proofcheck")
    ]
    assert not out, out


def test_the_rule_sees_a_violation():
    # a module-level arrow from core to numeric and a hidden circle are both found
    top = {"phdesign.core.a": {"phdesign.numeric.b"}, "phdesign.numeric.b": {"phdesign.core.a"}}
    assert _reaches("phdesign.numeric.b", "phdesign.core.a", top)
    assert layer("phdesign.numeric.b") > layer("phdesign.core.a")


def test_mpmath_precision_is_set_for_a_block_never_globally():
    # a global ``mp.dps = 30`` in one test changes every later mpmath computation of the run
    offenders = [
        f"{p.relative_to(ROOT)}:{i}"
        for p in (ROOT / "tests").rglob("*.py")
        if p.name != "test_layers.py"
        for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if "mp.dps =" in line or "mp.prec =" in line
    ]
    assert not offenders, offenders
