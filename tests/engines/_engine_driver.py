"""A small map run in its own process (for the SIGKILL-and-resume test):

    python _engine_driver.py OUT N SLEEP SLOW CALLS

runs ``compute`` over N tasks (the first three sleep SLEEP seconds, the others SLOW) on 2 local worker processes, each result saved in a MapStore in OUT
as it arrives; finished tasks found in the store are not run again (the sleeps are not part of
the key). Prints "saved <task>" as each result is saved and "done" at the end.
"""

from __future__ import annotations

import sys
from pathlib import Path

if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _engine_tasks import compute, make_tasks

    from rattle.engines import ProcessEngine
    from rattle.maps._store import MapStore

    out, n, sleep, slow, calls = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
    store = MapStore(out)
    tasks = make_tasks(n, calls=calls)
    for i, (_, payload) in enumerate(tasks):
        payload["sleep"] = sleep if i < 3 else slow
    keys = {name: store.key({"name": name, "x": payload["x"]}) for name, payload in tasks}
    todo = [(name, payload) for name, payload in tasks if store.load(keys[name]) is None]

    def on_result(name: str, result: dict) -> None:
        store.save(keys[name], result)
        print("saved", name, flush=True)

    ProcessEngine(2).run(compute, todo, on_result)
    print("done", flush=True)
