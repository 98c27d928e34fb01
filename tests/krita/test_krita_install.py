"""``aarecovery krita install|remove|status``: resource folders, kritarc, the copied files (no Krita)."""

import json
import sys
from pathlib import Path

import aarecovery
from aarecovery.cli import main
from aarecovery.gimp import install as gimp_install
from aarecovery.krita import install as inst


def test_resource_folders_per_platform():
    env = {"HOME": "/home/u", "APPDATA": r"C:\Users\u\AppData\Roaming", "LOCALAPPDATA": r"C:\Users\u\AppData\Local"}
    linux = inst.native_profile("linux", env)
    assert (linux.resource_dir, linux.kritarc) == (Path("/home/u/.local/share/krita"), Path("/home/u/.config/kritarc"))
    xdg = inst.native_profile("linux", {**env, "XDG_DATA_HOME": "/d", "XDG_CONFIG_HOME": "/c"})
    assert (xdg.resource_dir, xdg.kritarc) == (Path("/d/krita"), Path("/c/kritarc"))
    windows = inst.native_profile("win32", env)
    assert windows.resource_dir == Path(r"C:\Users\u\AppData\Roaming") / "krita"
    assert windows.kritarc == Path(r"C:\Users\u\AppData\Local") / "kritarc"
    mac = inst.native_profile("darwin", env)
    assert mac.resource_dir == Path("/home/u/Library/Application Support/krita")
    flatpak = inst.flatpak_profile(env)
    assert flatpak.resource_dir == Path("/home/u/.var/app/org.kde.krita/data/krita")
    assert flatpak.kritarc == Path("/home/u/.var/app/org.kde.krita/config/kritarc")


def test_flatpak_is_found_and_offered(tmp_path):
    env = {"HOME": str(tmp_path), "PATH": str(tmp_path / "empty-bin")}
    assert [p.kind for p in inst.find_profiles("linux", env)] == ["native"]
    (tmp_path / ".var/app/org.kde.krita").mkdir(parents=True)
    chosen, note = inst.choose_profile(platform="linux", environ=env)
    assert chosen.kind == "flatpak" and "only the Flatpak Krita" in note
    (tmp_path / ".local/share/krita").mkdir(parents=True)      # the AppImage's and the package's
    chosen, note = inst.choose_profile(platform="linux", environ=env)
    assert chosen.kind == "native" and "--flatpak" in note


def test_kritarc_tick_keeps_everything_else(tmp_path):
    kritarc = tmp_path / "kritarc"
    text = "[General]\nfoo=1\n\n[python]\nenable_scripter=true\nenable_aarecovery_krita=false\n\n[Other]\nbar=2\n"
    kritarc.write_text(text)
    assert not inst.is_enabled(kritarc)
    inst.set_enabled(kritarc)
    after = kritarc.read_text()
    assert inst.is_enabled(kritarc) and after.count("enable_aarecovery_krita") == 1
    assert after.replace("enable_aarecovery_krita=true\n", "") == text.replace("enable_aarecovery_krita=false\n", "")
    inst.set_enabled(kritarc, False)
    assert not inst.is_enabled(kritarc)
    fresh = tmp_path / "new" / "kritarc"
    inst.set_enabled(fresh)
    assert fresh.read_text() == "[python]\nenable_aarecovery_krita=true\n"


def test_install_status_remove(tmp_path, capsys):
    where = ["--resource-dir", str(tmp_path / "krita"), "--kritarc", str(tmp_path / "kritarc")]
    assert main(["krita", "status", *where]) == 1
    assert "not installed" in capsys.readouterr().out
    assert main(["krita", "install", *where]) == 0
    pykrita = tmp_path / "krita" / "pykrita"
    for rel, source in inst.plugin_files():
        assert (pykrita / rel).read_bytes() == source.read_bytes(), rel
    # One copy of the shared helpers in the repository: the GIMP plug-in installs the same files.
    bridge = {rel.name: source for rel, source in inst.plugin_files() if rel.parts[0] == "aarecovery_bridge"}
    assert bridge == {rel.name: source for rel, source in gimp_install.plugin_files()
                      if rel.parts[0] == "aarecovery_bridge"}
    # The plug-in checks at run time that its aarecovery_bridge is of its own release.
    plugin = (pykrita / "aarecovery_krita" / "__init__.py").read_text()
    assert f'AARECOVERY_VERSION = "{aarecovery.__version__}"' in plugin
    config = json.loads((pykrita / "aarecovery_krita" / "config.json").read_text())
    assert config == {"python": sys.executable, "aarecovery_version": aarecovery.__version__}
    assert inst.is_enabled(tmp_path / "kritarc")
    capsys.readouterr()
    assert main(["krita", "status", *where]) == 0
    out = capsys.readouterr().out
    assert "up to date:      yes" in out and "enabled:         yes" in out and "imports aarecovery" in out

    inst.set_enabled(tmp_path / "kritarc", False)                 # unticked in Krita's manager
    (pykrita / "aarecovery_bridge" / "npy.py").write_text("# another release\n")
    assert main(["krita", "status", *where]) == 1
    out = capsys.readouterr().out
    assert "not enabled" in out and "differs from this aarecovery's" in out

    assert main(["krita", "remove", *where]) == 0
    assert sorted(p.name for p in pykrita.iterdir()) == []
    assert not inst.is_enabled(tmp_path / "kritarc")


def test_unwritable_folder_is_one_line(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    from aarecovery.krita.__main__ import main as krita_main
    assert krita_main(["install", "--resource-dir", str(tmp_path / "file" / "krita")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("aarecovery: error: cannot write to") and err.count("\n") == 1, err


def test_a_host_python_without_the_core_is_told_what_to_do(tmp_path):
    """What a host's Python without NumPy or aarecovery, and no worker Python, says; per host."""
    import subprocess
    profile = inst.Profile("custom", tmp_path / "krita")
    inst.install(profile)
    probe = ("import sys; sys.path.insert(0, sys.argv[1]); sys.modules['numpy'] = None\n"
             "from aarecovery_bridge import PluginError, worker\n"
             "for bundles in (True, False):\n"
             "    host = worker.Host('Krita', 'aarecovery krita', sys.argv[2], 'the dialog', '', bundles)\n"
             "    try:\n"
             "        worker.run_core(host, (b'', (0, 0, 4)), (b'', (0, 0, 4)), {})\n"
             "    except PluginError as error:\n"
             "        print(error)\n")
    proc = subprocess.run([sys.executable, "-I", "-S", "-c", probe, str(profile.pykrita),
                           str(tmp_path / "nowhere")], capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"})
    with_bundle, without = proc.stdout.strip().splitlines()
    assert "Krita's Python" in without and "cannot import aarecovery" in without, proc.stderr
    assert "install --bundle" in with_bundle and "--bundle" not in without
    assert "AARECOVERY_PYTHON" in without and "enter that Python in the dialog" in without
