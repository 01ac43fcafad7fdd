"""Imports point one way: the rules of the package layout, read from the source with ``ast``.

- nothing below ``rattle.demo`` imports it (only the command line runs it);
- ``rattle.results`` holds data: it imports neither ``io``, ``plotting`` nor ``analysis`` when
  loaded (its ``.to_csv()``/``.plot()`` delegates import them inside the method, when called);
- ``rattle.plotting`` draws results and knows nothing of the front ends, the demo or the CLI;
- the command line imports the demo and the numerics only inside a command (a quick front door);
- ``rattle.files`` (atomic writes, CSV, bounded reads, metadata) imports nothing of rattle but
  ``errors``: every layer may write through it;
- ``rattle.model`` is the ground floor of the numerics: it imports nothing above it, not even
  inside a method (``Model.from_toml`` reads its tables with ``rattle.model._tables`` and the
  bounded read of ``rattle.files``, never through ``rattle.io``);
- packages talk through their public modules: no module imports another package's ``_private``
  module (or a name from it), apart from the allowlists :data:`PRIVATE_TARGETS_ALLOWED` and
  :data:`PRIVATE_IMPORTS_ALLOWED`.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "rattle"


def _module_name(path: Path) -> str:
    parts = ("rattle", *path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> list[tuple[str, bool]]:
    """``(imported module, at module level)`` for every import of ``path``, relative ones resolved;
    ``from X import name`` counts as importing ``X.name`` too (it may be a sub-module)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = _module_name(path) if path.name == "__init__.py" else _module_name(path).rpartition(".")[0]
    found: list[tuple[str, bool]] = []

    def visit(node: ast.AST, top: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inside = top and not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                found.extend((alias.name, top) for alias in child.names)
            elif isinstance(child, ast.ImportFrom):
                base = child.module or ""
                if child.level:
                    anchor = package.split(".")[: len(package.split(".")) - (child.level - 1)]
                    base = ".".join([*anchor, base] if base else anchor)
                found.append((base, top))
                found.extend((f"{base}.{alias.name}", top) for alias in child.names)
            visit(child, inside)

    visit(tree, True)
    return found


MODULES = sorted(SRC.rglob("*.py"))


def _in(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def test_the_source_tree_is_found() -> None:
    names = {_module_name(p) for p in MODULES}
    assert {"rattle.demo", "rattle.results._comparison", "rattle.cli.app", "rattle.cli.commands"} <= names


@pytest.mark.parametrize("path", MODULES, ids=lambda p: _module_name(p))
def test_imports_point_one_way(path: Path) -> None:
    me = _module_name(path)
    imports = _imports(path)
    if not (_in(me, "rattle.demo") or _in(me, "rattle.cli")):
        assert not [m for m, _ in imports if _in(m, "rattle.demo")], f"{me} imports rattle.demo"
    if _in(me, "rattle.results"):
        bad = [m for m, top in imports if top and any(_in(m, p) for p in ("rattle.io", "rattle.plotting",
                                                                               "rattle.analysis"))]
        assert not bad, f"{me} imports {bad} when loaded; import them inside the delegate method"
    if _in(me, "rattle.plotting"):
        bad = [m for m, _ in imports if any(_in(m, p) for p in ("rattle.analysis", "rattle.demo", "rattle.cli"))]
        assert not bad, f"{me} imports {bad}"
    if _in(me, "rattle.files"):  # the file primitives: below every layer that writes
        bad = [m for m, _ in imports if _in(m, "rattle") and not any(_in(m, p) for p in ("rattle.files", "rattle.errors",
                                                                                        "rattle._release", "rattle._lazy"))]
        assert not bad, f"{me} imports {bad}: rattle.files knows no model, result or configuration"
    if _in(me, "rattle.model"):  # the ground floor: its own modules and the helpers below it only
        below = ("rattle.model", "rattle.errors", "rattle._limits", "rattle._typing", "rattle._validate", "rattle._table_checks",
                 "rattle.files")
        bad = [m for m, _ in imports if _in(m, "rattle") and m != "rattle" and not any(_in(m, p) for p in below)]
        assert not bad, f"{me} imports {bad}: the model knows no configuration reader, analysis, result or front end"
    if _in(me, "rattle.cli"):
        heavy = [m for m, top in imports if top and any(_in(m, p) for p in ("rattle.demo", "rattle.analysis"))]
        assert not heavy, f"{me} imports {heavy} when loaded; import them inside the command"


def test_the_model_rule_catches_an_import_of_io_inside_a_method(tmp_path: Path, monkeypatch) -> None:
    """The rule above sees an import made inside a method (the arrow ``Model.from_toml`` once drew)."""
    fake = tmp_path / "rattle" / "model" / "_reader.py"
    fake.parent.mkdir(parents=True)
    fake.write_text("class M:\n    def from_toml(cls, path):\n        from ..io import load_config\n\n"
                    "        return load_config(path).model\n", encoding="utf-8")
    monkeypatch.setitem(globals(), "SRC", tmp_path / "rattle")
    with pytest.raises(AssertionError, match=r"rattle\.model\._reader imports \['rattle\.io', 'rattle\.io\.load_config'\]"):
        test_imports_point_one_way(fake)


def test_moved_column_lists_still_answer_from_io_with_a_warning() -> None:
    import rattle.io
    import rattle.results

    for name in ("FRF_COLUMNS", "SWEEP_COLUMNS", "ORBIT_COLUMNS"):
        with pytest.warns(DeprecationWarning, match=f"`rattle.io.{name}` is deprecated; import it from rattle.results"):
            assert getattr(rattle.io, name) == getattr(rattle.results, name)
    assert "FRF_COLUMNS" not in rattle.io.__all__


# ---------------------------------------------------------------------------------------------
# Packages talk through their public module APIs: no reach-in into another package's _private module
# ---------------------------------------------------------------------------------------------
#: Private modules of other packages that may be imported: none (issue 23: 0 reach-ins, counted
#: from the source by :func:`_private_reach_ins`). Kept as the place to name one, with its reason,
#: should a restructuring ever need a step in between.
PRIVATE_TARGETS_ALLOWED: tuple[str, ...] = ()

#: (importing module, private module) pairs allowed: none.
PRIVATE_IMPORTS_ALLOWED: frozenset[tuple[str, str]] = frozenset()


def _package(module: str) -> str:
    """``rattle.X`` of a module ``rattle.X…`` (``rattle`` itself for the root package)."""
    return ".".join(module.split(".")[:2])


def _private_reach_ins(paths: list[Path]) -> list[tuple[str, str]]:
    """``(importing module, private module)`` for every import, by a module of package ``rattle.X``,
    of ``rattle.Y._private`` (or of a name from it) with Y ≠ X: imports inside functions and
    ``TYPE_CHECKING`` blocks included, relative ones resolved. ``rattle._x`` modules (``_validate``,
    ``_limits``, ``_lazy``, ``_typing`` …) are the root package's shared helpers, not a package's
    private modules."""
    found: list[tuple[str, str]] = []
    for path in paths:
        me = _module_name(path)
        for name, _ in _imports(path):
            parts = name.split(".")
            if len(parts) < 3 or parts[0] != "rattle" or parts[1].startswith("_"):
                continue
            private = parts[2].startswith("_") and not parts[2].startswith("__")
            target = ".".join(parts[:3])
            if private and _package(target) != _package(me) and (me, target) not in found:
                found.append((me, target))
    return found


def _check_private_imports(paths: list[Path]) -> None:
    bad = [(me, target) for me, target in _private_reach_ins(paths)
           if (me, target) not in PRIVATE_IMPORTS_ALLOWED and not any(_in(target, p) for p in PRIVATE_TARGETS_ALLOWED)]
    assert not bad, (
        f"{len(bad)} import(s) of another package's private module: "
        + "; ".join(f"{me} imports {target}" for me, target in bad)
        + " — import the name from the package (export it in its __init__ and __all__, and in its lazy table "
        "if it has one)"
    )


def test_packages_import_each_other_through_their_public_modules() -> None:
    """A module imports another package's names from the package (its ``__init__`` exports them),
    never from that package's ``_private`` modules: 0 such imports in the source."""
    _check_private_imports(MODULES)
    assert _private_reach_ins(MODULES) == []


def test_the_private_import_rule_names_the_importer_and_the_target(tmp_path: Path, monkeypatch) -> None:
    """A new reach-in fails, naming both modules, whether at module level or inside a function;
    the root package's ``rattle._x`` helpers and a package's public names pass."""
    extra = tmp_path / "rattle" / "cli" / "_extra.py"
    extra.parent.mkdir(parents=True)
    extra.write_text("from ..maps import response_map\nfrom .. import _validate\nfrom .._limits import check_magnitude\n"
                     "from ._other import x\n\n\n"
                     "def f():\n    from ..plotting._sweep import period_label\n\n    return period_label\n",
                     encoding="utf-8")
    monkeypatch.setitem(globals(), "SRC", tmp_path / "rattle")
    assert _private_reach_ins([extra]) == [("rattle.cli._extra", "rattle.plotting._sweep")]
    with pytest.raises(AssertionError, match=r"1 import\(s\) .*: rattle\.cli\._extra imports rattle\.plotting\._sweep —"):
        _check_private_imports([extra])
