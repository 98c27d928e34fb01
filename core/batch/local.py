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
from .filtering import stop_filter_commands
from .planner import PlannerProcesses
from .work import compute, prepare, store

__all__ = ["run_local", "default_workers"]


def default_workers(cores=None):
    """Workers for a batch on a machine with `cores` cores (default: this one's): one per
    core. A worker is an analysis process; one more thread than workers reads, filters and
    writes, so that a thread waiting for a plan blocks no write.

    Measured with ``aarecovery bench --batch 100`` (1920 x 1080 PNG pairs, thresholded, safe
    mode, GL on llvmpipe) on 2 cores, images per second for 1 / 2 / 3 / 4 workers, against
    separate ``aarecovery recover`` calls in the same run of the command:

    * machine nearly idle at the start (load 0 rising to 5 as other jobs began):
      1.73 / 2.01 / 2.14 / 2.33, separate calls 0.99;
    * machine shared with other jobs (load 4 to 7): 1.38 / 1.18 / 1.00 / 1.08, separate
      0.63; and 1.15 / 0.91 / 0.96 / 1.01, separate 0.57.

    The analysis processes are the bottleneck when the cores are ours: one per core. More
    only won a larger share of cores that other jobs were taking (their load rose during
    those runs), and when other jobs hold the cores, fewer workers leave the engine (which
    renders on the CPU with llvmpipe) more of them; ``--workers`` overrides the rule.
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
        Analysis processes, and one thread more for reading, filtering and writing (default
        :func:`default_workers`).
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
    threads = ThreadPoolExecutor(workers + 1, thread_name_prefix="aarecovery-batch")
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
            # Filter commands run in process groups of their own, out of the terminal's reach.
            stop_filter_commands()
            for _, future in prepared:
                if not future.cancel():
                    _discard(future)
            writing = []
            for index, future, work in storing:
                if future.cancel():
                    work.finished()
                else:
                    writing.append((index, future, work))
            pool.shutdown(wait=True, cancel_futures=True)
            # The images whose writing had begun are on disk now: count and report them.
            for item in writing:
                with contextlib.suppress(Exception):
                    finish(*item)
            raise
    return results


def _discard(future):
    try:
        work = future.result()
    except BaseException:
        return
    work.finished()

