"""Swapped arguments: a one-line warning when the image given as original has the hard edges."""

import json
import os
import subprocess
import sys
import warnings
from importlib import resources

import numpy as np
import pytest

import aarecovery
from aarecovery import OrderWarning, check_order, filters
from aarecovery.cli import main
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.evaluate import QUICK
from aarecovery.lab.groundtruth import make_case


def to8(image):
    return np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)


@pytest.fixture(scope="module")
def quick_cases():
    """Every pair of the quick evaluation suite, 8-bit: {(scene, space, filter): (O, F)}."""
    cases = {}
    for scene in QUICK.scenes:
        rendered = _scenes.render(scene, QUICK.width, QUICK.k)
        spaces = ("linear",) if _scenes.SCENES[scene].kind == "photo" else ("linear", "srgb")
        for space in spaces:
            for name in QUICK.filters:
                case = make_case(rendered, name, QUICK.k, space)
                cases[scene, space, name] = to8(case.original), to8(case.filtered)
    return cases


def test_no_correctly_ordered_pair_is_called_reversed(quick_cases):
    called = [key for key, (o, f) in quick_cases.items() if check_order(o, f).looks_reversed]
    assert called == []


def test_every_reversed_threshold_pair_is_caught(quick_cases):
    verdicts = {key: check_order(f, o) for key, (o, f) in quick_cases.items() if key[2] == "threshold"}
    assert len(verdicts) == 7 and all(verdict.looks_reversed for verdict in verdicts.values()), verdicts
    reason = next(iter(verdicts.values())).reason
    assert "\n" not in reason and "look swapped" in reason and "hard edges" in reason


def test_an_aliased_drawing_under_a_blur_is_in_order():
    scene = _scenes.render("star", 128, 4)
    aliased = scene[2::4, 2::4]  # point-sampled: no antialiasing at all
    blurred = filters.apply("blur", aliased)
    verdict = check_order(to8(aliased), to8(blurred))
    assert not verdict.looks_reversed and "low-pass" in verdict.reason


@pytest.fixture
def swapped_files(tmp_path, quick_cases):
    original, filtered = quick_cases["text", "linear", "threshold"]
    aarecovery.write_image(tmp_path / "o.png", original)
    aarecovery.write_image(tmp_path / "f.png", filtered)
    return tmp_path


def test_recover_warns_in_the_api(swapped_files, quick_cases):
    original, filtered = quick_cases["text", "linear", "threshold"]
    with pytest.warns(OrderWarning, match="look swapped"):
        aarecovery.recover(filtered, original, backend="numpy")
    with warnings.catch_warnings():
        warnings.simplefilter("error", OrderWarning)
        aarecovery.recover(original, filtered, backend="numpy")


def test_the_command_line_warns_in_one_line(swapped_files, capsys):
    folder = swapped_files
    status = main(["recover", str(folder / "f.png"), str(folder / "o.png"), "-o", str(folder / "r.png"),
                   "--backend", "numpy"])
    captured = capsys.readouterr()
    assert status == 0
    (line,) = captured.err.splitlines()
    assert line.startswith("aarecovery: warning: the images look swapped")
    assert main(["recover", str(folder / "o.png"), str(folder / "f.png"), "-o", str(folder / "r.png"),
                 "--backend", "numpy"]) == 0
    assert capsys.readouterr().err == ""
    assert main(["filter", "threshold", str(folder / "o.png"), "-o", str(folder / "t.png"), "--recover",
                 "--backend", "numpy"]) == 0
    assert capsys.readouterr().err == ""


def test_the_plugin_worker_passes_it_on(tmp_path, quick_cases):
    original, filtered = (image.astype(np.float32) / 255 for image in quick_cases["text", "linear", "threshold"])
    np.save(tmp_path / "o.npy", filtered)  # swapped
    np.save(tmp_path / "f.npy", original)
    (tmp_path / "params.json").write_text(json.dumps(
        {"sigma_d": 0.1, "sigma_e": 0.01, "iterations": 3, "backend": "numpy", "linear": False,
         "clip_filtered": False}))
    script = resources.files("aarecovery.gimp").joinpath("aarecovery-gimp", "aarecovery-gimp.py")
    done = subprocess.run([sys.executable, os.fspath(script), "--worker",
                           *(str(tmp_path / name) for name in ("o.npy", "f.npy", "r.npy", "params.json"))],
                          capture_output=True, text=True, timeout=120)
    reply = json.loads(done.stdout.strip().splitlines()[-1])
    assert any(message.startswith("order: the images look swapped") for message in reply["messages"]), reply
