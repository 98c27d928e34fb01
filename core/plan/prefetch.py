"""Parts of the analysis that need only the pair, computed in a second thread.

The analysis is a chain of decisions in NumPy on one core (one BLAS thread, ``blas.py``), and
it runs before any tile: while it runs, the machine's other cores wait. A few of its
measures depend on nothing the chain decides (the low-pass fit, the JPEG block grid): they
run beside it, in the order the chain asks for them, and the chain takes each result when it
reaches it. NumPy releases the GIL in its array operations, so the two threads run at once.
The figures are the same as computed in line (the same calls on the same arrays); only the
time moves.
"""

import threading

__all__ = ["Prefetch"]


class Prefetch:
    """Run named calls one after another in a second thread; hand each result over on request.

    Parameters
    ----------
    calls : sequence of (str, callable)
        Names and calls without arguments, in the order the caller will need them.

    Use as a context manager: leaving it skips the calls not yet started (the chain returned
    early) and waits for the one running, so that no thread outlives the analysis.
    """

    def __init__(self, calls):
        self._calls = list(calls)
        self._results = {}
        self._done = {name: threading.Event() for name, _ in self._calls}
        self._stopped = False
        self._thread = threading.Thread(target=self._run, name="aarecovery-analysis", daemon=True)
        self._thread.start()

    def _run(self):
        for name, call in self._calls:
            if self._stopped:
                break
            try:
                self._results[name] = (True, call())
            except BaseException as error:  # handed to the caller, raised there
                self._results[name] = (False, error)
            self._done[name].set()

    def result(self, name):
        """The named call's result, once it has run; its exception is raised here."""
        self._done[name].wait()
        ok, value = self._results[name]
        if not ok:
            raise value
        return value

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self._stopped = True
        self._thread.join()
        return False
