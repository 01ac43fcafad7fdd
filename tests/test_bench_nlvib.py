"""benchmarks/bench_nlvib.py without Octave or NLvib: it says how to get them and exits 0 ("skipped").

The benchmark itself (NLvib beside rattle, both timed) needs GNU Octave and an NLvib checkout that
the user fetches; without them it must not fail, so that it runs anywhere."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_nlvib.py"


def _bench(monkeypatch):
    spec = importlib.util.spec_from_file_location("bench_nlvib", BENCH)
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "bench_nlvib", module)  # its dataclass looks its module up
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("given, missing", [
    (["--octave", "no-such-octave-here", "--nlvib", str(BENCH.parent)], "no Octave (no-such-octave-here not found)"),
    (["--nlvib", "/no/such/NLvib"], "no NLvib checkout at /no/such/NLvib (SRC/solve_and_continue.m missing)"),
    ([], "no NLvib checkout (neither --nlvib nor NLVIB_PATH given)"),
])
def test_skips_and_says_how_to_get_octave_and_nlvib(given, missing, monkeypatch, capsys):
    monkeypatch.delenv("NLVIB_PATH", raising=False)
    assert _bench(monkeypatch).main(given) == 0
    out = capsys.readouterr().out
    assert out.startswith("bench_nlvib: skipped — ") and missing in out
    assert "apt-get install octave" in out
    assert "git clone https://github.com/maltekrack/NLvib" in out
