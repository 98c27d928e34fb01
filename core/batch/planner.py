"""The safe plan's analysis in processes of its own, beside the batch's engine.

The analysis is NumPy on small arrays: between its array operations Python holds the GIL,
so in threads it barely runs in parallel. Measured on 2 cores (loaded), 1920 x 1080
photo-like pairs: one analysis took 1.09 s in one thread, 0.84 s each with two threads,
0.50 s each with two processes. Each process here runs ``python -m
aarecovery.batch`` and answers requests on its standard input and output: only the
analysis window (two 512 x 512 crops) and the plan cross. Plain subprocesses, not
``multiprocessing``: that would import the caller's main script again in every process
(its "safe importing of the main module" rule), which a script calling
``aarecovery.recover_many`` at its top level does not expect.
"""

import os
import pickle
import queue
import signal
import struct
import subprocess
import sys
import threading

from ..errors import InputError

__all__ = ["PlannerProcesses", "serve"]

_LENGTH = struct.Struct("<Q")
# One BLAS thread per process: the processes are the parallelism, and OpenBLAS's threads
# wait by spinning. Measured (16 pairs of 1920 x 1080, 2 workers): 14.6 CPU seconds with
# OpenBLAS's default threads, 12.5 with one.
_ONE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def _send(stream, value):
    data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(_LENGTH.pack(len(data)))
    stream.write(data)
    stream.flush()


def _receive(stream):
    head = stream.read(_LENGTH.size)
    if len(head) < _LENGTH.size:
        return None
    return pickle.loads(stream.read(_LENGTH.unpack(head)[0]))


def serve(requests=None, replies=None):
    """Answer ``(original, filtered, parameters, options)`` requests with ``make_plan``'s plan until EOF."""
    from ..plan import make_plan
    from ..plan.ahead import plan_in_order

    # The processes are the parallelism: each plan in one thread (plan/ahead.py).
    plan_in_order()
    # Ctrl+C reaches every process of the terminal's group; the batch decides what stops.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    requests = requests or sys.stdin.buffer
    replies = replies or sys.stdout.buffer
    try:
        while (request := _receive(requests)) is not None:
            original, filtered, parameters, options = request
            try:
                reply = (True, make_plan(original, filtered, parameters, **options))
            except Exception as error:  # handed back to the batch, which fails that image
                reply = (False, error)
            _send(replies, reply)
    except (BrokenPipeError, EOFError, pickle.UnpicklingError):
        # The batch is gone (killed, even with SIGKILL, mid-request or mid-reply): nobody
        # reads the answer, so stop without a traceback on the terminal it shared.
        _stop_quietly(replies)


def _stop_quietly(replies):
    """Point `replies` at /dev/null, so that the flush at exit does not raise on the broken pipe."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), replies.fileno())
    except (OSError, ValueError):
        pass


class PlannerProcesses:
    """A callable like ``make_plan`` that runs it in one of `count` processes.

    Use it as a context manager; the processes end when it closes (or when this process
    dies: they stop at the end of their input).
    """

    def __init__(self, count):
        self._count = count
        self._processes = []
        self._idle = queue.Queue()
        self._lock = threading.Lock()

    def _process(self):
        """An idle process; a new one while fewer than `count` run (none start for a batch
        whose results are all up to date)."""
        try:
            return self._idle.get_nowait()
        except queue.Empty:
            pass
        with self._lock:
            if len(self._processes) < self._count:
                process = subprocess.Popen([sys.executable, "-m", "aarecovery.batch"], stdin=subprocess.PIPE,
                                           stdout=subprocess.PIPE, env={**os.environ, **_ONE_THREAD})
                self._processes.append(process)
                return process
        return self._idle.get()

    def __call__(self, original, filtered, parameters, **options):
        process = self._process()
        try:
            _send(process.stdin, (original, filtered, parameters, options))
            reply = _receive(process.stdout)
        except (BrokenPipeError, OSError):
            reply = None
        finally:
            self._idle.put(process)
        if reply is None:
            raise InputError(f"the analysis process stopped (exit status {process.poll()}); the image was not "
                             "planned")
        ok, value = reply
        if not ok:
            raise value
        return value

    def close(self):
        for process in self._processes:
            try:
                process.stdin.close()
            except OSError:
                pass
        for process in self._processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
            process.stdout.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

