"""Making F inside the batch: a built-in filter, or any command-line tool the user already has.

A command is a template such as ``convert {in} -threshold 50% {out}`` (ImageMagick 6),
``magick {in} -threshold 50% {out}`` (ImageMagick 7), ``gmic {in} -quantize 4 -o {out}``
or ``gegl {in} -o {out} -- gegl:levels in-high=0.6``. It is split into words first (POSIX
shell quoting rules, no shell runs it), then ``{in}`` and ``{out}`` are replaced inside
each word, so paths with spaces need no quoting. The command reads a temporary copy of
the original, so a tool that writes into its input cannot touch it, and writes a file in
the same temporary folder, in the original's format when it is lossless, else PNG, unless
``{out}`` is given an extension (``{out}.jpg``); a non-zero exit status, or no output file, fails that image with
the tool's own message.
"""

import os
import re
import shlex
import shutil
import signal
import subprocess
import threading
from dataclasses import dataclass, field

from ..errors import InputError
from ..io.formats import lossless_extension

__all__ = ["BuiltinFilter", "FilterCommand", "FilterFailed"]

# The last lines of a failing tool's stderr that are reported (a tool may print pages).
_STDERR_LINES = 3
# ... and of each line, so that a tool printing one 10 MB line gives a readable error.
_STDERR_LINE_CHARACTERS = 200


class FilterFailed(InputError):
    """The filter command of a batch failed on one image (its exit status and message)."""


@dataclass(frozen=True)
class BuiltinFilter:
    """One of ``aarecovery.filters``, with its parameters.

    Attributes
    ----------
    name : str
    params : dict
    """

    name: str
    params: dict = field(default_factory=dict)

    def __post_init__(self):
        from ..filters import get_filter
        get_filter(self.name)

    def describe(self):
        """str: the filter as a user would write it."""
        return " ".join([self.name] + [f"{key}={value!r}" for key, value in self.params.items()])

    def apply(self, original):
        """F for the array `original`, in its layout and dtype."""
        from ..filters import apply
        return apply(self.name, original, **self.params)


@dataclass(frozen=True)
class FilterCommand:
    """A command-line tool run on each original, as a template with ``{in}`` and ``{out}``.

    Attributes
    ----------
    template : str
    timeout : float or None
        Seconds after which the command is stopped and the image failed.
    """

    template: str
    timeout: float = None

    def __post_init__(self):
        words = self.words()
        if not words:
            raise InputError("--filter-cmd is empty; give a command such as 'convert {in} -threshold 50% {out}'")
        joined = " ".join(words)
        for placeholder in ("{in}", "{out}"):
            if placeholder not in joined:
                raise InputError(f"--filter-cmd {self.template!r} has no {placeholder}; the command must read "
                                 "{in} and write {out}, for example 'convert {in} -threshold 50% {out}'")
        if shutil.which(words[0]) is None:
            raise InputError(f"--filter-cmd: the program {words[0]!r} is not found on PATH; install it or give "
                             "its full path")

    def words(self):
        try:
            return shlex.split(self.template)
        except ValueError as error:
            raise InputError(f"--filter-cmd {self.template!r} cannot be split into words ({error}); check "
                             "its quotes") from None

    def describe(self):
        return self.template

    def _chosen_extension(self):
        """The extension the template gives ``{out}`` (``{out}.png``), or None."""
        chosen = re.search(r"\{out\}(\.\w+)", self.template)
        return chosen.group(1) if chosen else None

    def output_extension(self, original_path):
        """The extension of the file the command writes for `original_path`: the template's
        (``{out}.jpg``), else the original's when lossless, else ``.png``.

        A JPEG F would add its own artefacts to the filter's result (a threshold came back
        with 52 grey levels), and F's values are what the recovery fits."""
        return self._chosen_extension() or lossless_extension(os.path.splitext(original_path)[1])

    def run(self, original_path, folder):
        """Run the command on a copy of `original_path` inside `folder`; return the output's path.

        Raises
        ------
        FilterFailed
            On a non-zero exit status, a time-out, or no output file.
        """
        copy = os.path.join(folder, "original" + os.path.splitext(original_path)[1])
        shutil.copyfile(original_path, copy)
        output = os.path.join(folder, "filtered")
        produced = output + self.output_extension(original_path)
        target = output if self._chosen_extension() else produced
        words = [word.replace("{in}", copy).replace("{out}", target) for word in self.words()]
        returncode, stderr = _run_as_group(words, self.timeout, folder, self.template)
        message = _tool_message(stderr)
        if returncode != 0:
            raise FilterFailed(f"the filter command exited with status {returncode}"
                               + (f": {message}" if message else "") + f" ({self.template})")
        if not os.path.isfile(produced):
            raise FilterFailed(f"the filter command wrote no {os.path.basename(produced)} ({self.template})"
                               + (f": {message}" if message else ""))
        return produced


def _cut(line):
    if len(line) <= _STDERR_LINE_CHARACTERS:
        return line
    return f"{line[:_STDERR_LINE_CHARACTERS]}... ({len(line) - _STDERR_LINE_CHARACTERS} more characters)"


def _tool_message(stderr):
    """The last lines of a tool's stderr, each cut, as one line."""
    # Without terminal colour codes (G'MIC colours its messages).
    text = re.sub(r"\x1b\[[0-9;]*m", "", stderr.decode(errors="replace"))
    return " | ".join(_cut(line.strip()) for line in text.strip().splitlines()[-_STDERR_LINES:])


# The filter commands running now, each its own process group: a new session does not get
# the terminal's Ctrl+C, so an interrupted batch stops them itself (stop_filter_commands).
_RUNNING = set()
_RUNNING_LOCK = threading.Lock()


def stop_filter_commands():
    """Stop every filter command running now, with the processes it started."""
    with _RUNNING_LOCK:
        running = list(_RUNNING)
    for process in running:
        _signal_group(process)


def _run_as_group(words, timeout, folder, template):
    """Run a command in its own process group; past `timeout`, stop the whole group.

    A filter is often a wrapper (a shell script, ``sh -c``, a tool that forks workers):
    stopping only the process started would leave its children running, writing into the
    batch's folders after the image was reported, and holding its stderr open so that the
    batch waits for them. Returns the exit status and stderr.
    """
    try:
        process = subprocess.Popen(words, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.PIPE, cwd=folder, start_new_session=True)
    except OSError as error:
        raise FilterFailed(f"the filter command could not start: {error}") from None
    with _RUNNING_LOCK:
        _RUNNING.add(process)
    try:
        _, stderr = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill_group(process)
        raise FilterFailed(f"the filter command did not finish within {timeout:g} s ({template})") from None
    except BaseException:
        _kill_group(process)
        raise
    finally:
        with _RUNNING_LOCK:
            _RUNNING.discard(process)
    return process.returncode, stderr


def _signal_group(process):
    try:
        if hasattr(os, "killpg"):
            os.killpg(process.pid, signal.SIGKILL)
        else:  # Windows has no process groups to signal: the command alone
            process.kill()
    except (ProcessLookupError, PermissionError):
        pass


def _kill_group(process):
    _signal_group(process)
    process.stderr.close()
    process.wait()
