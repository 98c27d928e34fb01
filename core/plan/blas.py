"""One BLAS thread while the plan runs.

The plan's matrix products are small (8 x 8 DCTs, 3-channel colour weights, least squares
of a few columns): OpenBLAS splits them over its threads, which then spin between calls,
taking a core from anything else on the machine for no gain in time. With one BLAS thread
the products give the same figures (tests/test_exact_speedups.py) and the plan's CPU
seconds equal its wall seconds (measured: docs/performance.md).
"""

import threading
from contextlib import contextmanager
from functools import lru_cache

__all__ = ["one_blas_thread"]


@lru_cache(maxsize=1)
def _controller():
    # Finding the loaded BLAS libraries takes about 1 ms: once per process.
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        # A dependency of the package, but not of the GIMP and Krita plug-ins' bundles
        # (NumPy and moderngl only): there BLAS keeps its threads, with the same results.
        return None
    return ThreadpoolController()


# BLAS's thread count is the process's: plans made in several threads at once (an engine
# per thread) share one limit, set by the first to enter and lifted by the last to leave, so
# that crossed exits cannot leave the caller's BLAS at one thread.
_lock = threading.Lock()
_inside = 0
_limit = None


@contextmanager
def one_blas_thread():
    """Limit the BLAS libraries NumPy loaded to one thread inside the block."""
    global _inside, _limit
    controller = _controller()
    if controller is None:
        yield
        return
    with _lock:
        if _inside == 0:
            _limit = controller.limit(limits=1, user_api="blas")
        _inside += 1
    try:
        yield
    finally:
        with _lock:
            _inside -= 1
            if _inside == 0:
                _limit.restore_original_limits()
                _limit = None
