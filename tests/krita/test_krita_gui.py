"""The Krita plug-in in Krita's real window (Debian's Krita 5 under Xvfb), through its menu.

gui_check.py, a test-only pykrita plug-in installed beside the real one, finds the menu
entries, opens a document with O below F, triggers Tools > Scripts > Repair antialiasing (from
layer below)... as the menu does, presses OK in the plug-in's dialog and exports the repaired
layer. Krita's Python here cannot import aarecovery, so the plug-in runs the core in the Python
that ``aarecovery krita install`` recorded (this test's). With ``AARECOVERY_KRITA_DOC_IMAGES=DIR``
the two screenshots are copied to DIR (docs/images/krita-dialog.png, krita-result.png).
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import aarecovery
from aarecovery.cli import main

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1]))
from scenes import disc_and_bar as scene  # noqa: E402
from test_krita_plugin import SIGMAS, TOLERANCE, decode, encode, threshold  # noqa: E402

HERE = Path(__file__).resolve().parent
DESKTOP = ("[Desktop Entry]\nType=Service\nServiceTypes=Krita/PythonPlugin\nX-KDE-Library=aarecovery_gui_check\n"
           "X-Python-2-Compatible=false\nName=aarecovery GUI check (tests only)\n")


@pytest.fixture(scope="module")
def gui_run(tmp_path_factory):
    missing = [tool for tool in ("krita", "xvfb-run") if not shutil.which(tool)]
    if missing:
        message = (f"Krita GUI test cannot run: {', '.join(missing)} missing; install Debian's krita, "
                   "python3-pyqt5 and xvfb as root (sudo bash packaging/test.sh)")
        if os.environ.get("CI"):
            pytest.fail(message)
        print(f"\n*** SKIPPING THE KRITA GUI TEST: {message} ***\n", file=sys.stderr)
        pytest.skip(message)
    root = tmp_path_factory.mktemp("krita-gui")
    data, config, folder = root / "data", root / "config", root / "case"
    for path in (config, folder, root / "tmp"):
        path.mkdir()
    # Another plug-in's tick already there: the installer must keep it.
    (config / "kritarc").write_text("[python]\nenable_aarecovery_gui_check=true\n")
    assert main(["krita", "install", "--resource-dir", str(data / "krita"), "--kritarc", str(config / "kritarc"),
                 "--python", sys.executable]) == 0
    check = data / "krita" / "pykrita" / "aarecovery_gui_check"
    check.mkdir()
    shutil.copy(HERE / "gui_check.py", check / "__init__.py")
    (check.parent / "aarecovery_gui_check.desktop").write_text(DESKTOP)
    rgba = scene(height=120, width=168)
    (folder / "O.raw").write_bytes(encode(rgba, "U8"))
    (folder / "F.raw").write_bytes(encode(threshold(rgba), "U8"))
    (folder / "case.json").write_text(json.dumps({"size": [168, 120]}))
    env = {**os.environ, "XDG_DATA_HOME": str(data), "XDG_CONFIG_HOME": str(config),
           "AARECOVERY_KRITA_GUI": str(folder),
           "TMPDIR": str(root / "tmp")}   # Krita leaves a frame-cache folder there
    env.pop("QT_QPA_PLATFORM", None)
    start = time.monotonic()
    # Its own session, so that a hung Krita is killed with xvfb-run (a Krita left running would
    # take the next run's arguments and let that one exit at once).
    proc = subprocess.Popen(["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", "krita", "--nosplash"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        _, stderr = proc.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, stderr = proc.communicate()
    seconds = time.monotonic() - start
    print(f"\nKrita GUI run: {seconds:.1f} s", file=sys.stderr)
    if not (folder / "gui.json").exists():
        pytest.fail(f"Krita's window run wrote no results (exit {proc.returncode}):\n{stderr[-4000:]}")
    if os.environ.get("AARECOVERY_KRITA_DOC_IMAGES") and (folder / "result.png").exists():
        for name in ("dialog", "result"):
            shutil.copy(folder / f"{name}.png", Path(os.environ["AARECOVERY_KRITA_DOC_IMAGES"]) / f"krita-{name}.png")
    return {"folder": folder, "record": json.loads((folder / "gui.json").read_text()), "rgba": rgba,
            "kritarc": (config / "kritarc").read_text()}


def test_the_check_ran_to_its_end(gui_run):
    assert "error" not in gui_run["record"], gui_run["record"]["error"]


def test_menu_has_both_entries_and_the_installer_kept_other_ticks(gui_run):
    assert gui_run["record"]["menu"] == ["Tools > Scripts > Repair antialiasing (from layer below)...",
                                         "Tools > Scripts > Repair antialiasing (apply filter)..."], gui_run["record"]
    assert "enable_aarecovery_gui_check=true" in gui_run["kritarc"]
    assert "enable_aarecovery_krita=true" in gui_run["kritarc"]


def test_menu_entry_repairs_the_layer_like_recover(gui_run):
    record, folder = gui_run["record"], gui_run["folder"]
    assert record["modal"] == [], record                      # no error box
    assert record["dialog_title"] == "Repair antialiasing", record
    shape = (120, 168)
    original, filtered, recovered = (decode(folder / f"{k}.raw", "U8", shape) for k in "OFR")
    expected = aarecovery.recover(original.astype(np.float32), filtered.astype(np.float32), backend="numpy",
                                  sigma_d=SIGMAS["sigma-d"], sigma_e=SIGMAS["sigma-e"], iterations=SIGMAS["iterations"])
    error = np.abs(recovered - expected).max()
    assert error <= TOLERANCE, f"max difference {error * 255:.3f}/255 from aarecovery.recover"
    assert np.abs(recovered - filtered).max() > 0.05
    assert record["layers"] == [["original", True], ["filtered", True], ["filtered (repaired)", True]], record
    for name in ("dialog.png", "result.png"):
        assert (folder / name).stat().st_size > 10_000, name


def test_one_undo_takes_the_repair_back(gui_run):
    # Krita's Python writes pixels outside the undo history; the repaired layer is one step.
    record, folder = gui_run["record"], gui_run["folder"]
    filtered, undone = (decode(folder / f"{k}.raw", "U8", (120, 168)) for k in "FU")
    assert record["layers_after_undo"] == ["original", "filtered"], record
    assert np.array_equal(undone, filtered)
