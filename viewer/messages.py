"""The lines shown over the image: errors, which stay until dismissed, and notes, which fade."""

import time
from dataclasses import dataclass

__all__ = ["Message", "MessageLog", "INFO_SECONDS"]

#: Information messages disappear after this many seconds; errors stay until dismissed.
INFO_SECONDS = 5.0


@dataclass(frozen=True)
class Message:
    """A line shown over the image: an error (red, stays) or information (fades)."""

    text: str
    error: bool
    shown_at: float


class MessageLog:
    """The messages shown now, oldest first; indexable like a list.

    Attributes
    ----------
    serial : int
        Counts messages ever shown; the frame loop stays awake for a few frames after it changes.
    """

    def __init__(self):
        self._shown = []
        self.serial = 0

    def _add(self, text, error):
        self._shown.append(Message(text, error, time.perf_counter()))
        self.serial += 1

    def error(self, text):
        """Show an error over the image (it stays until dismissed or a pair opens)."""
        self._add(text, True)

    def info(self, text):
        """Show a passing note over the image."""
        self._add(text, False)

    def dismiss(self, message):
        """Remove one message."""
        if message in self._shown:
            self._shown.remove(message)

    def clear_errors(self):
        """Remove every error (a pair opened: what went wrong before no longer applies)."""
        self._shown = [m for m in self._shown if not m.error]

    def expire(self, now):
        """Remove the notes older than :data:`INFO_SECONDS`."""
        self._shown = [m for m in self._shown if m.error or now - m.shown_at < INFO_SECONDS]

    def __len__(self):
        return len(self._shown)

    def __getitem__(self, index):
        return self._shown[index]

    def __iter__(self):
        return iter(list(self._shown))
