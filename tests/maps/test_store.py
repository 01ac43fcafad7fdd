"""MapStore: one atomic JSON part per finished combination, read back bit for bit; a damaged part
is treated as missing; any difference in the task gives another key."""

from __future__ import annotations

import json
import math
import os
import time

import numpy as np
import pytest

import rattle.maps._store as store_module
from rattle.maps._store import PARTS_FOLDER, MapStore, canonical_json

FINGERPRINT = {
    "config": {"model": {"elastic": {"alpha": 0.1, "stages": [1.0, 0.05]}}, "excitation": {"mean": 0.3}},
    "values": {"alpha": 0.1},
    "settings": {"harmonics": 32, "omega": [0.1, 3.0], "points": 146},
}


def _awkward_floats() -> list:
    rng = np.random.default_rng(7)
    return [0.1, 1 / 3, 5e-324, 1.7976931348623157e308, -0.0, math.pi * 1e-17, None,
            *[float(x) for x in rng.standard_normal(50) * 10.0 ** rng.integers(-300, 300, 50)]]


def test_save_then_load_is_bit_exact(tmp_path) -> None:
    store = MapStore(tmp_path / "out")
    key = store.key(FINGERPRINT)
    result = {"values": {"alpha": 0.1}, "rms_max_stable": _awkward_floats(), "rattle": [True, False],
              "regime_max_stable": ["impact", ""], "n_stable": [0, 1, 2], "timings": {"total": 1.25}}
    assert store.load(key) is None and store.finished() == set()
    path = store.save(key, result, fingerprint=FINGERPRINT)
    assert path == tmp_path / "out" / PARTS_FOLDER / f"{key}.json"
    back = store.load(key)
    assert back == result
    for a, b in zip(back["rms_max_stable"], result["rms_max_stable"]):  # bit for bit (also -0.0)
        assert (a is None and b is None) or (np.float64(a).tobytes() == np.float64(b).tobytes())
    assert store.finished() == {key}
    assert json.loads(path.read_text())["fingerprint"] == FINGERPRINT
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary file left


def test_a_cell_result_round_trips_through_the_store(tmp_path) -> None:
    from rattle.maps import CellResult

    n = 5
    cell = CellResult(
        values={"alpha": 0.1}, omega=np.linspace(0.1, 3.0, n), n_solutions=np.array([1, 3, 3, 1, 1]),
        n_stable=np.array([1, 2, 2, 0, 1]), rms_max_stable=np.array([0.1, 1 / 3, np.nan, 2.0, 1e-9]),
        rms_ac_max_stable=np.array([0.01, 0.2, np.nan, 1.5, 0.0]),
        regime_max_stable=np.array(["no impact", "impact", "", "impact", "no impact"], dtype=object),
        periods_stable=np.array(["1", "1;2", "0", "1", "1"], dtype=object),
        rattle=np.array([False, True, True, True, False]),
    )
    store = MapStore(tmp_path)
    key = store.key(FINGERPRINT)
    store.save(key, cell.to_dict())
    back = CellResult.from_dict(store.load(key), resumed=True)
    assert back.rms_max_stable.tobytes() == cell.rms_max_stable.tobytes()
    assert back.omega.tobytes() == cell.omega.tobytes() and back.resumed
    assert list(back.periods_stable) == list(cell.periods_stable)


def test_the_write_is_atomic(tmp_path, monkeypatch) -> None:
    store = MapStore(tmp_path)
    key = store.key(FINGERPRINT)
    store.save(key, {"v": 1})
    real_replace = os.replace

    def crash(*args):
        raise OSError("disk gone")

    monkeypatch.setattr(os, "replace", crash)  # the write dies before the rename
    with pytest.raises(OSError, match="disk gone"):
        store.save(key, {"v": 2})
    monkeypatch.setattr(os, "replace", real_replace)
    assert store.load(key) == {"v": 1}  # the old part, whole
    assert [p.name for p in store.parts.iterdir()] == [f"{key}.json"]  # the temporary file removed
    assert store_module.atomic_write_text.__module__ == "rattle.files._atomic"


@pytest.mark.parametrize("damage", ["truncated", "empty", "not json", "other key", "not a dict", "binary"])
def test_a_damaged_part_is_treated_as_missing(tmp_path, damage) -> None:
    store = MapStore(tmp_path)
    key = store.key(FINGERPRINT)
    path = store.save(key, {"rms": [0.1, 0.2]})
    text = path.read_text()
    bad = {
        "truncated": text[: len(text) // 2],
        "empty": "",
        "not json": "rattle",
        "other key": text.replace(key, "0" * 64),
        "not a dict": "[1, 2]",
    }
    if damage == "binary":
        path.write_bytes(b"\xff\xfe\x00garbage")
    else:
        path.write_text(bad[damage])
    assert store.load(key) is None  # no exception: recomputed
    store.save(key, {"rms": [0.1, 0.2]})  # and replaced
    assert store.load(key) == {"rms": [0.1, 0.2]}


def test_keys_differ_with_any_difference_in_the_task() -> None:
    key = MapStore.key(FINGERPRINT)
    assert len(key) == 64 and key == MapStore.key(json.loads(json.dumps(FINGERPRINT)))
    reordered = {k: FINGERPRINT[k] for k in reversed(list(FINGERPRINT))}
    assert MapStore.key(reordered) == key  # order of keys does not matter
    changed = [
        {**FINGERPRINT, "values": {"alpha": 0.1 + 2 ** -55}},  # the next double
        {**FINGERPRINT, "settings": {**FINGERPRINT["settings"], "harmonics": 33}},
        {**FINGERPRINT, "settings": {**FINGERPRINT["settings"], "points": 146.0}},  # 146.0 is not 146
        {**FINGERPRINT, "command": "map"},
    ]
    keys = {MapStore.key(f) for f in changed}
    assert len(keys) == len(changed) and key not in keys
    assert MapStore.key({"x": np.float64(0.25), "y": np.arange(3)}) == MapStore.key({"x": 0.25, "y": [0, 1, 2]})
    with pytest.raises(TypeError, match="no canonical JSON form"):
        MapStore.key({"x": object()})
    assert canonical_json({"b": 1, "a": [1.0, None]}) == '{"a":[1.0,null],"b":1}'


def test_the_rattle_version_is_part_of_the_key(monkeypatch) -> None:
    key = MapStore.key(FINGERPRINT)
    monkeypatch.setattr(store_module, "rattle_version", lambda: "99.0")
    assert MapStore.key(FINGERPRINT) != key


def test_finished_and_clear_stale(tmp_path) -> None:
    store = MapStore(tmp_path)
    keys = [store.key({"i": i}) for i in range(3)]
    for k in keys:
        store.save(k, {"k": k})
    (store.parts / f".{keys[0]}.json.abc.tmp.json").write_text("{")  # left by a killed write
    (store.parts / "notes.txt").write_text("mine")
    assert store.finished() == set(keys)
    removed = store.clear_stale(keep=keys[:2])
    assert removed == sorted([f"{keys[2]}.json", f".{keys[0]}.json.abc.tmp.json"])
    assert store.finished() == set(keys[:2]) and (store.parts / "notes.txt").exists()
    with pytest.raises(ValueError, match="`key`"):
        store.load("../escape")
    assert MapStore(tmp_path / "nothing").finished() == set()


def test_clear_orphans_removes_only_old_temporaries(tmp_path) -> None:
    store = MapStore(tmp_path)
    key = store.key({"i": 1})
    store.save(key, {"k": 1})
    old = store.parts / f".{key}.json.abc.tmp.json"
    fresh = store.parts / f".{key}.json.xyz.tmp.json"
    old.write_text("{")
    fresh.write_text("{")
    past = time.time() - 3600
    os.utime(old, (past, past))
    assert store.clear_orphans(min_age=60.0) == [old.name]
    assert fresh.exists() and not old.exists() and store.finished() == {key}
    assert MapStore(tmp_path / "nothing").clear_orphans() == []
