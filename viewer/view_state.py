"""Where the image sits in the window: zoom, pan and the split divider, as plain arithmetic.

Everything here is in *view pixels*: framebuffer pixels of the image area (the part of the
window not covered by the side panel), origin at its top-left corner, y down. At zoom 1 one
image pixel covers one physical pixel, which is what "1:1" must mean on a HiDPI screen.

Magnified zoom levels are whole numbers, so that every texel covers the same number of screen
pixels (a 3x zoom that alternated 3- and 4-pixel texels would itself look like aliasing, the
very thing the viewer is for).
"""

import math
from dataclasses import dataclass

__all__ = ["ViewState", "MAX_ZOOM", "ZOOM_LEVELS"]

#: The strongest magnification: 32 screen pixels per image pixel.
MAX_ZOOM = 32.0
#: The levels the wheel and the +/- keys step through (fit-to-window may sit between them).
ZOOM_LEVELS = (1 / 16, 1 / 12, 1 / 8, 1 / 6, 1 / 4, 1 / 3, 1 / 2, 2 / 3, 1.0, 2.0, 3.0, 4.0, 6.0,
               8.0, 12.0, 16.0, 24.0, 32.0)
# How much of the image must stay on screen after a pan, in view pixels: enough to find it again.
_KEEP_VISIBLE = 48.0
# Comparisons between zoom levels tolerate float noise from repeated multiplication.
_ZOOM_EPSILON = 1e-6


@dataclass
class ViewState:
    """The mapping between image pixels and view pixels, and the split divider.

    Attributes
    ----------
    image_width, image_height : int
        Size of the image shown, in pixels.
    view_width, view_height : float
        Size of the image area, in framebuffer pixels.
    zoom : float
        View pixels per image pixel.
    offset_x, offset_y : float
        View position of the image's top-left corner.
    split : float
        Divider position as a fraction of the view width (0 left edge, 1 right edge).
    """

    image_width: int = 1
    image_height: int = 1
    view_width: float = 1.0
    view_height: float = 1.0
    zoom: float = 1.0
    offset_x: float = 0.0
    offset_y: float = 0.0
    split: float = 0.5

    # ----------------------------------------------------------------- coordinates
    def image_to_view(self, x, y):
        """View position of image position ``(x, y)`` (pixel corners are whole numbers)."""
        return self.offset_x + x * self.zoom, self.offset_y + y * self.zoom

    def view_to_image(self, x, y):
        """Image position (fractional) under view position ``(x, y)``."""
        return (x - self.offset_x) / self.zoom, (y - self.offset_y) / self.zoom

    def pixel_at(self, x, y):
        """The image pixel ``(column, row)`` under a view position, or None outside the image."""
        image_x, image_y = self.view_to_image(x, y)
        column, row = math.floor(image_x), math.floor(image_y)
        if 0 <= column < self.image_width and 0 <= row < self.image_height:
            return column, row
        return None

    # ----------------------------------------------------------------- sizes
    def set_image_size(self, width, height):
        """Show an image of a new size, fitted to the view."""
        self.image_width, self.image_height = max(1, int(width)), max(1, int(height))
        self.fit()

    def set_view_size(self, width, height):
        """Resize the view, keeping the image point at the view centre where it was."""
        width, height = max(1.0, float(width)), max(1.0, float(height))
        if (width, height) == (self.view_width, self.view_height):
            return
        centre = self.view_to_image(self.view_width / 2, self.view_height / 2)
        self.view_width, self.view_height = width, height
        self.offset_x = width / 2 - centre[0] * self.zoom
        self.offset_y = height / 2 - centre[1] * self.zoom
        self._keep_on_screen()

    # ----------------------------------------------------------------- zoom
    @property
    def min_zoom(self):
        """The weakest zoom: a sixteenth, or less when even that does not fit the view."""
        return min(ZOOM_LEVELS[0], self.fit_zoom())

    def fit_zoom(self):
        """The zoom that shows the whole image; whole numbers when it magnifies."""
        zoom = min(self.view_width / self.image_width, self.view_height / self.image_height)
        if zoom >= 1:
            zoom = min(MAX_ZOOM, math.floor(zoom))
        return zoom

    def fit(self):
        """Show the whole image, centred (the fit-to-window key)."""
        self.zoom = self.fit_zoom()
        self._centre()

    def one_to_one(self):
        """One image pixel per view pixel, keeping the image point at the view centre."""
        self.zoom_at(self.view_width / 2, self.view_height / 2, 1.0)

    def zoom_at(self, x, y, zoom):
        """Set the zoom, keeping the image point under view position ``(x, y)`` fixed."""
        zoom = min(MAX_ZOOM, max(self.min_zoom, float(zoom)))
        image_x, image_y = self.view_to_image(x, y)
        self.zoom = zoom
        self.offset_x = x - image_x * zoom
        self.offset_y = y - image_y * zoom
        if zoom >= 1:
            # Whole-pixel offsets put texel edges on pixel edges at every magnified level.
            self.offset_x, self.offset_y = round(self.offset_x), round(self.offset_y)
        self._keep_on_screen()

    def next_zoom(self, steps):
        """The zoom `steps` levels above (positive) or below (negative) the current one."""
        zoom = self.zoom
        for _ in range(abs(int(steps))):
            if steps > 0:
                higher = [level for level in ZOOM_LEVELS if level > zoom * (1 + _ZOOM_EPSILON)]
                zoom = higher[0] if higher else MAX_ZOOM
            else:
                lower = [level for level in ZOOM_LEVELS if level < zoom * (1 - _ZOOM_EPSILON)]
                zoom = lower[-1] if lower else self.min_zoom
        return zoom

    def step_zoom_at(self, x, y, steps):
        """Zoom in (`steps` > 0) or out by whole levels around view position ``(x, y)``."""
        if steps:
            self.zoom_at(x, y, self.next_zoom(steps))

    # ----------------------------------------------------------------- pan
    def pan(self, dx, dy):
        """Move the image by ``(dx, dy)`` view pixels (a mouse drag)."""
        self.offset_x += dx
        self.offset_y += dy
        self._keep_on_screen()

    # ----------------------------------------------------------------- split
    @property
    def split_x(self):
        """View x of the divider."""
        return self.split * self.view_width

    def set_split_at(self, x):
        """Move the divider to view x (clamped to the view)."""
        self.split = min(1.0, max(0.0, x / self.view_width))

    def near_divider(self, x, tolerance):
        """True when view x is within `tolerance` view pixels of the divider."""
        return abs(x - self.split_x) <= tolerance

    # ----------------------------------------------------------------- helpers
    def _centre(self):
        self.offset_x = (self.view_width - self.image_width * self.zoom) / 2
        self.offset_y = (self.view_height - self.image_height * self.zoom) / 2
        if self.zoom >= 1:
            self.offset_x, self.offset_y = math.floor(self.offset_x), math.floor(self.offset_y)

    def _keep_on_screen(self):
        # Clamp so that at least a strip of the image (or all of a small one) stays visible.
        shown_width = self.image_width * self.zoom
        shown_height = self.image_height * self.zoom
        keep_x = min(_KEEP_VISIBLE, shown_width)
        keep_y = min(_KEEP_VISIBLE, shown_height)
        self.offset_x = min(self.view_width - keep_x, max(keep_x - shown_width, self.offset_x))
        self.offset_y = min(self.view_height - keep_y, max(keep_y - shown_height, self.offset_y))
