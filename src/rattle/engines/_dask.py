"""The Dask engine: the tasks on a Dask distributed cluster (``rattle map --scheduler ADDRESS``).

Each task is submitted with ``pure=False`` under a readable key (``rattle-<task key>-<index>-<run>``);
results come back through ``distributed.as_completed`` and ``on_result`` is called in the calling
thread as each arrives. A worker lost mid-task is the scheduler's business: it runs the task again
on another worker (up to its ``distributed.scheduler.allowed-failures``, default 3; then the run
fails with :class:`~rattle.engines.EngineError`). A task that raises is not retried: the run ends
with :class:`~rattle.engines.TaskError`, every unfinished task cancelled.

Worker settings for rattle's tasks (CPU-bound, much of it pure Python): Dask's defaults cost a
map cell 1.5× its time in a plain process (measured on the reference map, α = 0.15: 14.7 s in a
process, 21.4 s in a default worker). Two settings account for all of it, and
:data:`WORKER_CONFIG` switches both off: the workers' statistical profiler (a stack sample every
10 ms, taking the GIL) and the ``MALLOC_TRIM_THRESHOLD_`` the nanny exports (a fixed glibc trim
threshold also fixes the mmap threshold, so every large numpy temporary is mapped and unmapped
again). The LocalCluster this engine starts uses them; for a cluster of your own, start its
workers with them (``DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False`` and
``distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_: null``, or
:func:`local_cluster`).

``distributed`` is imported here only when a run needs it (an optional dependency: ``pip install
'rattle[dask]'``). Workers of a remote cluster must have rattle installed (the same version: the
function is sent by reference).
"""

from __future__ import annotations

import importlib.util
import re
import socket
import struct
import threading
import time
import uuid
from collections.abc import Callable, Sequence
from typing import Any

from ..errors import ConfigError
from ._base import (
    EngineError,
    ProgressCallback,
    ResultCallback,
    Task,
    TaskError,
    check_run,
    check_workers,
    cpu_count,
)

#: Seconds to wait for a scheduler to answer before giving up.
CONNECT_TIMEOUT = 10.0

_INSTALL = "install it with `pip install 'rattle[dask]'` (or `pip install 'dask[distributed]'`)"


#: Dask configuration of workers that run rattle's tasks (see the module docstring).
WORKER_CONFIG: dict[str, Any] = {
    "distributed.worker.profile.enabled": False,
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
}


def local_cluster(workers: int | None = None, **options: Any) -> Any:
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes (default:
    the CPUs) configured with :data:`WORKER_CONFIG`; ``options`` go to LocalCluster."""
    import dask
    import distributed

    kwargs = {"n_workers": workers, "threads_per_worker": 1, "processes": True, "dashboard_address": None,
              **options}
    with dask.config.set(WORKER_CONFIG):
        return distributed.LocalCluster(**kwargs)


def dask_available() -> bool:
    """Whether ``distributed`` can be imported (without importing it)."""
    return importlib.util.find_spec("distributed") is not None


#: The address schemes of Dask's communication layer.
SCHEMES: tuple[str, ...] = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
#: Largest first message a scheduler sends (its handshake, a few hundred bytes): what announces
#: more is not Dask.
_MAX_HANDSHAKE = 1 << 24


def _refuse(address: str, why: str) -> ConfigError:
    return ConfigError(f"`--scheduler` {address!r} is not a Dask scheduler address: it {why}; use the address "
                       "`dask scheduler` prints, e.g. tcp://127.0.0.1:8786, or leave --scheduler out to run on local "
                       "processes")


def _unanswered(address: str, timeout: float, why: str) -> ConfigError:
    return ConfigError(f"`--scheduler` {address!r}: no Dask scheduler answered within {timeout:g} s ({why}); start "
                       "one (`dask scheduler`, then `dask worker ADDRESS`) or give the address it prints, e.g. "
                       "tcp://127.0.0.1:8786")


def check_scheduler_address(address: str, timeout: float | None = None, *, probe: bool = True) -> str:
    """Check that ``address`` is a Dask scheduler's, before a client is made: the form
    (``[scheme://]host:port``, a scheme of :data:`SCHEMES`, a port 1 … 65535) at once, and for
    ``tcp`` that a scheduler answers there within ``timeout`` seconds: the connection is made and
    the scheduler's handshake — which a Dask scheduler sends first, unasked — is awaited
    (``timeout`` default :data:`CONNECT_TIMEOUT`; ``probe=False``: the form only). An
    unroutable address, a closed port, a host that is not found, or a server of another protocol
    (an HTTP server waits for a request and says nothing) are refused with one line; nothing here
    waits longer than ``timeout`` (the name lookup included). Returns the address, stripped.

    Raises
    ------
    ConfigError
        Naming ``--scheduler``, the address and what is wrong.
    """
    timeout = CONNECT_TIMEOUT if timeout is None else float(timeout)  # the module's, read now
    text = address.strip()
    if not text or any(ord(c) < 32 or c.isspace() for c in text):
        raise _refuse(address, "is blank or holds spaces or control characters")
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if scheme not in SCHEMES:
        raise _refuse(address, f"has the scheme {scheme!r}, which Dask does not know (it knows {', '.join(SCHEMES)})")
    if scheme == "inproc":
        return text
    host, colon, port_text = rest.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if not colon or not host or not port_text.isdigit() or not 1 <= int(port_text) <= 65535 or "/" in host:
        raise _refuse(address, "is not of the form [scheme://]host:port with a port 1 … 65535")
    if scheme != "tcp" or not probe:  # TLS, websockets, UCX: the client's own timeout bounds the connection
        return text
    verdict: list[str | None] = []

    def probe() -> None:
        try:
            with socket.create_connection((host, int(port_text)), timeout=timeout) as sock:
                sock.settimeout(max(0.05, deadline - time.monotonic()))
                head = b""
                while len(head) < 8:
                    chunk = sock.recv(8 - len(head))
                    if not chunk:
                        verdict.append("the server there closed the connection without a Dask handshake")
                        return
                    head += chunk
            (size,) = struct.unpack("<Q", head)
            ok = 8 <= size <= _MAX_HANDSHAKE
            verdict.append(None if ok else "the server there answered, but not in Dask's protocol")
        except socket.gaierror as exc:
            verdict.append(f"the host cannot be found: {exc.strerror or exc}")
        except ConnectionRefusedError:
            verdict.append("connection refused: nothing listens at that port")
        except TimeoutError:
            verdict.append("no handshake: an unroutable or filtered address, or a server of another protocol "
                           "such as HTTP")
        except OSError as exc:
            verdict.append(f"cannot be reached: {exc.strerror or exc}")

    deadline = time.monotonic() + timeout
    thread = threading.Thread(target=probe, name="rattle-scheduler-probe", daemon=True)
    thread.start()
    thread.join(timeout + 0.5)  # a name lookup has no timeout of its own: the thread is left behind
    if not verdict:
        raise _unanswered(address, timeout, "the host name was not resolved in time")
    if verdict[0] is not None:
        raise _unanswered(address, timeout, verdict[0])
    return text


def _key_text(key: Any) -> str:
    return re.sub(r"[^A-Za-z0-9_.=,+-]+", "_", str(key))[:120]


class DaskEngine:
    """Runs the tasks on a Dask distributed cluster.

    Parameters
    ----------
    scheduler : str, distributed.Client or distributed.LocalCluster (or any cluster), optional
        The scheduler's address (``tcp://host:8786``), a connected client (used, not closed), or
        a cluster object (a client is opened on it and closed after each run). None: a
        ``LocalCluster`` of ``workers`` single-threaded worker processes is started for each run
        and closed after it.
    workers : int, optional
        Only with ``scheduler=None``: the LocalCluster's worker processes (default: the CPUs).
    timeout : float
        Seconds to wait for the scheduler (default 10).

    ``workers`` is, after :meth:`connect`, the number of worker threads of the cluster.
    """

    name = "dask"

    def __init__(self, scheduler: Any = None, workers: int | None = None, *,
                 timeout: float | None = None) -> None:
        if not dask_available():
            raise ConfigError(f"`--scheduler` runs a map on Dask distributed, which is not installed: {_INSTALL}")
        requested = check_workers(workers)
        if scheduler is not None and requested is not None:
            raise ValueError(
                f"`workers` ({requested}) applies only to the LocalCluster started when no `scheduler` is given; "
                "a cluster's size is set where the cluster is started"
            )
        if scheduler is not None and not isinstance(scheduler, str) and not hasattr(scheduler, "submit") \
                and not hasattr(scheduler, "scheduler_address"):
            raise TypeError(
                f"`scheduler` must be an address ('tcp://host:8786'), a distributed.Client or a cluster, got {scheduler!r}"
            )
        if isinstance(scheduler, str) and not scheduler.strip():
            raise ConfigError("`--scheduler` must be a Dask scheduler address such as tcp://host:8786, got ''")
        self.scheduler = scheduler
        self.timeout = float(CONNECT_TIMEOUT if timeout is None else timeout)
        if not (self.timeout > 0 and self.timeout < 3600):
            raise ValueError(f"`timeout` must be a number of seconds in (0, 3600), got {timeout!r}")
        self.workers = requested if requested is not None else (cpu_count() if scheduler is None else 0)
        self.last_run: dict[str, Any] = {}

    def __repr__(self) -> str:
        where = "LocalCluster" if self.scheduler is None else repr(self.scheduler)
        return f"DaskEngine({where}, workers={self.workers})"

    # -----------------------------------------------------------------------------------------
    def connect(self) -> tuple[Any, Callable[[], None]]:
        """A client on the cluster and the function that releases what this call opened.

        Raises ConfigError naming ``--scheduler`` when the scheduler cannot be reached within
        ``timeout`` seconds.
        """
        try:
            import distributed
        except ImportError as exc:  # pragma: no cover - find_spec said yes
            raise ConfigError(f"`--scheduler` needs Dask distributed, which cannot be imported ({exc}): {_INSTALL}") \
                from None
        s = self.scheduler
        if isinstance(s, distributed.Client):
            self.workers = self._threads(s) or self.workers
            return s, lambda: None
        if s is None:
            cluster = local_cluster(self.workers)
            try:
                client = distributed.Client(cluster, timeout=self.timeout, set_as_default=False)
            except BaseException:
                cluster.close()
                raise

            def release() -> None:
                client.close()
                cluster.close()

            return client, release
        where = s if isinstance(s, str) else getattr(s, "scheduler_address", s)
        if isinstance(s, str):
            s = check_scheduler_address(s, self.timeout)  # refused at once, or within the timeout
        try:
            client = distributed.Client(s, timeout=self.timeout, set_as_default=False)
        except (OSError, TimeoutError, RuntimeError) as exc:
            raise ConfigError(
                f"`--scheduler` {where!r}: no Dask scheduler answered within {self.timeout:g} s "
                f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]}); "
                "start one (`dask scheduler`, then `dask worker ADDRESS`) or give the address it prints, "
                "e.g. tcp://127.0.0.1:8786"
            ) from None
        except ValueError as exc:
            raise ConfigError(f"`--scheduler` {where!r} is not a Dask scheduler address ({exc}); "
                              "use e.g. tcp://127.0.0.1:8786") from None
        self.workers = self._threads(client) or self.workers
        return client, client.close

    @staticmethod
    def _confirm_cancelled(client: Any, keys: Sequence[Any], timeout: float = 5.0) -> None:
        """Wait (at most ``timeout`` s) until the scheduler holds none of ``keys`` in memory.

        ``Client.cancel`` only queues the cancellation on the client's batched stream and returns;
        a task submitted just before (its graph queued on the same stream) may still finish and be
        held for a moment. A run that ends leaves nothing of its own on a shared cluster, so the
        scheduler is asked until it has released them (a handful of round trips).
        """
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            states = client.sync(client.scheduler.get_task_status, keys=list(keys))
            if all(state in (None, "released", "forgotten") for state in states.values()):
                return
            time.sleep(0.01)

    @staticmethod
    def _threads(client: Any) -> int:
        try:
            return int(sum(client.nthreads().values()))
        except Exception:  # pragma: no cover - information only
            return 0

    # -----------------------------------------------------------------------------------------
    def run(self, fn: Callable[[Any], Any], tasks: Sequence[Task], on_result: ResultCallback,
            progress: ProgressCallback | None = None) -> None:
        items = check_run(fn, tasks, on_result, progress, pickled=True)
        total = len(items)
        t0 = time.time()
        self.last_run = {"wall": 0.0, "startup": None}
        if total == 0:
            return
        import distributed

        client, release = self.connect()
        self.last_run["startup"] = time.time() - t0
        futures: dict[Any, Any] = {}
        try:
            run_id = uuid.uuid4().hex[:8]
            # At most one task per worker thread is handed to the scheduler at a time (the next
            # when one finishes): given them all, the scheduler assigns some ahead of time, and a
            # long task can wait behind another on a busy worker while another worker idles.
            window = max(1, self._threads(client) or self.workers or 1)
            pending = iter(enumerate(items))
            completed = distributed.as_completed(loop=client.loop)

            def submit_next() -> None:
                item = next(pending, None)
                if item is None:
                    return
                i, (key, payload) = item
                future = client.submit(fn, payload, key=f"rattle-{_key_text(key)}-{i}-{run_id}", pure=False)
                futures[future] = key
                completed.add(future)

            for _ in range(window):
                submit_next()
            done = 0
            for future in completed:
                key = futures[future]
                if future.status == "error":
                    exc = future.exception()
                    if isinstance(exc, distributed.KilledWorker):
                        raise EngineError(
                            f"task `{key}` was lost: the Dask workers running it died too often ({exc}); "
                            "a task that kills its process needs a fix or more memory; run with the serial "
                            "engine (--workers 1) to see the error", key,
                        ) from exc
                    raise TaskError(key, exc) from exc
                if future.status == "cancelled":
                    raise EngineError(f"task `{key}` was cancelled on the Dask cluster (by someone else?)", key)
                result = future.result()
                future.release()
                del futures[future]
                submit_next()
                done += 1
                on_result(key, result)
                if progress is not None:
                    progress(done, total)
        finally:
            if futures:
                try:
                    keys = [f.key for f in futures]
                    client.cancel(list(futures), force=True)
                    futures.clear()
                    self._confirm_cancelled(client, keys)
                except Exception:  # pragma: no cover - the client is going anyway
                    pass
            release()
            self.last_run["wall"] = time.time() - t0
