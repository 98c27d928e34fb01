"""Bundles made for real: pip downloads the wheels from the package index (CI has access).

Each bundle is made for the Python that runs these tests, so that it can load it here: in a
Python started without any site-packages (``-I -S``), as GIMP's own Python has none of ours.
That shows the bundle is complete by itself. test_gimp_plugin.py runs one in the real GIMP.
"""

import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import aarecovery
from aarecovery.cli import main
from aarecovery.gimp import gimp_python
from aarecovery.gimp import install as inst

CHECKOUT = Path(__file__).resolve().parents[2]

# What the plug-in does in GIMP's Python, in a Python that sees only the bundle.
BUNDLE_ONLY = """\
import json, sys
sys.path.insert(0, sys.argv[1])
import numpy as np
import aarecovery
original = np.load(sys.argv[2])
np.save(sys.argv[3], aarecovery.recover(original, (original > 0.5).astype(np.float32),
                                        backend="numpy"))
print(json.dumps({"numpy": np.__file__, "aarecovery": aarecovery.__file__,
                  "file_formats": sorted(m for m in sys.modules
                                         if m.split(".")[0] in ("PIL", "imagecodecs", "tifffile"))}))
"""


@pytest.fixture(scope="module")
def this_python():
    return gimp_python.ask([sys.executable], sys.executable)


def recover_with_the_bundle_only(site, tmp_path):
    """Run BUNDLE_ONLY on `site`; check its result equals recover's here; return its report."""
    original = np.random.default_rng(3).random((24, 31, 3), dtype=np.float32)
    np.save(tmp_path / "o.npy", original)
    proc = subprocess.run([sys.executable, "-I", "-S", "-c", BUNDLE_ONLY, str(site),
                           str(tmp_path / "o.npy"), str(tmp_path / "r.npy")],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-3000:]
    expected = aarecovery.recover(original, (original > 0.5).astype(np.float32), backend="numpy")
    np.testing.assert_allclose(np.load(tmp_path / "r.npy"), expected, atol=1e-6)
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["numpy"].startswith(str(site)) and report["aarecovery"].startswith(str(site))
    assert report["file_formats"] == [], "the plug-in's path imported a file-format package"
    return report


def test_flatpak_install_with_given_tags(tmp_path, monkeypatch, capsys, this_python):
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.delenv("GIMP3_DIRECTORY", raising=False)
    given = ["--python-version", this_python.python, "--platform", this_python.pip_platforms[0],
             "--wheel-dir", str(tmp_path / "wheels")]
    assert main(["gimp", "install", "--flatpak", *given]) == 0
    # The kept wheels are enough for the next bundle: it installs with no index at all.
    with monkeypatch.context() as offline:
        offline.setenv("PIP_NO_INDEX", "1")
        assert main(["gimp", "install", "--flatpak", *given]) == 0
    plugins = tmp_path / ".var/app/org.gimp.GIMP/config/GIMP/3.0/plug-ins"
    config = json.loads((plugins / "aarecovery-gimp" / "config.json").read_text())
    assert config["python"] == ""             # the Flatpak cannot run a Python from outside
    bundle = config["bundle"]
    assert (bundle["python"], bundle["platform"]) == (this_python.python, this_python.platform)
    assert set(bundle["packages"]) == {"aarecovery", "numpy", "moderngl", "glcontext"}
    assert not (plugins / "aarecovery-gimp" / "site-packages" / "bin").exists()
    recover_with_the_bundle_only(plugins / "aarecovery-gimp" / "site-packages", tmp_path)

    capsys.readouterr()
    assert main(["gimp", "status", "--flatpak", "--gimp-python", sys.executable]) == 0
    out = capsys.readouterr().out
    assert f"flatpak  {plugins} (plug-in installed)" in out
    assert "(up to date)" in out and f"GIMP's Python:  CPython {this_python.python}" in out
    # A GIMP running another Python, or a core changed since: status says what to do.
    older = inst.status(plugins, gimp_target=lambda: gimp_python.from_tags(
        "3.9", "manylinux_2_17_x86_64"))
    assert any(f"bundle is for CPython {this_python.python}" in p and "runs 3.9" in p
               for p in older["problems"]), older["problems"]
    (plugins / "aarecovery-gimp" / "site-packages" / "aarecovery" / "__init__.py").write_text("#\n")
    assert main(["gimp", "status", "--flatpak", "--gimp-python", sys.executable]) == 1
    assert "the bundled core differs" in capsys.readouterr().out


def test_zip_with_a_bundle(tmp_path, this_python):
    subprocess.run([sys.executable, str(CHECKOUT / "packaging" / "build-gimp-zip.py"),
                    "--out", str(tmp_path), "--python-version", this_python.python,
                    "--platform", this_python.pip_platforms[0]], check=True, capture_output=True)
    (archive,) = tmp_path.glob(f"aarecovery-gimp-*-cp{this_python.python.replace('.', '')}-*.zip")
    plugins = tmp_path / "plug-ins"
    with zipfile.ZipFile(archive) as zf:
        zf.extractall(plugins)
        mode = zf.getinfo("aarecovery-gimp/aarecovery-gimp.py").external_attr >> 16
    assert mode & 0o111, "the script must unpack executable"
    (plugins / "aarecovery-gimp" / "aarecovery-gimp.py").chmod(mode & 0o777)  # as unzip does
    assert "CPython " + this_python.python in (plugins / "aarecovery-gimp" / "README.txt").read_text()
    recover_with_the_bundle_only(plugins / "aarecovery-gimp" / "site-packages", tmp_path)
    info = inst.status(plugins, gimp_target=lambda: this_python)
    assert info["problems"] == [] and info["bundle_current"], info
