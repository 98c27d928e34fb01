"""The recovery parameters the sliders edit, and the same run as a shell command line."""

import contextlib
import functools
import inspect
import io
import os
import shlex
from dataclasses import dataclass, replace

import aarecovery

__all__ = ["RecoverySettings", "supported_modes", "command_line", "mode_on_command_line", "SIGMA_D_RANGE", "SIGMA_E_RANGE",
           "ITERATIONS_RANGE"]

# Slider ranges (logarithmic for the sigmas); ctrl+click on a slider types any value the core accepts.
SIGMA_D_RANGE = (0.005, 1.0)
SIGMA_E_RANGE = (0.0005, 0.5)
ITERATIONS_RANGE = (0, 16)


def _compute_parameter(name):
    return inspect.signature(aarecovery.Engine.compute).parameters.get(name)


@functools.lru_cache(maxsize=None)
def supported_modes():
    """The ``mode`` values the engine's ``compute`` takes, default first; empty if it has none.

    The core names its modes in ``aarecovery.MODES`` where it exports them; an engine that
    takes ``mode`` without exporting the names gets the two the quality work defined.
    """
    parameter = _compute_parameter("mode")
    if parameter is None:
        return ()
    modes = tuple(getattr(aarecovery, "MODES", ("safe", "paper")))
    default = parameter.default
    return (default,) + tuple(m for m in modes if m != default) if default in modes else modes


@dataclass(frozen=True)
class RecoverySettings:
    """One set of recovery parameters; equal settings mean the shown R is current.

    Attributes
    ----------
    sigma_d, sigma_e : float
    iterations : int
    mode : str or None
        None where the engine has no mode switch.
    """

    sigma_d: float = 0.1
    sigma_e: float = 0.01
    iterations: int = 3
    mode: str = None

    @classmethod
    def defaults(cls):
        """The paper's parameters and the engine's default mode."""
        modes = supported_modes()
        return cls(mode=modes[0] if modes else None)

    def with_values(self, **changes):
        """A copy with some values changed."""
        return replace(self, **changes)

    def compute_arguments(self):
        """Keyword arguments for ``Engine.compute``."""
        arguments = {"sigma_d": self.sigma_d, "sigma_e": self.sigma_e, "iterations": self.iterations}
        if self.mode is not None:
            arguments["mode"] = self.mode
        return arguments


def _cli_accepts(argv):
    """True when ``aarecovery`` parses `argv` (checked, never run)."""
    from aarecovery.cli import build_parser
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        try:
            build_parser().parse_args(argv)
        except SystemExit:
            return False
    return True


def _number(value):
    return f"{value:g}"


def _quote(path):
    return shlex.quote(os.fspath(path))


def _filter_step(source, filtered):
    """The command that writes F with the library's own filter."""
    argv = ["filter", source.filter_name, os.fspath(source.original), "-o", filtered]
    for key, value in source.filter_params.items():
        argv += ["--param", f"{key}={_number(value) if isinstance(value, float) else value}"]
    if _cli_accepts(argv):
        return "aarecovery " + " ".join(_quote(part) for part in argv)
    # An install without the filter command: the same through the Python API.
    params = "".join(f", {key}={value!r}" for key, value in source.filter_params.items())
    script = ("import aarecovery, aarecovery.filters as f; "
              f"aarecovery.write_image({filtered!r}, f.apply({source.filter_name!r}, "
              f"aarecovery.read_image({os.fspath(source.original)!r}){params}))")
    return f"{'python' if os.name == 'nt' else 'python3'} -c {shlex.quote(script)}"


def _mode_arguments(argv, mode):
    """The options that select `mode` on the recover command line, or None if it has none."""
    for extra in (["--mode", mode], [f"--{mode}"]):
        if _cli_accepts(argv + extra):
            return extra
    return None


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
        A POSIX shell command line (one line). A mode the command line cannot select is
        left out; :func:`mode_on_command_line` tells whether that happened.
    """
    filtered = source.filtered
    steps = []
    if not filtered:
        filtered = f"{os.path.splitext(output)[0]}-filtered.png"
        steps.append(_filter_step(source, filtered))
    argv = ["recover", os.fspath(source.original), os.fspath(filtered), "-o", os.fspath(output),
            "--sigma-d", _number(settings.sigma_d), "--sigma-e", _number(settings.sigma_e),
            "--iterations", str(settings.iterations)]
    modes = supported_modes()
    if settings.mode is not None and modes and settings.mode != modes[0]:
        argv += _mode_arguments(argv, settings.mode) or []
    steps.append("aarecovery " + " ".join(_quote(part) for part in argv))
    return " && ".join(steps)


def mode_on_command_line(settings):
    """False when `settings` use a mode that the recover command cannot select."""
    modes = supported_modes()
    if settings.mode is None or not modes or settings.mode == modes[0]:
        return True
    return _mode_arguments(["recover", "o.png", "f.png", "-o", "r.png"], settings.mode) is not None
