"""What the image area compares: the view, the image R is compared with, flicker, and the layers.

The views are :data:`~aarecovery.viewer.keys.VIEW_MODES`: R, F, O, the split view, the
|R - F| heat-map and the four maps. :meth:`Comparison.layers` turns the choice into the
:class:`~aarecovery.viewer.image_view.Layer` pair that the image view draws.
"""

import time

from .image_view import Layer

__all__ = ["Comparison", "MAP_VIEWS"]

#: Views that show an intermediate map, which the recovery must keep.
MAP_VIEWS = ("alpha", "beta", "edge_strength", "residual", "strength")
_IMAGE_NAMES = {"filtered": "F", "original": "O"}


class Comparison:
    """The user's choice of what to show.

    Attributes
    ----------
    view_mode : str
        One of the names in ``VIEW_MODES``.
    compare_with : {"filtered", "original"}
        The image R is compared with in the split view and by flicker.
    swapped : bool
        Flicker state: the comparison image is shown where R would be.
    auto_flicker : bool
    flicker_period : float
        Seconds between automatic swaps.
    difference_gain : float
        Scale of the |R - F| heat-map.
    """

    def __init__(self):
        self.view_mode = "result"
        self.compare_with = "filtered"
        self.swapped = False
        self.auto_flicker = False
        self.flicker_period = 0.5
        self.difference_gain = 4.0
        self._flicker_time = time.perf_counter()

    @property
    def needs_maps(self):
        """bool: the view shows a map, which the recovery must keep."""
        return self.view_mode in MAP_VIEWS

    def set_view_mode(self, mode):
        """Show one of :data:`~aarecovery.viewer.keys.VIEW_MODES` (by name)."""
        self.view_mode = mode
        self.swapped = False

    def toggle_split(self):
        """The split view on, or back to R."""
        self.set_view_mode("result" if self.view_mode == "split" else "split")

    def toggle_compared_image(self):
        """Compare R with O instead of F, or back."""
        self.compare_with = "original" if self.compare_with == "filtered" else "filtered"

    def flicker(self):
        """Swap R and the comparison image in place (split view: swap the sides)."""
        self.swapped = not self.swapped

    def toggle_auto_flicker(self, now):
        """Start or stop swapping every :attr:`flicker_period` seconds, counting from `now`."""
        self.auto_flicker = not self.auto_flicker
        self._flicker_time = now

    def tick(self, now):
        """Swap if automatic flicker is on and its period has passed."""
        if self.auto_flicker and now - self._flicker_time >= self.flicker_period:
            self.flicker()
            self._flicker_time = now

    def side_names(self):
        """Names of the images shown left and right of the divider in split view."""
        compare = _IMAGE_NAMES[self.compare_with]
        return ("R", compare) if self.swapped else (compare, "R")

    def layers(self, texture, settings):
        """The layers the image view draws now: ``(left, right or None)``.

        Parameters
        ----------
        texture : callable
            ``Engine.texture``: a name to the engine's texture.
        settings : RecoverySettings
            The settings of the shown R (the maps are scaled by its sigmas).
        """
        result = texture("result")
        compare = texture(self.compare_with)
        mode = self.view_mode
        if mode == "result":
            return Layer.colour(compare if self.swapped else result), None
        if mode in ("filtered", "original"):
            return Layer.colour(result if self.swapped else texture(mode)), None
        if mode == "split":
            left, right = (result, compare) if self.swapped else (compare, result)
            return Layer.colour(left), Layer.colour(right)
        if mode == "difference":
            return Layer.difference(result, texture("filtered"), self.difference_gain), None
        gain = {"alpha": 1.0, "beta": 1.0, "edge_strength": 1.0 / (3.0 * settings.sigma_e),
                "residual": 1.0 / settings.sigma_d, "strength": 1.0}[mode]
        return Layer.map(texture(mode), gain), None
