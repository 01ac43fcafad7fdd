"""rattle.engines is a low layer: it imports nothing from rattle but rattle.errors (and itself),
and `import rattle.engines` loads neither numpy nor Dask."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import rattle.engines

ENGINES = Path(rattle.engines.__file__).resolve().parent


def test_engines_import_only_errors_from_rattle() -> None:
    for path in sorted(ENGINES.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level:
                assert node.level == 1 or node.module == "errors", f"{path.name} imports ..{node.module}"
                if node.level == 2:
                    assert node.module == "errors", f"{path.name} imports ..{node.module}"
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
                bad = [n for n in names if n.startswith("rattle") and n != "rattle.errors"]
                assert not bad, f"{path.name} imports {bad}"


def test_importing_the_engines_is_light() -> None:
    code = ("import sys, rattle.engines; "
            "print(sorted(m for m in ('numpy', 'distributed', 'dask', 'rattle.maps') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
