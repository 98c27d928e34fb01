"""Without OpenGL every command, the plug-in's worker and the API say so in one line.

The machine is made to lack OpenGL for real, in a child process: glvnd finds no EGL vendor,
Mesa offers at most OpenGL 3.0, and there is no X display; ``create_context`` then fails in
the drivers exactly as on a server without GL.
"""

import json
import os
import subprocess
import sys
from importlib import resources

import numpy as np
import pytest

from aarecovery import write_image

NO_GL = {"__EGL_VENDOR_LIBRARY_FILENAMES": "/nonexistent/no-vendor.json", "MESA_GL_VERSION_OVERRIDE": "3.0"}


def without_gl():
    env = {key: value for key, value in os.environ.items() if key not in ("DISPLAY", "WAYLAND_DISPLAY")}
    return {**env, **NO_GL}


def run(*args, module=("-m", "aarecovery")):
    return subprocess.run([sys.executable, *module, *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=without_gl())


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pair")
    ramp = np.tile(np.linspace(0, 255, 40).astype(np.uint8), (30, 1))
    write_image(folder / "o.png", ramp)
    write_image(folder / "f.png", np.where(ramp > 127, 255, 0).astype(np.uint8))
    return folder


def test_the_environment_really_has_no_gl():
    code = ("from aarecovery.backends.gl.context import create_context, GLUnavailable\n"
            "try:\n    create_context()\nexcept GLUnavailable as e:\n    print('unavailable:', e.reason)")
    done = run(module=("-c", code))
    assert done.stdout.startswith("unavailable:"), done.stdout + done.stderr


def assert_one_line(done, prefix):
    assert "Traceback" not in done.stderr, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(prefix), done.stderr
    return lines[0]


@pytest.mark.parametrize("command", [
    ["recover", "{o}", "{f}", "-o", "{out}/r.png", "--backend", "gl"],
    ["filter", "threshold", "{o}", "-o", "{out}/r.png", "--recover", "--backend", "gl"],
    ["demo", "-o", "{out}/demo", "--backend", "gl"],
    ["eval", "--quick", "--no-peers", "--scenes", "text", "--filters", "threshold", "--backend", "gl"],
    ["bench", "--configs", "gl-fragment", "--sizes", "32x32", "--runs", "1"],
], ids=lambda command: command[0])
def test_commands_fail_in_one_line_with_backend_gl(pair, tmp_path, command):
    names = {"o": pair / "o.png", "f": pair / "f.png", "out": tmp_path}
    done = run(*[part.format(**names) for part in command])
    assert done.returncode == 1
    line = assert_one_line(done, "aarecovery: error: no OpenGL 3.3 context here (")
    assert "--backend numpy" in line and "apt-get install" in line
    assert os.listdir(tmp_path) == []


def test_auto_falls_back_with_one_warning(pair, tmp_path):
    done = run("recover", pair / "o.png", pair / "f.png", "-o", tmp_path / "r.png")
    assert done.returncode == 0, done.stderr
    line = assert_one_line(done, "aarecovery: warning: no OpenGL 3.3 context (")
    assert "using the NumPy backend" in line
    assert "numpy backend" in done.stdout


def test_demo_warns_once_for_its_three_recoveries(tmp_path):
    done = run("demo", "-o", tmp_path / "demo")
    assert done.returncode == 0, done.stderr
    assert_one_line(done, "aarecovery: warning: no OpenGL 3.3 context (")


def plugin_worker(folder, backend):
    script = resources.files("aarecovery.gimp").joinpath("aarecovery-gimp", "aarecovery-gimp.py")
    ramp = np.tile(np.linspace(0, 1, 24, dtype=np.float32), (16, 1))
    np.save(folder / "o.npy", np.repeat(ramp[..., None], 3, -1))
    np.save(folder / "f.npy", np.repeat((ramp > 0.5).astype(np.float32)[..., None], 3, -1))
    (folder / "params.json").write_text(json.dumps(
        {"sigma_d": 0.1, "sigma_e": 0.01, "iterations": 3, "backend": backend, "linear": False,
         "clip_filtered": False}))
    done = run("--worker", *(folder / name for name in ("o.npy", "f.npy", "r.npy", "params.json")),
               module=(os.fspath(script),))
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_plugin_worker_reports_one_line(tmp_path):
    reply = plugin_worker(tmp_path, "gl")
    assert reply["error"].startswith("no OpenGL 3.3 context here (") and "\n" not in reply["error"]


def test_plugin_worker_notes_the_fallback_for_the_status_bar(tmp_path):
    reply = plugin_worker(tmp_path, "auto")
    assert reply["backend"] == "numpy"
    assert any(message.startswith("no OpenGL 3.3 context (") for message in reply["messages"]), reply
