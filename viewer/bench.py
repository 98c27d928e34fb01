"""``aarecovery view --bench``: frame time while nothing changes, and slider-to-frame latency.

The latency is measured the way a user meets it: a mouse press is sent through the window's
input callbacks onto the sigma_e slider, and the clock stops when the frame showing the new R
has been presented and the GPU has finished it.
"""

import os
import statistics
import tempfile
import time

import glfw  # before imgui_bundle
import numpy as np

import aarecovery

from .app import ViewerApp
from .sources import PairSource

__all__ = ["run_bench", "make_bench_pair"]

_WARM_UP_FRAMES = 10
_IDLE_FRAMES = 120
_SLIDER_CHANGES = 8
# Frames a slider change may take to show before the bench gives up on it.
_MAX_FRAMES_PER_CHANGE = 20


def make_bench_pair(width, height):
    """An antialiased original (soft-edged discs and stripes) and its threshold, uint8 RGB.

    Returns
    -------
    original, filtered : ndarray of uint8, shape (height, width, 3)
    """
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    rng = np.random.default_rng(4)
    coverage = np.zeros((height, width), np.float32)
    for cx, cy, radius in zip(rng.uniform(0, width, 40), rng.uniform(0, height, 40),
                              rng.uniform(0.02, 0.12, 40) * min(width, height)):
        # Distance to the circle's edge, clipped to one pixel: an analytic antialiased edge.
        edge = np.clip(radius - np.hypot(x - cx, y - cy) + 0.5, 0, 1)
        coverage = np.maximum(coverage, edge)
    stripes = np.clip(np.abs(((x + 0.37 * y) % 64) - 32) - 15.5, 0, 1)
    blue = np.stack([0.15 + 0.0 * x, 0.25 + 0.0 * x, 0.55 + 0.0 * x], axis=-1)
    amber = np.array([0.95, 0.7, 0.2], np.float32)
    base = blue * (1 - 0.3 * stripes[..., None])
    original = base * (1 - coverage[..., None]) + amber * coverage[..., None]
    original = np.rint(original * 255).astype(np.uint8)
    luma = original @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    filtered = np.where((luma >= 110)[..., None], np.uint8(255), np.uint8(0)).repeat(3, axis=-1)
    return original, filtered


def _press(app, x, y):
    app.platform.cursor_pos_callback(app.window, x, y)
    app.platform.mouse_button_callback(app.window, glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)


def _release(app, x, y):
    app.platform.cursor_pos_callback(app.window, x, y)
    app.platform.mouse_button_callback(app.window, glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)


def _frame(app):
    app.step()
    app.context.finish()


def _idle_frame_times(app):
    times = []
    for _ in range(_IDLE_FRAMES):
        start = time.perf_counter()
        _frame(app)
        times.append(time.perf_counter() - start)
    return times


def _slider_latencies(app):
    left, top, right, bottom = app.widget_rects["sigma_e"]
    y = (top + bottom) / 2
    latencies = []
    for index in range(_SLIDER_CHANGES):
        # Alternate between two points of the slider so that every press changes the value.
        x = left + (right - left) * (0.3 if index % 2 == 0 else 0.7)
        before = app.recovery.recoveries
        start = time.perf_counter()
        _press(app, x, y)
        for _ in range(_MAX_FRAMES_PER_CHANGE):
            _frame(app)
            if app.recovery.recoveries > before:
                latencies.append(time.perf_counter() - start)
                break
        _release(app, x, y)
        for _ in range(3):
            _frame(app)
    return latencies


def _milliseconds(values):
    ordered = sorted(values)
    p95 = ordered[min(len(ordered) - 1, int(round(0.95 * (len(ordered) - 1))))]
    return f"median {statistics.median(values) * 1000:.1f} ms, p95 {p95 * 1000:.1f} ms, max {max(values) * 1000:.1f} ms"


def run_bench(original, filtered, filter_name, image_size, window_size):
    """Print the viewer's frame time and slider latency; returns 0, or 1 if a change never showed."""
    with tempfile.TemporaryDirectory(prefix="aarecovery-bench-") as folder:
        if original is None:
            pair = make_bench_pair(*image_size)
            original = os.path.join(folder, "original.png")
            filtered = os.path.join(folder, "filtered.png")
            aarecovery.write_image(original, pair[0])
            aarecovery.write_image(filtered, pair[1])
        source = PairSource(original, filtered, None if filtered else filter_name or "threshold")
        app = ViewerApp(None, size=window_size, vsync=False)
        try:
            if not app.opener.open(source):
                print(f"aarecovery view --bench: {app.messages[-1].text}")
                return 1
            for _ in range(_WARM_UP_FRAMES):
                _frame(app)
            renderer = app.context.info["GL_RENDERER"]
            fb_width, fb_height = glfw.get_framebuffer_size(app.window)
            width, height = app.recovery.pair.size
            print(f"renderer: {renderer}; window {fb_width}x{fb_height}; images {width}x{height}; "
                  f"{os.cpu_count()} CPUs")
            idle = _idle_frame_times(app)
            print(f"idle frame time ({len(idle)} frames): {_milliseconds(idle)} "
                  f"-> {1 / statistics.median(idle):.0f} frames per second")
            failed = False
            for mode in aarecovery.MODES:
                app.recovery.settings = app.recovery.settings.with_values(mode=mode)
                _frame(app)
                latencies = _slider_latencies(app)
                label = f"mode={mode}"
                if len(latencies) < _SLIDER_CHANGES:
                    print(f"slider-to-frame latency, {label}: {_SLIDER_CHANGES - len(latencies)} changes never showed")
                    failed = True
                if latencies:
                    print(f"slider-to-frame latency, {label} ({len(latencies)} changes of sigma_e): "
                          f"{_milliseconds(latencies)}; engine compute alone {app.engine.last_seconds * 1000:.1f} ms "
                          "(last change)")
        finally:
            app.close()
    return 1 if failed else 0
