"""A clean build of the wheel is quiet and complete.

``pip install .`` once printed about 120 lines of setuptools' "Package would be ignored"
(folders of shaders and images that were data of a package but no package of their own).
The build runs as ``pip install .`` runs it, isolated, on a copy of the source tree; its
verbose log shows everything setuptools says.
"""

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# Import name -> source folder, as pyproject.toml's package-dir maps them.
FOLDERS = {"aarecovery": "core", "aarecovery/viewer": "viewer", "aarecovery/gimp": "plugin_gimp",
           "aarecovery/krita": "plugin_krita", "aarecovery_bridge": "plugin_bridge"}


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
    return done.stdout + done.stderr, names, wheel, source


def test_the_build_is_quiet(built):
    log = built[0]
    ignored = [line for line in log.splitlines() if "would be ignored" in line]
    assert not ignored, f"{len(ignored)} lines of 'Package would be ignored', the first: {ignored[0]}"


def test_the_wheel_holds_every_module_and_data_file(built):
    names = built[1]
    for package, folder in FOLDERS.items():
        for path in (ROOT / folder).rglob("*"):
            if path.is_file() and "__pycache__" not in path.parts:
                assert f"{package}/{path.relative_to(ROOT / folder).as_posix()}" in names, path


def install_command_when_installed_from(what, target):
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--target", str(target), str(what)],
                   check=True, capture_output=True, timeout=600)
    code = "from aarecovery.extras import install_command; print(install_command('viewer'))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          env={**os.environ, "PYTHONPATH": str(target)}, cwd=target)
    return done.stdout.strip()


def test_the_missing_extra_advice_fits_the_install(built, tmp_path, monkeypatch):
    _, _, wheel, source = built
    # From a folder: that folder with the extra (not PyPI's name, which only works from PyPI).
    assert install_command_when_installed_from(source, tmp_path / "folder").endswith(f" install '{source}[viewer]'")
    # From a wheel: the extra's packages themselves.
    assert "install 'glfw>=2.7'" in install_command_when_installed_from(wheel, tmp_path / "wheel")
    # This test's own environment, installed from the checkout by packaging/test.sh (editable).
    from aarecovery.extras import _source, install_command
    monkeypatch.chdir(ROOT)
    if _source() == (".", True):
        assert install_command("viewer").endswith("pip install -e '.[viewer]'")
