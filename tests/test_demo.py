"""The demo: runs from an install on the bundled sample and writes readable images."""

import os

import numpy as np
from PIL import Image

from aarecovery.lab.demo import DEMO_FILTERS, run_demo
from aarecovery.cli import main


def test_demo_command_writes_readable_images(tmp_path, capsys):
    folder = tmp_path / "demo"
    assert main(["demo", "-o", str(folder), "--backend", "numpy"]) == 0
    out = capsys.readouterr().out
    assert "sheet.png" in out
    for name in DEMO_FILTERS:
        assert name in out
    names = sorted(os.listdir(folder))
    assert "O.png" in names and "sheet.png" in names
    for name in DEMO_FILTERS:
        assert f"F-{name}.png" in names and f"R-{name}.png" in names
    for name in names:
        with Image.open(folder / name) as image:
            pixels = np.asarray(image)
        assert pixels.size > 0 and pixels.std() > 0


def test_demo_gains_are_positive_on_the_sample(tmp_path):
    outcome = run_demo(folder=str(tmp_path), backend="numpy")
    for name, (before, after) in outcome["gains"].items():
        assert after > before + 1.0, name


def test_demo_on_a_small_user_image_has_no_reference(tmp_path):
    image = np.zeros((40, 60, 3), np.uint8)
    image[10:30, 20:40] = 200
    outcome = run_demo(image, str(tmp_path), backend="numpy")
    assert all(gain is None for gain in outcome["gains"].values())
    assert os.path.exists(outcome["sheet"])


def test_demo_of_a_large_user_image_says_that_it_shrinks_it(tmp_path, capsys):
    from aarecovery import write_image
    write_image(tmp_path / "mine.png", (np.random.default_rng(0).random((300, 320, 3)) * 255).astype(np.uint8))
    assert main(["demo", str(tmp_path / "mine.png"), "-o", str(tmp_path / "demo"), "--backend", "numpy"]) == 0
    out = capsys.readouterr().out
    assert "(320x300) was shrunk 4x to 80x75" in out
    with Image.open(tmp_path / "demo" / "O.png") as image:
        assert image.size == (80, 75)
