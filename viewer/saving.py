"""Saving R and sharing how it was made.

Where R goes by default, when to ask before replacing a file, and the equivalent command
line on the clipboard.
"""

import os

import aarecovery

from .settings import command_line

__all__ = ["default_output_path", "overwrite_question", "save_result", "SaveActions"]


def default_output_path(source):
    """``<filtered>-recovered.png`` next to F (or next to O when F came from a filter)."""
    if source.filtered:
        stem = os.path.splitext(source.filtered)[0]
    else:
        stem = f"{os.path.splitext(source.original)[0]}-{source.filter_name}"
    return f"{stem}-recovered.png"


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def overwrite_question(path, source):
    """The question to ask before writing `path`, or None when nothing would be replaced.

    Parameters
    ----------
    path : str
        Where R would be written.
    source : PairSource or None
        The shown pair; replacing one of its inputs gets a sterner question.
    """
    if not os.path.lexists(path):
        return None
    inputs = source.input_paths if source is not None else []
    for role, input_path in zip(("ORIGINAL", "FILTERED"), inputs):
        if _same_file(path, input_path):
            return (f"{path} is the {role} input image. Replace it with the result? "
                    "The input is lost.")
    return f"{path} exists. Replace it?"


def save_result(engine, path, overwrite=False):
    """Write the engine's R to `path` atomically, in F's layout and bit depth.

    Raises
    ------
    aarecovery.InputError
        Where `path` exists and `overwrite` is False, or the format cannot hold R.
    OSError
        When the disk refuses the write.
    """
    aarecovery.write_image(path, engine.result(), overwrite=overwrite)


class SaveActions:
    """Save R (asking before replacing a file) and copy the command line that makes it.

    Parameters
    ----------
    panel : PanelState
        Holds the save path and the pending questions.
    recovery : LiveRecovery
        The shown pair and the engine holding R.
    messages : MessageLog
    set_clipboard : callable
        ``set_clipboard(text)``; the app passes ImGui's.
    """

    def __init__(self, panel, recovery, messages, set_clipboard):
        self.panel = panel
        self.recovery = recovery
        self.messages = messages
        self.set_clipboard = set_clipboard

    def start(self):
        """Open the save dialog (Ctrl+S)."""
        if self.recovery.pair is None:
            self.messages.error("nothing to save: open an image pair first")
            return
        self.panel.save_dialog_requested = True

    def request(self, path):
        """Save R to `path`, first asking if that replaces a file (an input most of all)."""
        path = os.path.expanduser(path.strip())
        if not path:
            self.messages.error("give a file name to save R to")
            return False
        pair = self.recovery.pair
        question = overwrite_question(path, pair.source if pair else None)
        if question is not None:
            self.panel.pending_overwrite = (path, question)
            return False
        return self._save(path, overwrite=False)

    def confirm_overwrite(self):
        """The user confirmed replacing the file of the pending save."""
        if self.panel.pending_overwrite is None:
            return False
        path, self.panel.pending_overwrite = self.panel.pending_overwrite[0], None
        return self._save(path, overwrite=True)

    def _save(self, path, overwrite):
        try:
            self.recovery.update()
            save_result(self.recovery.engine, path, overwrite=overwrite)
        except (aarecovery.InputError, OSError) as error:
            self.messages.error(f"not saved: {error}")
            return False
        self.messages.info(f"saved R to {path}")
        return True

    def command_line(self):
        """The shell command that reproduces the shown R, or None without a pair."""
        pair = self.recovery.pair
        if pair is None:
            return None
        output = self.panel.save_path.strip() or default_output_path(pair.source)
        return command_line(pair.source, self.recovery.settings, output)

    def copy_command_line(self):
        """Put :meth:`command_line` on the clipboard."""
        text = self.command_line()
        if text is None:
            self.messages.error("open an image pair first")
            return
        self.set_clipboard(text)
        self.messages.info("command line copied to the clipboard")
