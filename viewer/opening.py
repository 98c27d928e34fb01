"""Opening a pair: from a source, from the panel's fields, from files dropped on the window.

A pair that cannot be opened shows a message and leaves the shown pair as it was.
"""

import os

import aarecovery

from .sources import PairSource, load_pair

__all__ = ["PairOpener"]


class PairOpener:
    """Loads pairs into the live recovery and the view.

    Parameters
    ----------
    panel : PanelState
    recovery : LiveRecovery
    view : ViewState
    messages : MessageLog
    view_size : callable
        Returns the image area's ``(width, height)`` in framebuffer pixels now, so that a new
        pair is fitted to the window before its first frame.
    """

    def __init__(self, panel, recovery, view, messages, view_size):
        self.panel = panel
        self.recovery = recovery
        self.view = view
        self.messages = messages
        self.view_size = view_size

    def open(self, source):
        """Load a pair; on bad input show the message and keep what was shown.

        Returns
        -------
        bool
            True when the pair was loaded.
        """
        try:
            pair = load_pair(source)
            self.recovery.load(pair)
        except (aarecovery.InputError, OSError) as error:
            self.messages.error(str(error))
            # The engine may have dropped its images on the way; put the shown pair back.
            self.recovery.restore_shown_pair()
            return False
        self.view.set_view_size(*self.view_size())
        self.view.set_image_size(*pair.size)
        self.panel.show_source(source)
        self.messages.clear_errors()
        self.messages.info(f"opened {os.path.basename(source.original)} and {source.describe_filtered()} "
                           f"({pair.size[0]}x{pair.size[1]})")
        if self.recovery.order.looks_reversed:
            self.messages.error(self.recovery.order.reason)
        return True

    def open_fields(self):
        """Open what the panel's fields name (the Open button, Ctrl+O)."""
        source, problem = self.panel.source()
        if source is None:
            self.messages.error(problem)
            return False
        return self.open(source)

    def choose_filter(self, name):
        """Pick a built-in filter for F and open the pair it makes, if ORIGINAL is named."""
        self.panel.choose_filter(name)
        if self.panel.original_path.strip():
            self.open_fields()

    def handle_drop(self, paths):
        """Files dropped on the window: two are ORIGINAL and FILTERED, one asks which it is."""
        if len(paths) >= 2:
            if len(paths) > 2:
                self.messages.info(f"{len(paths)} files dropped; using the first two as ORIGINAL and FILTERED")
            self.open(PairSource(paths[0], paths[1]))
        elif paths:
            self.panel.pending_drop = paths[0]

    def use_dropped_as(self, role):
        """Use the single dropped file as the ``"original"`` or the ``"filtered"`` image."""
        if self.panel.take_dropped_as(role):
            return self.open_fields()
        return False
