"""Run many independent cases locally or on a Dask cluster, with a resumable on-disk store.

One function does the work, :func:`run_cases`. A *case* is a mapping of JSON-able values with a
unique string ``"id"`` (a dict, or a mapping that also carries built objects for the function,
such as :class:`cavex.verification.fedata.cases.FECase`: the store keeps its items, the worker
receives the case itself); the *function* is a picklable top-level callable that takes a
*chunk* (a list of cases) and returns one entry per case: a JSON-able dict, or the exception
that case failed with. The work unit sent to a process or a Dask worker is a chunk, so a
function can treat its cases together (the FE cases run as stacks of one solver,
:func:`cavex.verification.fedata.cases.fe_cases`). Every result is passed through JSON inside
the worker, so a result read back from the store is bit-for-bit the one computed (floats are
written with ``repr``, which round-trips exactly).
"""

import contextlib
import ctypes
import fcntl
import json
import math
import multiprocessing
import os
import re
import signal
import socket
import sys
import threading
import time
import uuid
from collections.abc import Mapping
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

from cavex.errors import CavexInputError, require
from cavex.verification.output.files import write_text_atomic

STORE_SUFFIX = ".json"
TMP_SUFFIX = ".json.tmp"
_BAD_ID_CHARS = set('/\\\0:*?"<>|')


MAX_CHUNK = 200  # cases per work unit (the FE solver's stack size)
MAX_WORKERS_PER_CPU = 4  # local processes beyond this only compete for the cores
SCHEDULER_TIMEOUT = 10.0  # s: how long an unreachable Dask scheduler is waited for
_ADDRESS = re.compile(r"^(?:(?P<protocol>tcp|tls|ws|wss|ucx)://)?"
                      r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9][A-Za-z0-9.\-]*):(?P<port>\d{1,5})$")


def run_cases(function, cases, *, store=None, scheduler=None, workers=None, progress=None,
              chunk_size=None, while_running=None):
    """Run ``function`` on every case and return the results in the order of ``cases``.

    Parameters
    ----------
    function : callable
        Picklable top-level callable ``chunk(list of dict) -> list`` with, per case, a
        JSON-able dict or the exception the case failed with.
    cases : list of Mapping
        Mappings of JSON-able values (dicts, or :class:`~cavex.verification.fedata.cases.FECase`),
        each with a unique string key ``"id"`` (used as a file name).
    store : str or os.PathLike, optional
        Directory; each finished case is written atomically to ``store/<id>.json`` as soon as
        it finishes, and cases already stored there are loaded instead of recomputed.
    scheduler : str or dask.distributed.Client, optional
        None runs on local processes; an address (``"tcp://host:8786"``) or a ``Client`` runs
        on that Dask cluster.
    workers : int, optional
        Local processes (default ``os.cpu_count()``); 1 runs serially in this process. With a
        Dask scheduler it bounds nothing: the cluster's threads set the parallelism.
    progress : bool, optional
        Progress bar with ETA on stderr; None shows it when stderr is a terminal.
    chunk_size : int, optional
        Consecutive cases per work unit; default: see :func:`chunks`.
    while_running : callable, optional
        Called once, without arguments, in this process once the first work units have been
        handed to the worker processes (or the Dask cluster): work the caller needs afterwards
        (e.g. importing the libraries that write its results), done while the cases compute
        instead of after them. Not called when the cases run in this process (``workers`` 1)
        or none is left to run.

    Returns
    -------
    list of dict
        The function's result plus ``"id"`` and ``"status"`` (``"ok"``), or
        ``{"id", "status": "failed", "reason": "<one line>"}`` for a case that failed (or whose
        whole chunk raised).

    Raises
    ------
    CavexInputError
        Bad cases (missing, duplicate or unusable ids, not JSON-able), bad ``workers``, or a
        store that holds a different case under the same id.
    """
    cases = list(cases)
    _check_cases(cases)
    check_execution(workers, scheduler)
    if scheduler is not None and workers is not None:
        print(f"cavex: note: workers = {workers} is ignored: the Dask scheduler's workers run "
              "the cases", file=sys.stderr)
    workers = (os.cpu_count() or 1) if workers is None else workers
    with _locked(store):
        results = _load_store(store, cases) if store is not None else {}
        todo = [case for case in cases if case["id"] not in results]
        bar = Progress(len(cases), len(results), show_progress(progress))

        def finished(chunk, chunk_results):
            for case, result in zip(chunk, chunk_results, strict=True):
                if store is not None:
                    write_case(store, case, result)
                results[case["id"]] = result
                bar.update()

        try:
            if todo:
                _execute(function, todo, scheduler, workers, finished, chunk_size,
                         while_running)
        finally:
            bar.close()
    return [results[case["id"]] for case in cases]


def check_execution(workers, scheduler):
    """Check ``workers`` (None: one per CPU) and ``scheduler`` before anything is created; a
    malformed scheduler address is refused at once, an unreachable one after
    :data:`SCHEDULER_TIMEOUT` seconds (the message says so)."""
    _check_workers(workers)
    if isinstance(scheduler, str):
        _check_address(scheduler)


def check_store(store, cases):
    """Raise :class:`CavexInputError` if ``store`` holds a different case under one of the
    ids of ``cases`` (nothing is created or changed)."""
    if store is None or not os.path.isdir(store):
        return
    _compare_with_store(store, cases)


@contextlib.contextmanager
def _locked(store):
    """Hold an exclusive lock on ``store`` (a second run into the same store is refused)."""
    if store is None:
        yield
        return
    os.makedirs(store, exist_ok=True)
    handle = os.open(store, os.O_RDONLY)  # the folder itself is locked: no lock file
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise CavexInputError(f"store '{os.fspath(store)}' is in use by another cavex run; "
                                  "wait for it or use another output folder") from None
        yield
    finally:
        os.close(handle)


def run_chunk(function, chunk):
    """Call ``function(chunk)``; per case its JSON-normalised result with ``id`` and ``status``.

    A case's exception (returned in its place, or raised by the whole call) becomes
    ``{"status": "failed", "reason": "<ExceptionType: first line>"}``. This is what the workers
    execute; it is public so that cases can be debugged in this process.
    """
    try:
        results = list(function(chunk))
        if len(results) != len(chunk):
            raise TypeError(f"the chunk function returned {len(results)} results for "
                            f"{len(chunk)} cases")
    except Exception as exc:  # every failure is recorded, not raised
        results = [exc] * len(chunk)
    return [_normalised(case, result) for case, result in zip(chunk, results, strict=True)]


def _normalised(case, result):
    try:
        if isinstance(result, Exception):
            raise result
        if not isinstance(result, dict):
            raise TypeError(f"the chunk function returned {type(result).__name__}, not a dict")
        return json.loads(json.dumps({**result, "id": case["id"], "status": "ok"}))
    except Exception as exc:  # every failure of a case is recorded, not raised
        return {"id": case["id"], "status": "failed", "reason": one_line_reason(exc)}


def one_line_reason(exc):
    """``"ExceptionType: message"`` reduced to its first line."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")


# --- the store ----------------------------------------------------------------------------------

def case_path(store, case_id):
    """Path of the stored case ``case_id`` in ``store``."""
    return os.path.join(os.fspath(store), case_id + STORE_SUFFIX)


def write_case(store, case, result):
    """Atomically write ``{"case": case, "result": result}`` to ``store/<id>.json``.

    Not fsynced: a killed run loses nothing it wrote, and after an operating-system crash an
    entry that did not reach the disk is missing or unreadable, which :func:`read_store` treats
    as not computed (recomputed on resume)."""
    write_text_atomic(case_path(store, case["id"]),
                      json.dumps({"case": dict(case), "result": result}, indent=1),
                      durable=False)


def read_store(store):
    """All complete stored cases of ``store`` as ``{id: {"case": ..., "result": ...}}``."""
    entries = {}
    if not os.path.isdir(store):
        return entries
    for name in sorted(os.listdir(store)):
        if name.endswith(STORE_SUFFIX):
            entry = _read_entry(os.path.join(store, name))
            if entry is not None:
                entries[entry["case"]["id"]] = entry
    return entries


def _read_entry(path):
    """A stored case, or None when it is unreadable, not JSON of the stored shape or holds a
    non-finite number (treated as not computed: recomputed and rewritten)."""
    try:
        with open(path, encoding="utf-8") as handle:
            entry = json.load(handle, parse_constant=_reject_constant)
    except (OSError, ValueError):
        return None
    if not (isinstance(entry, dict) and {"case", "result"} <= entry.keys()
            and isinstance(entry["case"], dict) and isinstance(entry["result"], dict)
            and isinstance(entry["case"].get("id"), str)
            and entry["result"].get("id") == entry["case"]["id"]
            and entry["result"].get("status") in ("ok", "failed")):
        return None
    return entry


def _reject_constant(name):
    raise ValueError(f"non-finite number {name}")


def _load_store(store, cases):
    os.makedirs(store, exist_ok=True)
    _remove_stale_tmp(store)
    return _compare_with_store(store, cases)


def _compare_with_store(store, cases):
    stored = read_store(store)
    results = {}
    for case in cases:
        entry = stored.get(case["id"])
        if entry is None:
            continue
        if entry["case"] != _json_normalised(dict(case)):
            raise CavexInputError(f"store '{os.fspath(store)}' holds a different case under id "
                                  f"'{case['id']}'; use a new store directory")
        results[case["id"]] = entry["result"]
    return results


def _remove_stale_tmp(store):
    """Temporary files left by a killed run (the store is locked: none is in flight)."""
    for name in os.listdir(store):
        if name.endswith(TMP_SUFFIX) or (name.startswith(".") and name.endswith(".tmp")):
            try:
                os.remove(os.path.join(store, name))
            except FileNotFoundError:
                pass




def _json_normalised(value):
    return json.loads(json.dumps(value))


# --- checks -------------------------------------------------------------------------------------

def _check_cases(cases):
    seen = set()
    for i, case in enumerate(cases):
        require(isinstance(case, Mapping) and "id" in case, f"cases[{i}]",
                "a mapping with an 'id'", case)
        case_id = case["id"]
        require(_usable_id(case_id), f"cases[{i}].id",
                "a non-empty string usable as a file name (no path separators, not starting "
                "with '.')", case_id)
        require(case_id not in seen, f"cases[{i}].id", "unique", case_id)
        seen.add(case_id)
        try:
            json.dumps(dict(case), allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise CavexInputError(f"case '{case_id}' is not JSON-able: {exc}") from None


def _usable_id(case_id):
    return (isinstance(case_id, str) and 0 < len(case_id) <= 200 and not case_id.startswith(".")
            and not (_BAD_ID_CHARS & set(case_id)) and case_id.isprintable())


def _check_workers(workers):
    cpus = os.cpu_count() or 1
    if workers is None:
        return cpus
    most = MAX_WORKERS_PER_CPU * cpus
    require(isinstance(workers, int) and not isinstance(workers, bool) and 1 <= workers <= most,
            "workers", f"an integer in [1, {most}] ({MAX_WORKERS_PER_CPU} per CPU)", workers)
    return workers


class SchedulerAddress(str):
    """A Dask scheduler address (``tls://host:port``) with the TLS files to reach it: the
    certificate authority ``ca`` (the scheduler's certificate is checked against it) and this
    client's certificate ``cert`` and key ``key``. A ``str`` everywhere an address goes; the
    connection (:func:`_connect`) uses :meth:`security`."""

    def __new__(cls, address, ca, cert=None, key=None):
        made = super().__new__(cls, address)
        made.ca, made.cert, made.key = ca, cert, key
        return made

    def security(self):
        """The :class:`distributed.Security` of this address: encryption required."""
        from distributed import Security

        return Security(tls_ca_file=self.ca, tls_client_cert=self.cert,
                        tls_client_key=self.key, require_encryption=True)


def scheduler_with_tls(address, ca=None, cert=None, key=None):
    """``address`` (None: no scheduler) with the TLS files of ``--scheduler-tls-ca``,
    ``--scheduler-tls-cert`` and ``--scheduler-tls-key`` (:class:`SchedulerAddress`); without
    them the address as it is. The files must be readable, the address ``tls://``, the
    certificate and key given together."""
    if ca is None and cert is None and key is None:
        if isinstance(address, str) and address.startswith("tls://") and not _dask_tls():
            raise CavexInputError(f"parameter 'scheduler' must be given with "
                                  f"--scheduler-tls-ca FILE for a tls:// address (got "
                                  f"{address!r}; or set Dask's distributed.comm.tls)")
        return address
    require(address is not None, "scheduler-tls-ca", "given with --scheduler tls://HOST:PORT",
            ca or cert or key)
    require(ca is not None, "scheduler-tls-ca", "a CA file (with --scheduler-tls-cert/key)",
            ca)
    require((cert is None) == (key is None), "scheduler-tls-cert",
            "given with --scheduler-tls-key (both or neither)", cert)
    require(str(address).startswith("tls://"), "scheduler",
            "a tls:// address with --scheduler-tls-*", address)
    for option, path in (("scheduler-tls-ca", ca), ("scheduler-tls-cert", cert),
                         ("scheduler-tls-key", key)):
        if path is not None:
            require(os.path.isfile(path) and os.access(path, os.R_OK), option,
                    "a readable file", path)
    return SchedulerAddress(address, ca, cert, key)


def _dask_tls():
    """Whether Dask's configuration names a TLS certificate authority for clients."""
    import dask

    return bool(dask.config.get("distributed.comm.tls.ca-file", None))


def _check_address(address):
    match = _ADDRESS.match(address)
    require(match is not None and 0 < int(match["port"]) < 65536, "scheduler",
            "a Dask scheduler address such as 'tcp://127.0.0.1:8786'", address)
    host = match["host"].strip("[]")
    try:
        socket.create_connection((host, int(match["port"])), timeout=SCHEDULER_TIMEOUT).close()
    except OSError as exc:
        raise CavexInputError(f"parameter 'scheduler' must be a reachable Dask scheduler (no "
                              f"connection to {address!r} within {SCHEDULER_TIMEOUT:g} s: "
                              f"{exc.strerror or exc})") from None


# --- execution ----------------------------------------------------------------------------------

def chunks(todo, parallelism, chunk_size=None):
    """``todo`` split into work units: ``chunk_size`` consecutive cases, or (default) one
    chunk per worker, at most :data:`MAX_CHUNK` cases each, the cases dealt out in turn so that
    every chunk gets its share of cheap and expensive ones (a grid is ordered by velocity)."""
    if chunk_size is not None:
        require(isinstance(chunk_size, int) and not isinstance(chunk_size, bool)
                and chunk_size >= 1, "chunk_size", "an integer >= 1", chunk_size)
        return [todo[i:i + chunk_size] for i in range(0, len(todo), chunk_size)]
    n = min(len(todo), max(parallelism, math.ceil(len(todo) / MAX_CHUNK)))
    return [todo[i::n] for i in range(n)]


def _execute(function, todo, scheduler, workers, finished, chunk_size, while_running=None):
    if scheduler is not None:
        _run_dask(function, todo, scheduler, finished, chunk_size, while_running)
    elif workers == 1:
        for chunk in chunks(todo, 1, chunk_size):
            finished(chunk, run_chunk(function, chunk))
    else:
        units = chunks(todo, workers, chunk_size)
        _run_pool(function, units, min(workers, len(units)), finished, while_running)


def _pool_context():
    """``fork`` from a single-threaded process (fast, no ``__main__`` guard needed), else
    ``forkserver`` (forking a threaded process, e.g. one holding a Dask client, can deadlock)."""
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def process_pool(workers):
    """A local pool of ``workers`` processes (:func:`_pool_context`), each ending with its
    parent (:func:`_die_with_parent`)."""
    return ProcessPoolExecutor(max_workers=workers, mp_context=_pool_context(),
                               initializer=_die_with_parent)


def _run_pool(function, todo, workers, finished, while_running=None):
    """Local processes; at most ``2 * workers`` chunks in flight; ``while_running`` once they
    are (the workers are forked by then)."""
    pending = iter(todo)
    with process_pool(workers) as pool:
        try:
            running = {}
            _top_up(running, pending, 2 * workers,
                    lambda chunk: pool.submit(run_chunk, function, chunk))
            if while_running is not None:
                while_running()
            while running:
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in done:
                    finished(running.pop(future), future.result())
                _top_up(running, pending, 2 * workers,
                        lambda chunk: pool.submit(run_chunk, function, chunk))
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise


def _die_with_parent():
    """Worker initialiser: end this process when its parent ends, even by ``kill -9`` (Linux's
    parent-death signal where available, and a watchdog thread)."""
    parent = os.getppid()
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass

    def watch():
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def _top_up(running, pending, limit, submit):
    while len(running) < limit:
        case = next(pending, None)
        if case is None:
            return
        running[submit(case)] = case


def _run_dask(function, todo, scheduler, finished, chunk_size, while_running=None):
    """A Dask cluster: an address (a client is opened and closed here) or a ``Client``."""
    from dask.distributed import Client, as_completed

    own = isinstance(scheduler, str)
    client = _connect(Client, scheduler) if own else scheduler
    try:
        with client.as_current():
            threads = max(1, sum(client.nthreads().values()))
            _stream_dask(client, as_completed, function, chunks(todo, threads, chunk_size),
                         finished, while_running)
    finally:
        if own:
            client.close()


def _stream_dask(client, as_completed, function, todo, finished, while_running=None):
    """Keep at most twice the cluster's threads of chunks in flight; hand results back as they
    finish; ``while_running`` once the first are in flight."""
    limit = 2 * max(1, sum(client.nthreads().values()))
    pending = iter(todo)
    running = {}

    def submit(chunk):  # tasks named by what they compute, e.g. "fe_cases-v0500.000_L0.30000+41"
        name = getattr(function, "__name__", "cases")
        return client.submit(run_chunk, function, chunk, pure=False,
                             key=f"{name}-{chunk[0]['id']}+{len(chunk) - 1}-{uuid.uuid4().hex[:8]}")

    _top_up(running, pending, limit, submit)
    if while_running is not None:
        while_running()
    stream = as_completed(list(running))
    for future in stream:
        case = running.pop(future)
        result = future.result()
        future.release()
        finished(case, result)
        before = set(running)
        _top_up(running, pending, limit, submit)
        for new in running.keys() - before:
            stream.add(new)


def _connect(client_class, address):
    """A client for ``address``; an unreachable or malformed address is an input error."""
    try:  # not the default client: a failed connection must not leave dask (and xarray) using it
        security = address.security() if isinstance(address, SchedulerAddress) else None
        return client_class(str(address), set_as_default=False, timeout=SCHEDULER_TIMEOUT,
                            security=security)
    except (OSError, ValueError, TypeError) as exc:
        raise CavexInputError(f"parameter 'scheduler' must be a reachable Dask scheduler "
                              f"address (got {address!r}: {one_line_reason(exc)})") from None


# --- progress -----------------------------------------------------------------------------------

def show_progress(progress):
    if progress is None:
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return bool(progress)


class Progress:
    """Progress bar with ETA on stderr through tqdm (works in terminals, notebooks and logs);
    nothing when disabled."""

    def __init__(self, total, done, enabled, unit="case"):
        if enabled:
            from tqdm.auto import tqdm
        else:  # draws nothing: the plain class (tqdm.auto warns in a notebook without widgets)
            from tqdm import tqdm

        tqdm.monitor_interval = 0  # no monitor thread: a pool forked later stays a plain fork
        self.bar = tqdm(total=total, initial=done, disable=not enabled, file=sys.stderr,
                        unit=unit, dynamic_ncols=True, leave=True)

    def update(self, n=1):
        self.bar.update(n)

    def close(self):
        self.bar.close()
