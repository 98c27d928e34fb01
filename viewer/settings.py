"""The recovery parameters the sliders edit, and the same run as a shell command line.

Defaults, ranges and help come from ``aarecovery.PARAMETERS`` and the modes from
``aarecovery.MODES``; nothing here repeats them.
"""

import os
import shlex
from dataclasses import dataclass, replace

import numpy as np

import aarecovery

__all__ = ["RecoverySettings", "command_line", "DEFAULT_MODE", "MODE_OPTIONS"]

#: The core lists its default mode first.
DEFAULT_MODE = aarecovery.MODES[0]
#: The ``aarecovery recover`` options that select each mode.
MODE_OPTIONS = {DEFAULT_MODE: (), "paper": ("--paper",)}


@dataclass(frozen=True)
class RecoverySettings:
    """One set of recovery parameters; equal settings mean the shown R is current.

    Attributes
    ----------
    sigma_d, sigma_e : float
    iterations : int
    strength : float or None
        As in ``aarecovery.PARAMETERS``, whose defaults they start at (strength None: the
        mode's own).
    mode : str
        One of ``aarecovery.MODES``.
    """

    sigma_d: float = aarecovery.PARAMETERS["sigma_d"].default
    sigma_e: float = aarecovery.PARAMETERS["sigma_e"].default
    iterations: int = aarecovery.PARAMETERS["iterations"].default
    strength: object = aarecovery.PARAMETERS["strength"].default
    mode: str = DEFAULT_MODE

    @classmethod
    def defaults(cls):
        """The paper's parameters and the engine's default mode."""
        return cls()

    def with_values(self, **changes):
        """A copy with some values changed."""
        return replace(self, **changes)

    def compute_arguments(self):
        """Keyword arguments for ``Engine.compute``."""
        arguments = {name: getattr(self, name) for name in aarecovery.PARAMETERS}
        arguments["mode"] = self.mode
        return arguments


def _number(value):
    """A number as the shortest text that reads back as the same float32.

    The viewer's widgets hold float32 values, and the passes take the sigmas as float32 (GL
    uniforms, and the specification's casts): this text reproduces the viewer's R exactly,
    where ``%g``'s six digits may not.
    """
    return str(np.float32(value)) if isinstance(value, float) else str(value)


def _quote(path):
    return shlex.quote(os.fspath(path))


def _command(argv):
    return "aarecovery " + " ".join(_quote(part) for part in argv)


def _filter_step(source, filtered):
    """The command that writes F with the library's own filter."""
    argv = ["filter", source.filter_name, os.fspath(source.original), "-o", filtered]
    for key, value in source.filter_params.items():
        argv += ["--param", f"{key}={_number(value)}"]
    return _command(argv)


def command_line(source, settings, output):
    """The shell command that computes the shown result and writes it to `output`.

    Parameters
    ----------
    source : PairSource
        The pair shown; when F comes from a built-in filter, the command first writes F
        next to `output` with the library's own filter.
    settings : RecoverySettings
    output : str
        Where the command writes R.

    Returns
    -------
    str
        A POSIX shell command line (one line).
    """
    filtered = source.filtered
    steps = []
    if not filtered:
        filtered = f"{os.path.splitext(output)[0]}-filtered.png"
        steps.append(_filter_step(source, filtered))
    argv = ["recover", os.fspath(source.original), os.fspath(filtered), "-o", os.fspath(output)]
    for name, spec in aarecovery.PARAMETERS.items():
        if getattr(settings, name) is not None:
            argv += [spec.option, _number(getattr(settings, name))]
    argv += MODE_OPTIONS[settings.mode]
    steps.append(_command(argv))
    return " && ".join(steps)
