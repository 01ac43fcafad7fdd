"""rattle._jit: the kernels' one compile setting, and numba's cached kernels loaded with the
runtime only (the command line's light load: no import of numba's lowering library)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rattle import _jit

SRC = Path(__file__).resolve().parents[1] / "src"

pytestmark = pytest.mark.skipif(_jit.numba is None, reason="numba is not installed")

#: A fresh process: hb's compiled force samples on a few deflections, loaded from (or written to)
#: the cache in NUMBA_CACHE_DIR; ``light`` installs the light load first; ``compile`` then asks for
#: a signature that is not in the cache (float32 deflections: compiled, with numba's full refresh).
_PROBE = r"""
import json, sys
import numpy as np
from rattle import _jit
mode = sys.argv[1]
if mode in ("light", "compile"):
    assert _jit.load_cached_lightly() and _jit.load_cached_lightly()  # installed once; a second call is a no-op
from rattle.hb import _kernels
delta = np.array([-2.0, -0.5, 0.0, 0.3, 1.7, np.nan])
bp, slopes, offsets = np.array([-1.0, 1.0]), np.array([2.0, 0.5, 3.0]), np.array([1.0, 0.0, -2.5])
out = np.empty((2, delta.size))
_kernels.force_samples(delta, bp, slopes, offsets, out)
reference = np.empty_like(out)
_kernels.force_samples.py_func(delta, bp, slopes, offsets, reference)
result = {"out": [[repr(float(v)) for v in row] for row in out],
          "same_as_python": bool(np.array_equal(out, reference, equal_nan=True)),
          "cache_hits": int(sum(_kernels.force_samples.stats.cache_hits.values())),
          "lowering_library_loaded": "numba.cpython.setobj" in sys.modules}
if mode == "compile":
    out32 = np.empty((2, delta.size))
    _kernels.force_samples(delta.astype(np.float32), bp, slopes, offsets, out32)
    reference32 = np.empty_like(out32)
    _kernels.force_samples.py_func(delta.astype(np.float32), bp, slopes, offsets, reference32)
    result["compiled_same"] = bool(np.array_equal(out32, reference32, equal_nan=True))
print(json.dumps(result))
"""


def _run(mode: str, cache: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", _PROBE, mode], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_cached_kernel_loads_with_the_runtime_only_and_computes_the_same(tmp_path: Path) -> None:
    written = _run("plain", tmp_path)  # compiles and writes the cache
    assert written["same_as_python"] and written["cache_hits"] == 0
    plain = _run("plain", tmp_path)  # numba's own load: its whole lowering library imported
    assert plain["cache_hits"] == 1 and plain["lowering_library_loaded"]
    light = _run("light", tmp_path)
    assert light["cache_hits"] == 1, "the kernel was not loaded from the cache"
    assert not light["lowering_library_loaded"], "the light load imported numba's lowering library"
    assert light["out"] == plain["out"] == written["out"] and light["same_as_python"]


def test_after_a_light_load_a_new_signature_still_compiles(tmp_path: Path) -> None:
    _run("plain", tmp_path)
    mixed = _run("compile", tmp_path)
    assert mixed["cache_hits"] == 1 and mixed["same_as_python"]
    assert mixed["compiled_same"]  # compiled in the same process: numba refreshed its contexts itself


def test_the_light_load_is_the_command_lines_only() -> None:
    """Imported by a program (here pytest), rattle leaves numba's cache loading as it is."""
    from numba.core.caching import Cache

    assert not getattr(Cache.load_overload, "rattle_light", False)


def test_njit_is_numbas_njit_with_the_kernels_options() -> None:
    def add(a: float, b: float) -> float:
        return a + b

    kernel = _jit.njit(add)
    assert kernel.py_func is add
    assert {k: kernel.targetoptions.get(k) for k in ("nogil",)} == {"nogil": True}
    assert _jit.OPTIONS == {"cache": True, "error_model": "numpy", "nogil": True}
