"""A batch on this machine: one engine for every image, workers around it.

The engine (one GL context, its programs compiled once) lives in the calling thread and
only recovers; worker threads decode, run the filter and encode, so that the next images
are read and the last ones written while the engine works, and the safe plan's analysis
runs in worker processes (:mod:`.planner`). At most ``workers + 1`` images wait on either
side of the engine, which bounds the memory to a few images, not the batch.
"""

import contextlib
import os
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor

from ..plan import make_plan
from .planner import PlannerProcesses
from .work import compute, prepare, store

__all__ = ["run_local", "default_workers"]


def default_workers(cores=None):
    """Worker threads for a batch on a machine with `cores` cores (default: this one's).

    Measured with ``aarecovery bench --batch`` (docs/performance.md) on 2 shared cores, 24
    pairs of 1920 x 1080 PNGs, GL on llvmpipe, safe mode: see the table there. Threads beyond
    the cores only add contention.
    """
    cores = cores or os.cpu_count() or 1
    return max(1, cores)


def run_local(jobs, settings, engine, *, workers=None, progress=None, started=None):
    """Run every job; return their :class:`ImageResult`, in the jobs' order.

    Parameters
    ----------
    jobs : list of Job
    settings : Settings
    engine : Engine
        Used in this thread only.
    workers : int, optional
        Worker threads (default :func:`default_workers`).
    progress : callable, optional
        ``progress(result)`` after each image, in the order they finish.
    started : float, optional
        The batch's start (``time.time()``); temporary files older than it are stale.
    """
    workers = workers or default_workers()
    started = time.time() if started is None else started
    capabilities = engine.capabilities
    results = [None] * len(jobs)
    waiting = deque(enumerate(jobs))
    processes = PlannerProcesses(workers) if settings.mode == "safe" and len(jobs) > 1 else None
    planner = processes or make_plan
    threads = ThreadPoolExecutor(workers, thread_name_prefix="aarecovery-batch")
    with processes or contextlib.nullcontext(), threads as pool:
        prepared, storing = deque(), deque()

        def finish(index, future, _work):
            results[index] = future.result()
            if progress is not None:
                progress(results[index])

        try:
            while waiting or prepared:
                while waiting and len(prepared) <= workers:
                    index, job = waiting.popleft()
                    prepared.append((index, pool.submit(prepare, job, settings, capabilities, started, planner)))
                index, future = prepared.popleft()
                work = compute(future.result(), engine, settings)
                storing.append((index, pool.submit(store, work, settings), work))
                while storing and (storing[0][1].done() or len(storing) > workers + 1):
                    finish(*storing.popleft())
            while storing:
                finish(*storing.popleft())
        except BaseException:
            # Ctrl+C or a failing callback: nothing new starts; images being written finish
            # (every write is atomic either way) and their scratch folders are removed.
            for _, future in prepared:
                if not future.cancel():
                    _discard(future)
            for _, future, work in storing:
                if future.cancel():
                    work.finished()
            pool.shutdown(wait=True, cancel_futures=True)
            raise
    return results


def _discard(future):
    try:
        work = future.result()
    except BaseException:
        return
    work.finished()

