"""A clean build of the wheel is quiet and complete.

``pip install .`` once printed about 120 lines of setuptools' "Package would be ignored"
(folders of shaders and images that were data of a package but no package of their own).
The build runs as ``pip install .`` runs it, isolated, on a copy of the source tree; its
verbose log shows everything setuptools says.
"""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# Import name -> source folder, as pyproject.toml's package-dir maps them.
FOLDERS = {"aarecovery": "core", "aarecovery/viewer": "viewer", "aarecovery/gimp": "plugin_gimp"}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    source = tmp_path_factory.mktemp("source") / "aarecovery"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(
        ".git", ".venv", "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache", "out", "aarecovery-demo"))
    wheels = tmp_path_factory.mktemp("wheels")
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-v", "-w", str(wheels), str(source)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    (wheel,) = wheels.glob("aarecovery-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    return done.stdout + done.stderr, names


def test_the_build_is_quiet(built):
    log, _ = built
    ignored = [line for line in log.splitlines() if "would be ignored" in line]
    assert not ignored, f"{len(ignored)} lines of 'Package would be ignored', the first: {ignored[0]}"


def test_the_wheel_holds_every_module_and_data_file(built):
    _, names = built
    for package, folder in FOLDERS.items():
        for path in (ROOT / folder).rglob("*"):
            if path.is_file() and "__pycache__" not in path.parts:
                assert f"{package}/{path.relative_to(ROOT / folder).as_posix()}" in names, path
