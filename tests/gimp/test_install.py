"""``aarecovery gimp install|uninstall|status``, the release zip and the worker mode (no GIMP).

Nothing here downloads: the bundle's failure paths run pip offline. test_bundle.py makes real
bundles through the package index.
"""

import json
import os
import re
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import numpy as np
import pytest

import aarecovery
import aarecovery_bridge
from aarecovery.cli import main
from aarecovery.gimp import InstallError, gimp_python, profiles
from aarecovery.gimp import install as inst
from aarecovery_bridge import npy, parameters, worker

CHECKOUT = Path(__file__).resolve().parents[2]


def test_gimp_dir_per_platform():
    env = {"HOME": "/home/u", "APPDATA": r"C:\Users\u\AppData\Roaming"}
    assert profiles.gimp_dir("linux", env) == Path("/home/u/.config/GIMP/3.0")
    assert profiles.gimp_dir("linux", {**env, "XDG_CONFIG_HOME": "/x"}) == Path("/x/GIMP/3.0")
    assert profiles.gimp_dir("darwin", env) == Path("/home/u/Library/Application Support/GIMP/3.0")
    assert profiles.gimp_dir("win32", env) == Path(r"C:\Users\u\AppData\Roaming") / "GIMP" / "3.0"
    assert profiles.gimp_dir("win32", {**env, "GIMP3_DIRECTORY": "/p"}) == Path("/p")
    assert profiles.flatpak_gimp_dir(env) == Path("/home/u/.var/app/org.gimp.GIMP/config/GIMP/3.0")


def test_flatpak_profile_is_found_and_offered(tmp_path):
    env = {"HOME": str(tmp_path), "PATH": str(tmp_path / "empty-bin")}
    assert [p.kind for p in profiles.find_profiles("linux", env)] == ["native"]
    flatpak = tmp_path / ".var/app/org.gimp.GIMP/config/GIMP/3.0"
    flatpak.mkdir(parents=True)
    # Only the Flatpak GIMP here: it is chosen, and the user is told.
    native, found = profiles.find_profiles("linux", env)
    assert (native.found, found.kind, found.plugins_dir) == (False, "flatpak", flatpak / "plug-ins")
    chosen, note = profiles.choose_profile(platform="linux", environ=env)
    assert chosen.kind == "flatpak" and "only the Flatpak GIMP" in note
    # Both: the native one by default, the Flatpak's offered.
    (tmp_path / ".config/GIMP/3.0").mkdir(parents=True)
    chosen, note = profiles.choose_profile(platform="linux", environ=env)
    assert chosen.kind == "native" and "--flatpak" in note
    assert profiles.choose_profile(flatpak=True, platform="linux", environ=env)[0].kind == "flatpak"
    custom = profiles.choose_profile(platform="linux", environ={**env, "GIMP3_DIRECTORY": "/p"})
    assert custom == (profiles.Profile("custom", Path("/p/plug-ins")), None)
    # Windows and macOS have no Flatpak.
    assert [p.kind for p in profiles.find_profiles("win32", env)] == ["native"]


def test_target_from_tags():
    linux = gimp_python.from_tags("3.13", "manylinux_2_28_x86_64")
    assert (linux.python, linux.platform) == ("3.13", "linux-x86_64")
    # Wheels for every older glibc load too; the legacy names stand for 2.17, 2.12 and 2.5.
    assert linux.pip_platforms[:2] == ("manylinux_2_28_x86_64", "manylinux_2_27_x86_64")
    assert {"manylinux2014_x86_64", "manylinux1_x86_64"} <= set(linux.pip_platforms)
    assert linux.pip_platforms[-1] == "manylinux1_x86_64"
    assert gimp_python.from_tags("3.12", "manylinux2014_aarch64").pip_platforms[0] == \
        "manylinux_2_17_aarch64"
    mac = gimp_python.from_tags("3.12", "macosx_11_0_arm64")
    assert (mac.platform, mac.pip_platforms) == ("macosx-arm64", ("macosx_11_0_arm64",))
    windows = gimp_python.from_tags("3.12", "win_amd64")
    assert windows.platform == "win-amd64" and "MSYS2" in gimp_python.caveat(windows)
    assert gimp_python.caveat(linux) is None
    for version, tag, message in (("3", "win_amd64", "X.Y"), ("3.12", "linux_x86_64", "platform tag"),
                                  ("3.12", None, "go together")):
        with pytest.raises(InstallError, match=message):
            gimp_python.target_for("native", python_version=version, platform_tag=tag)


def test_target_from_what_the_python_says():
    probe = {"implementation": "cpython", "version": "3.12", "machine": "arm64", "libc": None}
    mac = gimp_python._from_probe({**probe, "platform": "macosx-11.0-arm64"}, "GIMP.app's python3")
    assert (mac.platform, mac.pip_platforms) == ("macosx-arm64", ("macosx_11_0_arm64",))
    universal = gimp_python._from_probe({**probe, "platform": "macosx-10.13-universal2"}, "py")
    assert universal.pip_platforms == ("macosx_10_13_arm64",)
    linux = gimp_python._from_probe({**probe, "platform": "linux-x86_64", "libc": "glibc 2.41"}, "py")
    assert linux.pip_platforms[0] == "manylinux_2_41_x86_64"
    # GIMP's Windows installer ships MSYS2's Python: PyPI's wheels cannot load there.
    with pytest.raises(InstallError, match="MSYS2"):
        gimp_python._from_probe({**probe, "platform": "mingw_x86_64_ucrt_llvm"}, "bin/python.exe")
    with pytest.raises(InstallError, match="glibc"):
        gimp_python._from_probe({**probe, "platform": "linux-x86_64"}, "alpine's python3")
    with pytest.raises(InstallError, match="CPython only"):
        gimp_python._from_probe({**probe, "implementation": "pypy", "platform": "linux-x86_64"}, "p")


def test_asks_a_real_python():
    target = gimp_python.ask([sys.executable], sys.executable)
    assert target.python == "%d.%d" % sys.version_info[:2]
    assert target.platform == "linux-x86_64" if sys.platform == "linux" else target.platform
    with pytest.raises(InstallError, match="cannot run /nonexistent/python3"):
        gimp_python.ask(["/nonexistent/python3"], "/nonexistent/python3")


def _fake_gimp(prefix):
    """A GIMP 3 installation's layout: bin/gimp-3.0 and this test's Python as its python3."""
    bin_dir = prefix / "bin"
    bin_dir.mkdir(parents=True)
    gimp = bin_dir / "gimp-3.0"
    gimp.write_text("#!/bin/sh\n")
    gimp.chmod(0o755)
    return bin_dir


def test_finds_the_python_of_a_native_gimp(tmp_path):
    bin_dir = _fake_gimp(tmp_path / "usr")
    env = {"PATH": str(bin_dir), "HOME": str(tmp_path)}
    assert gimp_python.native_gimp_python("linux", {"PATH": str(tmp_path), "HOME": "/h"}) is None
    (bin_dir / "python3").symlink_to(sys.executable)
    assert gimp_python.native_gimp_python("linux", env) == bin_dir / "python3"
    # An interpreters file (as GIMP's Windows and macOS builds have) wins: GIMP follows it.
    interp = tmp_path / "usr/lib/gimp/3.0/interpreters"
    interp.mkdir(parents=True)
    (interp / "pygimp.interp").write_text("# comment\npython=python.exe\npython3=/opt/py/python3\n"
                                          ":Python:E::py::python3:\n")
    assert gimp_python.native_gimp_python("linux", env) == Path("/opt/py/python3")
    (interp / "pygimp.interp").write_text(":Python:E::py::python.exe:\n")
    assert gimp_python.native_gimp_python("win32", env) == bin_dir / "python.exe"


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


def offline_pip(monkeypatch, tmp_path):
    """pip with no index and an empty wheel folder: every download fails, quickly."""
    (tmp_path / "no-wheels").mkdir()
    monkeypatch.setenv("PIP_NO_INDEX", "1")
    monkeypatch.setenv("PIP_FIND_LINKS", str(tmp_path / "no-wheels"))


def test_failed_bundle_leaves_the_earlier_install(tmp_path, monkeypatch, capsys):
    plugins = tmp_path / "plug-ins"
    inst.install(plugins)
    before = sorted(p.name for p in plugins.iterdir())
    config = (plugins / "aarecovery-gimp" / "config.json").read_text()
    offline_pip(monkeypatch, tmp_path)
    capsys.readouterr()
    assert main(["gimp", "install", "--plugins-dir", str(plugins), "--python-version", "3.13",
                 "--platform", "manylinux_2_28_x86_64"]) == 1
    err = capsys.readouterr().err
    # One line saying what is missing, for which Python, and what to check; no traceback.
    assert err.count("\n") == 1 and err.startswith("aarecovery: error: no wheel of numpy"), err
    assert "CPython 3.13 on linux-x86_64" in err and "--python-version" in err
    # The earlier plug-in is untouched and no staging folder is left behind.
    assert sorted(p.name for p in plugins.iterdir()) == before == ["aarecovery-gimp"]
    assert (plugins / "aarecovery-gimp" / "config.json").read_text() == config


def test_unwritable_plugins_folder_is_one_line(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    from aarecovery.gimp.__main__ import main as gimp_main
    assert gimp_main(["install", "--plugins-dir", str(tmp_path / "file" / "plug-ins")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("aarecovery: error: ") and err.count("\n") == 1, err


def test_flatpak_install_bundles_and_needs_flatpak_to_ask(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("PATH", str(Path(sys.executable).parent))       # no flatpak command
    monkeypatch.delenv("GIMP3_DIRECTORY", raising=False)
    assert main(["gimp", "install", "--flatpak"]) == 1
    captured = capsys.readouterr()
    assert "so the core is bundled" in captured.out
    assert captured.err.startswith("aarecovery: error: cannot ask the Flatpak GIMP")
    assert captured.err.count("\n") == 1
    assert not (tmp_path / ".var").exists()


THIS_PYTHON = ("%d.%d" % sys.version_info[:2],
               re.sub(r"^macosx-[0-9.]+-", "macosx-", sysconfig.get_platform()))


@pytest.mark.parametrize("python, platform, used", [
    (*THIS_PYTHON, True),
    ("3.9", THIS_PYTHON[1], False),              # GIMP's Python was upgraded since the install
    (THIS_PYTHON[0], "win-arm64", False)])
def test_plugin_uses_only_a_bundle_made_for_its_python(tmp_path, python, platform, used):
    (tmp_path / "site-packages").mkdir()
    bundle = {"python": python, "platform": platform}
    (tmp_path / "config.json").write_text(json.dumps({"python": "", "bundle": bundle}))
    host = worker.Host("GIMP", "aarecovery gimp", str(tmp_path), "the dialog", "")
    saved = list(sys.path)
    try:
        note = worker.use_bundle(host)
        path = list(sys.path)
    finally:
        sys.path[:] = saved
    assert (path[0] == str(tmp_path / "site-packages")) == used
    if used:
        assert note is None
    else:
        assert f"are for CPython {python} on {platform}, but GIMP runs cpython" in note
        assert "aarecovery gimp install --bundle" in note


def test_installed_helpers_are_the_scripts_release_and_need_only_the_standard_library(tmp_path):
    inst.install(tmp_path)
    folder = tmp_path / inst.PLUGIN_NAME
    script = (folder / f"{inst.PLUGIN_NAME}.py").read_text(encoding="utf-8")
    assert f'AARECOVERY_VERSION = "{aarecovery.__version__}"' in script
    assert aarecovery_bridge.__version__ == aarecovery.__version__
    # A host's Python without NumPy (or anything of ours) imports every helper module.
    probe = ("import sys; sys.path.insert(0, sys.argv[1]); sys.modules['numpy'] = None; "
             "import aarecovery_bridge.worker, aarecovery_bridge.filters, aarecovery_bridge.npy, "
             "aarecovery_bridge.parameters as p; print(aarecovery_bridge.__file__, len(p.RECOVERY_ARGUMENTS))")
    proc = subprocess.run([sys.executable, "-I", "-S", "-c", probe, str(folder)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(str(folder / "aarecovery_bridge")), proc.stdout
    # Helpers from another release: the plug-in stops with a message that says what to run.
    with pytest.raises(aarecovery_bridge.PluginError, match="aarecovery 0.0.9 but its helper modules .* "
                       "install both again with: aarecovery gimp install"):
        aarecovery_bridge.check_version("0.0.9", "aarecovery-gimp.py", "aarecovery gimp install")
    (folder / "aarecovery_bridge" / "npy.py").write_text("# an older copy\n")
    info = inst.status(tmp_path)
    assert not info["current"] and any("differs" in p for p in info["problems"])


def test_npy_codec_round_trips_with_numpy(tmp_path):
    data = np.random.default_rng(2).random((5, 7, 3), dtype=np.float32)
    npy.write_npy(tmp_path / "a.npy", data.tobytes(), data.shape)
    np.testing.assert_array_equal(np.load(tmp_path / "a.npy"), data)
    np.save(tmp_path / "b.npy", data)
    assert npy.read_npy(tmp_path / "b.npy", data.nbytes) == data.tobytes()
    with pytest.raises(aarecovery_bridge.PluginError, match="returned 420 bytes, expected 8"):
        npy.read_npy(tmp_path / "b.npy", 8)


def test_zip_has_executable_plugin(tmp_path):
    subprocess.run([sys.executable, str(CHECKOUT / "packaging" / "build-gimp-zip.py"),
                    "--out", str(tmp_path)], check=True, capture_output=True)
    (archive,) = tmp_path.glob("aarecovery-gimp-*.zip")
    with zipfile.ZipFile(archive) as zf:
        info = zf.getinfo("aarecovery-gimp/aarecovery-gimp.py")
        assert (info.external_attr >> 16) & 0o111, "the script must unpack executable"
        assert zf.read(info) == inst.plugin_source().read_bytes()
        config = json.loads(zf.read("aarecovery-gimp/config.json"))
        assert config == {"python": "", "aarecovery_version": aarecovery.__version__}
        assert "aarecovery-gimp/README.txt" in zf.namelist()
        for rel, source in inst.plugin_files():
            assert zf.read(f"aarecovery-gimp/{rel.as_posix()}") == source.read_bytes()


def run_worker(folder, tmp_path):
    """The worker process exactly as the installed plug-in in `folder` starts it."""
    return subprocess.run([sys.executable, "-c", worker.WORKER, str(folder),
                           *(str(tmp_path / n) for n in ("o.npy", "f.npy", "r.npy", "p.json"))],
                          capture_output=True, text=True)


def test_worker_mode_matches_recover(tmp_path):
    """The out-of-process side, run as GIMP's plug-in would run it, needs no GIMP."""
    inst.install(tmp_path / "plug-ins")
    rng = np.random.default_rng(5)
    original = rng.random((12, 9, 3), dtype=np.float32)
    filtered = (original > 0.5).astype(np.float32)
    np.save(tmp_path / "o.npy", original)
    np.save(tmp_path / "f.npy", filtered)
    params = {"sigma_d": 0.1, "sigma_e": 0.01, "iterations": 3, "backend": "numpy",
              "linear": False, "clip_filtered": False}
    (tmp_path / "p.json").write_text(json.dumps(params))
    proc = run_worker(tmp_path / "plug-ins" / inst.PLUGIN_NAME, tmp_path)
    assert proc.returncode == 0, proc.stderr
    reply = json.loads(proc.stdout.strip().splitlines()[-1])
    assert reply["backend"] == "numpy"
    expected = aarecovery.recover(original, filtered, backend="numpy")
    np.testing.assert_allclose(np.load(tmp_path / "r.npy"), expected, atol=1e-6)


def test_worker_mode_reports_bad_input(tmp_path):
    np.save(tmp_path / "o.npy", np.zeros((4, 4, 3), np.float32))
    np.save(tmp_path / "f.npy", np.zeros((5, 4, 3), np.float32))
    (tmp_path / "p.json").write_text(json.dumps({"backend": "numpy", "linear": False}))
    inst.install(tmp_path / "plug-ins")
    proc = run_worker(tmp_path / "plug-ins" / inst.PLUGIN_NAME, tmp_path)
    assert proc.returncode == 0
    assert "error" in json.loads(proc.stdout.strip().splitlines()[-1])
    assert not (tmp_path / "r.npy").exists()


@pytest.mark.parametrize("argv", [["gimp", "--help"]])
def test_help(argv, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 0
    assert "install" in capsys.readouterr().out


def test_plugin_dialog_repeats_the_core_parameters_exactly():
    """The plug-ins run in a host's Python, which may not import the core, so the bridge
    repeats every recovery parameter; each must equal aarecovery.PARAMETERS (name, kind,
    range, default, help)."""
    rows = parameters.RECOVERY_ARGUMENTS
    assert [row[0] for row in rows] == [spec.name.replace("_", "-") for spec in aarecovery.PARAMETERS.values()]
    for (_, _, kind, minimum, maximum, default, blurb), spec in zip(rows, aarecovery.PARAMETERS.values()):
        assert (kind, minimum, maximum, default, blurb) == (spec.kind.__name__, spec.minimum, spec.maximum,
                                                            spec.default, spec.help)
    # A parameter the safe default chooses has an "automatic" box, with the core's words.
    assert {name: blurb for name, (_, _, blurb) in parameters.AUTOMATIC_ARGUMENTS.items()} == {
        spec.name.replace("_", "-"): spec.automatic for spec in aarecovery.PARAMETERS.values() if spec.automatic}
