"""``aarecovery gimp install|uninstall|status``, the release zip and the worker mode (no GIMP)."""

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import aarecovery
from aarecovery.cli import main
from aarecovery.gimp import install as inst

CHECKOUT = Path(__file__).resolve().parents[2]


def test_gimp_dir_per_platform():
    env = {"HOME": "/home/u", "APPDATA": r"C:\Users\u\AppData\Roaming"}
    assert inst.gimp_dir("linux", env) == Path("/home/u/.config/GIMP/3.0")
    assert inst.gimp_dir("linux", {**env, "XDG_CONFIG_HOME": "/x"}) == Path("/x/GIMP/3.0")
    assert inst.gimp_dir("darwin", env) == Path("/home/u/Library/Application Support/GIMP/3.0")
    assert inst.gimp_dir("win32", env) == Path(r"C:\Users\u\AppData\Roaming") / "GIMP" / "3.0"
    assert inst.gimp_dir("win32", {**env, "GIMP3_DIRECTORY": "/p"}) == Path("/p")


def test_install_status_uninstall(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("GIMP3_DIRECTORY", str(tmp_path / "profile"))
    assert main(["gimp", "status"]) == 1
    assert "not installed" in capsys.readouterr().out

    assert main(["gimp", "install"]) == 0
    script = tmp_path / "profile" / "plug-ins" / "aarecovery-gimp" / "aarecovery-gimp.py"
    assert script.read_bytes() == inst.plugin_source().read_bytes()
    assert os.access(script, os.X_OK), "GIMP skips a plug-in that is not executable"
    config = json.loads((script.parent / "config.json").read_text())
    assert config["python"] == sys.executable
    assert config["aarecovery_version"] == aarecovery.__version__

    capsys.readouterr()
    assert main(["gimp", "status"]) == 0
    out = capsys.readouterr().out
    assert "executable:     yes" in out and "imports aarecovery" in out

    script.chmod(0o644)                                  # what a careless copy does
    assert main(["gimp", "status"]) == 1
    assert "not executable" in capsys.readouterr().out

    assert main(["gimp", "uninstall"]) == 0
    assert not script.parent.exists()


def test_install_records_another_python(tmp_path):
    inst.install(tmp_path, python="/opt/py/bin/python3")
    info = inst.status(tmp_path)
    assert info["python"] == "/opt/py/bin/python3" and not info["python_ok"]
    assert any("cannot import aarecovery" in p for p in info["problems"])


def test_zip_has_executable_plugin(tmp_path):
    subprocess.run([sys.executable, str(CHECKOUT / "packaging" / "build-gimp-zip.py"),
                    "--out", str(tmp_path)], check=True, capture_output=True)
    (archive,) = tmp_path.glob("aarecovery-gimp-*.zip")
    with zipfile.ZipFile(archive) as zf:
        info = zf.getinfo("aarecovery-gimp/aarecovery-gimp.py")
        assert (info.external_attr >> 16) & 0o111, "the script must unpack executable"
        assert zf.read(info) == inst.plugin_source().read_bytes()
        assert json.loads(zf.read("aarecovery-gimp/config.json")) == {"python": ""}


def test_worker_mode_matches_recover(tmp_path):
    """The out-of-process side, run as GIMP's plug-in would run it, needs no GIMP."""
    rng = np.random.default_rng(5)
    original = rng.random((12, 9, 3), dtype=np.float32)
    filtered = (original > 0.5).astype(np.float32)
    np.save(tmp_path / "o.npy", original)
    np.save(tmp_path / "f.npy", filtered)
    params = {"sigma_d": 0.1, "sigma_e": 0.01, "iterations": 3, "backend": "numpy",
              "linear": False, "clip_filtered": False}
    (tmp_path / "p.json").write_text(json.dumps(params))
    proc = subprocess.run([sys.executable, str(inst.plugin_source()), "--worker",
                           *(str(tmp_path / n) for n in ("o.npy", "f.npy", "r.npy", "p.json"))],
                          capture_output=True, text=True, check=True)
    reply = json.loads(proc.stdout.strip().splitlines()[-1])
    assert reply["backend"] == "numpy"
    expected = aarecovery.recover(original, filtered, backend="numpy")
    np.testing.assert_allclose(np.load(tmp_path / "r.npy"), expected, atol=1e-6)


def test_worker_mode_reports_bad_input(tmp_path):
    np.save(tmp_path / "o.npy", np.zeros((4, 4, 3), np.float32))
    np.save(tmp_path / "f.npy", np.zeros((5, 4, 3), np.float32))
    (tmp_path / "p.json").write_text(json.dumps({"backend": "numpy", "linear": False}))
    proc = subprocess.run([sys.executable, str(inst.plugin_source()), "--worker",
                           *(str(tmp_path / n) for n in ("o.npy", "f.npy", "r.npy", "p.json"))],
                          capture_output=True, text=True)
    assert proc.returncode == 0
    assert "error" in json.loads(proc.stdout.strip().splitlines()[-1])
    assert not (tmp_path / "r.npy").exists()


@pytest.mark.parametrize("argv", [["gimp", "--help"]])
def test_help(argv, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 0
    assert "install" in capsys.readouterr().out
