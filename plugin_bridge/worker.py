"""Running the core for a plug-in: in the host's Python, or in a worker process.

The core runs in the host's Python when ``import aarecovery`` works there: from the bundle that
``aarecovery HOST install --bundle`` puts into ``site-packages`` in the plug-in's folder (when
it was made for this Python; :func:`use_bundle`), or from the host's own paths (a Linux
distribution's package). Otherwise it runs under a configured Python that has aarecovery:
``python -c WORKER O.npy F.npy R.npy PARAMS.json``, the pixels travelling as ``.npy`` files
written without NumPy (:mod:`.npy`). The Python is, in order: the one the user typed into the
dialog, the environment variable ``AARECOVERY_PYTHON``, or the one the installer recorded in
``config.json`` in the plug-in's folder.
"""

import json
import os
import re
import subprocess
import sys
import sysconfig
import tempfile
import warnings
from dataclasses import dataclass, field

from . import PluginError
from .npy import read_npy, write_npy

__all__ = ["Host", "Outcome", "read_config", "python_platform", "use_bundle", "recover_arrays",
           "worker_main", "run_core", "ORDER_MARK", "SUMMARY_MARK", "KEPT_MARK"]

ORDER_MARK = "order: "
# The recovery's one-line summary travels among the messages too: SUMMARY_MARK when it
# repaired, KEPT_MARK when it returned F unchanged (which the user is told in a message).
SUMMARY_MARK = "summary: "
KEPT_MARK = "kept: "
BUNDLE_FOLDER = "site-packages"
CONFIG_FILE = "config.json"
# The worker process: this package's parent goes first on sys.path, so the worker runs the
# plug-in's own copy, whatever aarecovery_bridge the configured Python may have.
WORKER = ("import sys; sys.path.insert(0, sys.argv.pop(1)); "
          "from aarecovery_bridge.worker import worker_main; sys.exit(worker_main(sys.argv[1:]))")


@dataclass(frozen=True)
class Host:
    """The application a plug-in runs in, as the shared messages name it.

    Attributes
    ----------
    name : str
        "GIMP", "Krita".
    command : str
        The install command, e.g. "aarecovery gimp".
    folder : str
        The plug-in's folder: ``config.json`` and the bundle's ``site-packages``.
    python_field : str
        Where the dialog takes a Python with aarecovery, in the host's words.
    force_hint : str
        How the summary tells the user to force a repair.
    bundles : bool
        Whether ``install --bundle`` exists for this host.
    """

    name: str
    command: str
    folder: str
    python_field: str
    force_hint: str
    bundles: bool = True

    @property
    def bundle_dir(self):
        return os.path.join(self.folder, BUNDLE_FOLDER)


@dataclass
class Outcome:
    """A recovery as the plug-in reports it.

    Attributes
    ----------
    data : bytes
        The result, float32, in the layout of F.
    backend, runner : str
        "gl" or "numpy"; "in-process" or "subprocess".
    folders : dict
        Where aarecovery and NumPy were imported from.
    summary : str
        The one-line summary of what the recovery did.
    alerts : list of str
        Messages the user must see (a swapped pair, F kept unchanged).
    notes : list of str
        Status-bar notes (the GL fallback, a bundle skipped and why).
    """

    data: bytes
    backend: str
    runner: str
    folders: dict
    summary: str = ""
    alerts: list = field(default_factory=list)
    notes: list = field(default_factory=list)


def read_config(folder):
    """``config.json`` in `folder` as a dict; empty when it is missing or unreadable."""
    try:
        with open(os.path.join(folder, CONFIG_FILE), encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def python_platform():
    """This Python's platform in the form the bundle records: sysconfig's, less macOS's version.

    The version is the oldest macOS the Python was built for; wheels for an older one load too.
    """
    return re.sub(r"^macosx-[0-9.]+-", "macosx-", sysconfig.get_platform())


def use_bundle(host):
    """Put the bundled packages first on ``sys.path`` if they were made for this Python.

    First, so that they shadow a NumPy or moderngl that the host's Python has from the system
    (Debian's python3-numpy): the bundled core was installed with the bundled ones. Call it
    before anything imports NumPy. Returns a sentence saying why the bundle is not used, or
    None (it is used, or there is none).
    """
    bundle = read_config(host.folder).get("bundle")
    if not bundle:
        return None
    again = f"run '{host.command} install --bundle' again"
    if not os.path.isdir(host.bundle_dir):
        return f"the bundle folder {host.bundle_dir} is missing; {again}"
    mine = ("%d.%d" % sys.version_info[:2], python_platform())
    made_for = (bundle.get("python"), bundle.get("platform"))
    if sys.implementation.name != "cpython" or made_for != mine:
        return (f"the packages bundled in {host.bundle_dir} are for CPython {made_for[0]} on "
                f"{made_for[1]}, but {host.name} runs {sys.implementation.name} {mine[0]} on "
                f"{mine[1]}; {again}")
    sys.path.insert(0, host.bundle_dir)
    return None


# ---- the side that has NumPy and aarecovery ----------------------------------------------------

def recover_arrays(original, filtered, params):
    """Run ``aarecovery.recover`` on float32 arrays; return ``(result, backend, messages)``.

    ``params`` holds sigma_d, sigma_e, iterations, strength (None: the safe default's),
    backend, linear, clip_filtered (see :func:`.parameters.core_params`) and force_hint. The
    last message is the recovery's summary (SUMMARY_MARK or KEPT_MARK). Raises
    aarecovery.InputError on bad input.
    """
    import numpy as np
    import aarecovery

    params = dict(params)
    force_hint = params.pop("force_hint", None)
    if params.pop("clip_filtered", False):
        filtered = np.clip(filtered, 0.0, 1.0)
    with warnings.catch_warnings(record=True) as caught:
        # "auto" falls back to NumPy with a RuntimeWarning; keep it for the status bar.
        warnings.simplefilter("always")
        engine = aarecovery.Engine(backend=params.pop("backend"))
        result = aarecovery.recover(original, filtered, engine=engine, **params)
    # An order warning (the original layer looks like the filtered one) is marked for a message
    # of its own; the rest (the GL fallback) goes to the status bar.
    messages = [(ORDER_MARK if issubclass(w.category, aarecovery.OrderWarning) else "") + str(w.message)
                for w in caught]
    summary = aarecovery.summarize_recovery(engine.last_plan, original, filtered, result)
    messages.append((KEPT_MARK if summary.plan.keeps_filtered else SUMMARY_MARK) + summary.line(force=force_hint))
    return np.ascontiguousarray(result, dtype=np.float32), engine.backend, messages


def package_folders():
    """The folders aarecovery and NumPy were imported from; each run reports them back."""
    import numpy
    import aarecovery
    return {"aarecovery": os.path.dirname(os.path.abspath(aarecovery.__file__)),
            "numpy": os.path.dirname(os.path.abspath(numpy.__file__))}


def worker_main(argv):
    """``O.npy F.npy R.npy PARAMS.json``: the out-of-process side; prints one JSON line."""
    import numpy as np
    try:
        import aarecovery
    except ImportError as error:
        print(json.dumps({"error": f"{sys.executable} cannot import aarecovery ({error}); "
                                   "install it there with: pip install aarecovery"}))
        return 0
    o_path, f_path, r_path, p_path = argv
    with open(p_path, encoding="utf-8") as fh:
        params = json.load(fh)
    try:
        result, backend, messages = recover_arrays(np.load(o_path), np.load(f_path), params)
    except aarecovery.InputError as error:
        print(json.dumps({"error": str(error)}))
        return 0
    np.save(r_path, result)
    print(json.dumps({"backend": backend, "messages": messages, "folders": package_folders()}))
    return 0


# ---- the host's side ---------------------------------------------------------------------------

def configured_python(host, typed=""):
    """The Python for the worker (`typed` in the dialog first), or None when none is set."""
    typed = (typed or "").strip()
    return typed or os.environ.get("AARECOVERY_PYTHON") or read_config(host.folder).get("python") or None


def _sort_messages(outcome, messages):
    """File the core's messages into the outcome: summary, alerts and status-bar notes."""
    for message in messages:
        if message.startswith((ORDER_MARK, KEPT_MARK)):   # a swapped pair, F unchanged: a message each
            outcome.alerts.append(message.split(": ", 1)[1])
        if message.startswith((SUMMARY_MARK, KEPT_MARK)):
            outcome.summary = message.split(": ", 1)[1]
        if not message.startswith((ORDER_MARK, SUMMARY_MARK, KEPT_MARK)):
            outcome.notes.append(message)
    return outcome


def run_core(host, original, filtered, params, python="", bundle_note=None):
    """Recover; return an :class:`Outcome`.

    Parameters
    ----------
    host : Host
    original, filtered : (bytes, tuple)
        Float32 pixels and their shape (H, W, C).
    params : dict
        From :func:`.parameters.core_params`.
    python : str
        A Python with aarecovery typed in the dialog; empty: the configured one.
    bundle_note : str, optional
        What :func:`use_bundle` said, for the status bar and the error.
    """
    params = {**params, "force_hint": host.force_hint}
    notes = [bundle_note] if bundle_note else []
    try:
        import numpy as np
        import aarecovery
    except ImportError as error:
        import_error = error
    else:
        arrays = [np.frombuffer(data, dtype=np.float32).reshape(shape) for data, shape in (original, filtered)]
        try:
            result, backend, messages = recover_arrays(*arrays, params)
        except aarecovery.InputError as error:
            raise PluginError(str(error)) from None
        outcome = Outcome(result.tobytes(), backend, "in-process", package_folders(), notes=notes)
        return _sort_messages(outcome, messages)
    bundled = host.bundle_dir in sys.path          # made for this Python, and yet it does not import
    if bundled:
        notes.append(f"the packages bundled in {host.bundle_dir} do not import in {host.name}'s "
                     f"Python ({import_error}); run '{host.command} install --bundle' again")
    chosen = configured_python(host, python)
    if not chosen:
        if bundled:
            raise PluginError(notes[-1])
        bundle = f"run '{host.command} install --bundle', or " if host.bundles else ""
        raise PluginError(
            f"{host.name}'s Python ({sys.executable}, {sys.version.split()[0]}) cannot import "
            f"aarecovery ({import_error}) and no Python with aarecovery is configured"
            + (f" ({bundle_note})" if bundle_note else "") + f". Either {bundle}run '{host.command} "
            "install' from a Python that has aarecovery, set the environment variable AARECOVERY_PYTHON, "
            f"or enter that Python in {host.python_field}.")
    return _run_worker(host, chosen, original, filtered, params, notes)


def _run_worker(host, python, original, filtered, params, notes):
    """The recovery in the worker process under `python`."""
    with tempfile.TemporaryDirectory(prefix="aarecovery-plugin-") as tmp:
        paths = [os.path.join(tmp, n) for n in ("o.npy", "f.npy", "r.npy", "params.json")]
        write_npy(paths[0], *original)
        write_npy(paths[1], *filtered)
        with open(paths[3], "w", encoding="utf-8") as fh:
            json.dump(params, fh)
        here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        try:
            proc = subprocess.run(
                [python, "-c", WORKER, here, *paths], capture_output=True, text=True, timeout=3600,
                stdin=subprocess.DEVNULL,
                creationflags=getattr(subprocess, "CREATE_NO_WINDOW", 0))   # no console on Windows
        except OSError as error:
            raise PluginError(f"cannot run the configured Python '{python}': {error}; fix the "
                              f"path ('{host.command} status' shows it)") from None
        lines = proc.stdout.strip().splitlines()
        try:
            reply = json.loads(lines[-1])
        except (IndexError, ValueError):
            tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
            raise PluginError(f"the core under '{python}' failed (exit {proc.returncode}): "
                              f"{tail}") from None
        if "error" in reply:
            raise PluginError(reply["error"])
        shape = filtered[1]
        data = read_npy(paths[2], shape[0] * shape[1] * shape[2] * 4)
    outcome = Outcome(data, reply["backend"], "subprocess", reply["folders"], notes=notes)
    return _sort_messages(outcome, reply["messages"])
