"""What aarecovery's GIMP and Krita plug-ins share, and neither host's API.

The plug-in installers copy this package beside each plug-in (``aarecovery gimp install``,
``aarecovery krita install``), so a host's Python imports it as ``aarecovery_bridge`` without
aarecovery, NumPy or anything else outside the standard library:

* :mod:`.worker`: running the core, in the host's Python or in a worker process with a
  configured Python, and the bundle of the core for the host's Python;
* :mod:`.npy`: the ``.npy`` files the pixels travel in to the worker, written without NumPy;
* :mod:`.parameters`: the recovery parameters as the plug-ins' dialogs offer them;
* :mod:`.filters`: the host filters each plug-in offers and their ``name=value`` properties.

A plug-in script carries the aarecovery version it was shipped with and checks it against
:data:`__version__` (:func:`check_version`): a script and helpers from two releases would
disagree about the worker protocol.
"""

__version__ = "0.1.0"

__all__ = ["__version__", "PluginError", "check_version", "module_files"]


class PluginError(Exception):
    """A failure with a message for the user; the plug-in shows it and changes nothing."""


def module_files():
    """The package's own files, ``(name, path)``: what an installer copies beside a plug-in."""
    import os
    folder = __path__[0]
    return [(name, os.path.join(folder, name)) for name in sorted(os.listdir(folder)) if name.endswith(".py")]


def check_version(expected, script, reinstall):
    """Raise PluginError unless this package is aarecovery `expected`'s.

    Parameters
    ----------
    expected : str
        The version the plug-in script was shipped with.
    script : str
        The script's path, for the message.
    reinstall : str
        The command that installs a matching pair, e.g. "aarecovery gimp install".
    """
    if expected != __version__:
        raise PluginError(
            f"the plug-in {script} is aarecovery {expected} but its helper modules in "
            f"{__path__[0]} are aarecovery {__version__}; install both again with: {reinstall}")
