"""Inside ``rattle.model`` imports go one way, from the table reader down to the objects and laws:
no module imports, even inside a function, a module that imports it back (read with ``ast``).
``Model.from_toml`` and ``Chain.from_toml`` reach the reader through the registry of
``rattle.model._readers``."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import rattle.model
from rattle.model import _readers

MODEL = Path(rattle.model.__file__).resolve().parent


def _edges(folder: Path = MODEL) -> dict[str, set[str]]:
    """module -> the modules of ``rattle.model`` it imports (at any depth of the file)."""
    names = {p.stem for p in folder.glob("*.py")}
    edges: dict[str, set[str]] = {}
    for path in folder.glob("*.py"):
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                if node.module:
                    found.add(node.module.split(".")[0])
                else:  # from . import x
                    found.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith("rattle.model."):
                found.add((node.module or "").split(".")[2])
            elif isinstance(node, ast.Import):
                found.update(a.name.split(".")[2] for a in node.names if a.name.startswith("rattle.model."))
        edges[path.stem] = {m for m in found if m in names} - {path.stem}
    return edges


def _cycle(edges: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        stack.append(m)
        for n in sorted(edges.get(m, ())):
            if state.get(n) == 1:
                return stack[stack.index(n):] + [n]
            if n not in state and (found := visit(n)):
                return found
        stack.pop()
        state[m] = 2
        return None

    for m in sorted(edges):
        if m not in state and (found := visit(m)):
            return found
    return None


def test_the_modules_of_the_model_import_one_way() -> None:
    edges = _edges()
    assert {"_tables", "_model", "_chain", "_discontinuous", "_system"} <= set(edges)
    assert edges["_model"] & {"_tables", "_chain"} == set(), edges["_model"]
    assert edges["_chain"] & {"_tables", "_model"} == set(), edges["_chain"]
    assert edges["_discontinuous"] <= {"_elastic"}, edges["_discontinuous"]
    assert _cycle({m: e for m, e in edges.items() if m != "__init__"}) is None


def test_the_cycle_finder_sees_a_cycle() -> None:
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_from_toml_without_a_registered_reader_says_so(tmp_path: Path, monkeypatch) -> None:
    path = tmp_path / "case.toml"
    path.write_text("[model]\n", encoding="utf-8")
    monkeypatch.setattr(_readers, "_READER", [])
    with pytest.raises(RuntimeError, match="no reader of the model tables is registered"):
        rattle.model.Model.from_toml(path)


def test_the_registered_reader_is_the_table_reader() -> None:
    from rattle.model._tables import model_tables

    assert _readers._READER == [model_tables]
    with pytest.raises(TypeError, match="`reader` must be callable"):
        _readers.register_reader("model_tables")  # type: ignore[arg-type]
