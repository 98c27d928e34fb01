"""What the side panel holds between frames: typed paths, the chosen filter, pending questions.

ImGui keeps no state for the viewer; every value a widget edits lives here, so that keys,
widgets and tests reach the same values.
"""

from .saving import default_output_path
from .sources import SAMPLE_FILTER, PairSource, filter_names, filter_parameters

__all__ = ["PanelState"]


class PanelState:
    """The panel's fields and the questions waiting for an answer.

    Attributes
    ----------
    original_path, filtered_path : str
        Paths typed (or dropped, or chosen in a dialog) for ORIGINAL and FILTERED.
    use_builtin_filter : bool
        Make F from ORIGINAL with :attr:`filter_name` instead of reading FILTERED.
    filter_name : str or None
    filter_params : dict
        Values typed for the filter's parameters (its defaults for the others).
    save_path : str
        Where Save R writes.
    visible, help_visible : bool
        The panel and the key help overlay.
    save_dialog_requested : bool
        Open the save dialog on the next frame.
    pending_overwrite : tuple or None
        ``(path, question)`` of a save awaiting confirmation.
    pending_drop : str or None
        A single dropped path awaiting "use as ORIGINAL / FILTERED".
    """

    def __init__(self):
        self.original_path = ""
        self.filtered_path = ""
        self.use_builtin_filter = False
        self.filter_name = SAMPLE_FILTER if SAMPLE_FILTER in filter_names() else (filter_names() or [None])[0]
        self.filter_params = {}
        self.save_path = ""
        self.visible = True
        self.help_visible = False
        self.save_dialog_requested = False
        self.pending_overwrite = None
        self.pending_drop = None

    def show_source(self, source):
        """Fill the fields from the pair that just opened."""
        self.original_path = source.original
        self.filtered_path = source.filtered or ""
        self.use_builtin_filter = not source.filtered
        if not source.filtered:
            self.filter_name = source.filter_name
            self.filter_params = dict(source.filter_params)
        self.save_path = default_output_path(source)

    def source(self):
        """The pair the fields name.

        Returns
        -------
        source : PairSource or None
        problem : str or None
            What to type first, when `source` is None.
        """
        original = self.original_path.strip()
        if not original:
            return None, "type the ORIGINAL image's path in the panel (or drop files on the window)"
        if self.use_builtin_filter:
            known = {name for name, *_ in filter_parameters(self.filter_name)}
            params = {key: value for key, value in self.filter_params.items() if key in known}
            return PairSource(original, None, self.filter_name, params), None
        filtered = self.filtered_path.strip()
        if not filtered:
            return None, "type the FILTERED image's path, or choose a built-in filter"
        return PairSource(original, filtered), None

    def choose_filter(self, name):
        """Pick a built-in filter for F (its parameters start at their defaults)."""
        self.filter_name = name
        self.filter_params = {}

    def take_dropped_as(self, role):
        """Put the single dropped file into the ``"original"`` or ``"filtered"`` field.

        Returns
        -------
        bool
            True when the fields now name a whole pair.
        """
        path, self.pending_drop = self.pending_drop, None
        if path is None:
            return False
        if role == "original":
            self.original_path = path
            if not self.use_builtin_filter and not self.filtered_path:
                self.use_builtin_filter = bool(filter_names())
        else:
            self.filtered_path = path
            self.use_builtin_filter = False
        return bool(self.original_path and (self.use_builtin_filter or self.filtered_path))

    def take_chosen_file(self, role, path):
        """A file chosen in a native dialog for ``"original"``, ``"filtered"`` or ``"save"``."""
        if role == "save":
            self.save_path = path
        elif role == "original":
            self.original_path = path
        else:
            self.filtered_path = path
            self.use_builtin_filter = False
