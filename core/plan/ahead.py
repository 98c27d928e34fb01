"""A second thread for the analyses that need nothing decided before them.

The plan's decisions are taken in order, each on what the ones before found; a few of its
analyses read only what is known when they start (the low-pass and point-wise fits of F,
the gated pure colours while the calibration runs) and run beside them in a second thread,
NumPy releasing the GIL in its array operations. The plans are the same (``tests/test_plan_ahead.py`` runs every decision both
ways). Measured on the bench's 4096 x 4096 pairs: docs/performance.md.

They run in order in the calling thread instead where the process's address space is
limited (``ulimit -v``, ``RLIMIT_AS``): a thread reserves its stack, and OpenBLAS a buffer for
each thread that calls it, which such a limit may not hold, and OpenBLAS reports that failure
on its own line, beside the command's (``tests/test_out_of_memory.py``); and in a process that
plans beside others on every core (a batch's analysis processes, :func:`plan_in_order`), where
the second thread finds no core free: 20 pairs of 1080p through ``aarecovery batch`` with its
default two processes, one run each, 2.04 images/s in order against 1.95 with the thread.
"""

import ctypes
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import contextmanager
from functools import lru_cache

__all__ = ["analyses_ahead", "plan_in_order", "InOrder"]


class InOrder:
    """An executor that runs each task when it is submitted, in the calling thread."""

    def submit(self, function, *args):
        """The task's Future, done: its result, or the exception it raised."""
        done = Future()
        try:
            done.set_result(function(*args))
        except BaseException as error:  # noqa: BLE001 - re-raised by done.result(), as from a thread
            done.set_exception(error)
        return done


_in_order = False


def plan_in_order():
    """Run this process's analyses in order from now on (one planner among several)."""
    global _in_order
    _in_order = True


def _address_space_limited():
    try:
        import resource
    except ImportError:  # not on POSIX
        return False
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    return soft != resource.RLIM_INFINITY


@lru_cache(maxsize=1)
def _malloc_trim():
    try:
        return ctypes.CDLL(None).malloc_trim  # glibc
    except (AttributeError, OSError):
        return None


@contextmanager
def analyses_ahead():
    """An executor for the analyses that run beside the plan's decisions.

    Yields
    ------
    concurrent.futures.Executor or InOrder
        One worker thread, joined when the block ends (a decision taken before a submitted
        analysis was read waits for it, so that nothing of the plan runs on beside the
        passes); :class:`InOrder` where the address space is limited or after
        :func:`plan_in_order`.
    """
    if _in_order or _address_space_limited():
        yield InOrder()
        return
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="aarecovery-plan") as executor:
        yield executor
    # The temporaries of two threads were held at once; glibc keeps what they freed at the
    # top of its heaps, which the tiles' buffers would be laid beside. Returned here: the
    # 4096 x 4096 photo pair's peak 395 -> 376-382 MiB (trimmed only the main heap's top; the
    # second thread's stays).
    trim = _malloc_trim()
    if trim is not None:
        trim(0)
