"""The Krita plug-in, run for real in Debian's Krita 5 through ``kritarunner`` (no display).

``aarecovery krita install`` puts the plug-in into a throwaway resource folder; the driver
(driver.py, run by ``kritarunner -s driver`` with ``QT_QPA_PLATFORM=offscreen``) makes
documents of the test's pixels, runs Krita's own Threshold, Posterize and Gradient Map, and
calls the installed plug-in's ``repair``, the code the menu entries run after their dialog.
Two runs: in-process (Krita's Python imports aarecovery from this test's environment) and
out-of-process (it cannot, so the plug-in runs the core in the Python recorded at install).

Every repaired layer, read back from Krita in its own depth, must equal ``aarecovery.recover``
on the O and F that Krita exported, within 1/255. Without Krita these tests skip with the
command to install it, except under CI (environment variable CI set), where they fail;
packaging/test.sh installs Debian's krita when run as root.
"""

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import time
from pathlib import Path

import numpy as np
import pytest

import aarecovery
from aarecovery.cli import main

sys.path.insert(0, str(Path(__file__).parents[1]))
from scenes import disc_and_bar as scene  # noqa: E402

HERE = Path(__file__).resolve().parent
TOLERANCE = 1 / 255 + 1e-6
SIGMAS = {"sigma-d": 0.1, "sigma-e": 0.01, "iterations": 3}
# Krita's stored channel order per colour model and depth (what the driver reports is checked
# against it), and the dtype of one channel per depth.
STORED = {("RGBA", "U8"): ("Blue", "Green", "Red", "Alpha"), ("RGBA", "U16"): ("Blue", "Green", "Red", "Alpha"),
          ("RGBA", "F16"): ("Red", "Green", "Blue", "Alpha"), ("RGBA", "F32"): ("Red", "Green", "Blue", "Alpha"),
          ("GRAYA", "U8"): ("Gray", "Alpha")}
DTYPES = {"U8": "<u1", "U16": "<u2", "F16": "<f2", "F32": "<f4"}
CORE_ORDER = {"RGBA": ("Red", "Green", "Blue", "Alpha"), "GRAYA": ("Gray", "Alpha")}
GRADIENT = ('<gradient type="stop"><stop offset="0" bitdepth="U8" alpha="1"><sRGB r="0.1" g="0.05" b="0.4"/>'
            '</stop><stop offset="1" bitdepth="U8" alpha="1"><sRGB r="1" g="0.85" b="0.2"/></stop></gradient>')


def missing_krita():
    if shutil.which("kritarunner"):
        return None
    return ("kritarunner is missing; install Debian's krita (and python3-pyqt5) as root, e.g. "
            "sudo bash packaging/test.sh, or: sudo apt-get install krita python3-pyqt5")


def as_model(rgba, model):
    if model == "RGBA":
        return rgba
    return np.stack([rgba[..., :3] @ np.array([0.2126, 0.7152, 0.0722]), rgba[..., 3]], -1)


def encode(image, depth, model="RGBA"):
    """float (H, W, C) in the core's order -> Krita's stored bytes for `model` and `depth`."""
    order, dtype = STORED[model, depth], DTYPES[depth]
    stored = image[..., [CORE_ORDER[model].index(name) for name in order]]
    if dtype.startswith("<u"):
        stored = np.round(np.clip(stored, 0, 1) * np.iinfo(dtype).max)
    return stored.astype(dtype).tobytes()


def decode(path, depth, shape, model="RGBA"):
    order, dtype = STORED[model, depth], DTYPES[depth]
    stored = np.frombuffer(Path(path).read_bytes(), dtype=dtype).reshape(shape[0], shape[1], len(order))
    stored = stored.astype(np.float64)
    if dtype.startswith("<u"):
        stored /= np.iinfo(dtype).max
    return stored[..., [order.index(name) for name in CORE_ORDER[model]]]


def threshold(image):
    """Colour channels (all but the last, alpha) at 0.5."""
    out = image.copy()
    out[..., :-1] = image[..., :-1] >= 0.5
    return out


def build_cases(folder):
    rgba = scene()
    h, w = rgba.shape[:2]

    def case(name, entry, depth="U8", settings=None, model="RGBA", **extra):
        image = as_model(rgba, model)
        (folder / f"{name}-in-O.raw").write_bytes(encode(image, depth, model))
        if entry == "from-layer":
            (folder / f"{name}-in-F.raw").write_bytes(encode(threshold(image), depth, model))
        return {"name": name, "entry": entry, "depth": depth, "model": model, "size": [w, h],
                "settings": {**SIGMAS, **(settings or {})}, **extra}

    def filtered_by(name, filter_key, props_text, props, depth="U8", **extra):
        return case(name, "apply-filter", depth, {"filter": filter_key, "properties": props_text},
                    filter_id=filter_key, reference_props=props, **extra)

    feathered = [10, 6, 34, 26, 4]
    return [
        filtered_by("filter-threshold-u8", "threshold", "threshold=128", {"threshold": 128}),
        filtered_by("filter-posterize-u8", "posterize", "steps=3", {"steps": 3}),
        filtered_by("filter-gradientmap-u8", "gradientmap", f"gradientXML='{GRADIENT}'", {"gradientXML": GRADIENT},
                    smooth=True),
        filtered_by("filter-indexcolors-u8", "indexcolors", "", {}),
        filtered_by("filter-palettize-u8", "palettize", "", {}),
        filtered_by("filter-desaturate-u8", "desaturate", "", {}, smooth=True),
        filtered_by("filter-threshold-u16", "threshold", "threshold=128", {"threshold": 128}, depth="U16"),
        filtered_by("filter-threshold-f32", "threshold", "threshold=128", {"threshold": 128}, depth="F32"),
        filtered_by("filter-threshold-u8-selection", "threshold", "threshold=128", {"threshold": 128},
                    selection=feathered),
        case("layer-u8", "from-layer"),
        case("layer-u8-selection", "from-layer", selection=feathered),
        case("layer-u16", "from-layer", depth="U16"),
        case("layer-f16", "from-layer", depth="F16"),
        filtered_by("filter-threshold-graya8", "threshold", "threshold=128", {"threshold": 128}, model="GRAYA"),
        case("error-group", "from-layer", group=True, expect="group layer"),
        case("error-offset", "from-layer", offset=[3, 2], expect="same size and position"),
        case("error-no-layer-below", "from-layer", alone=True, expect="no layer below"),
        filtered_by("error-bad-property", "threshold", "lowest=3", {"threshold": 128}, expect="has no property 'lowest'"),
    ]


OUT_OF_PROCESS = ("filter-threshold-u8", "layer-u8-selection", "filter-threshold-f32", "layer-u16", "layer-f16",
                  "filter-threshold-graya8", "error-offset")


def krita_run(workdir, mode, cases, pykrita, env, screenshot=None):
    run_dir = workdir / mode
    run_dir.mkdir()
    chosen = [c for c in cases if mode == "in-process" or c["name"] in OUT_OF_PROCESS]
    for case in chosen:
        for suffix in ("in-O", "in-F"):
            source = workdir / "inputs" / f"{case['name']}-{suffix}.raw"
            if source.exists():
                shutil.copy(source, run_dir / source.name)
    (run_dir / "cases.json").write_text(json.dumps(chosen))
    # Krita makes a frame-cache folder in the temporary folder and leaves it there: its own.
    (run_dir / "tmp").mkdir()
    full_env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "PYTHONPATH": str(HERE), "TMPDIR": str(run_dir / "tmp"),
                "AARECOVERY_KRITA_PYKRITA": str(pykrita), "AARECOVERY_KRITA_CASES": str(run_dir / "cases.json"),
                **env}
    if screenshot:
        full_env["AARECOVERY_KRITA_SCREENSHOT"] = str(screenshot)
    start = time.monotonic()
    proc = subprocess.run(["kritarunner", "-s", "driver"], env=full_env, capture_output=True, text=True,
                          timeout=600, cwd=run_dir)
    seconds = time.monotonic() - start
    results_file = run_dir / "results.json"
    if not results_file.exists():
        pytest.fail(f"the {mode} Krita run wrote no results (exit {proc.returncode}):\n"
                    f"{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
    results = {r["name"]: r for r in json.loads(results_file.read_text())}
    assert "driver" not in results, results["driver"]["message"]
    return {"dir": run_dir, "cases": {c["name"]: c for c in chosen}, "results": results, "seconds": seconds,
            "log": proc.stdout + proc.stderr}


@pytest.fixture(scope="session")
def krita_runs(tmp_path_factory):
    missing = missing_krita()
    if missing:
        message = f"Krita plug-in tests cannot run: {missing}"
        if os.environ.get("CI"):
            pytest.fail(message)
        print(f"\n*** SKIPPING THE KRITA TESTS: {message} ***\n", file=sys.stderr)
        pytest.skip(message)
    workdir = tmp_path_factory.mktemp("krita")
    resources = workdir / "resources"
    assert main(["krita", "install", "--resource-dir", str(resources), "--kritarc", str(workdir / "kritarc")]) == 0
    (workdir / "inputs").mkdir()
    cases = build_cases(workdir / "inputs")
    site_dir = sysconfig.get_paths()["purelib"]      # this test's aarecovery, NumPy, moderngl
    runs = {"in-process": krita_run(workdir, "in-process", cases, resources / "pykrita",
                                    {"AARECOVERY_KRITA_SITE": site_dir}, screenshot=workdir / "dialog.png"),
            "subprocess": krita_run(workdir, "subprocess", cases, resources / "pykrita", {})}
    print("\nKrita test timings (s): " + ", ".join(f"{k} {v['seconds']:.1f}" for k, v in runs.items()),
          file=sys.stderr)
    runs["workdir"] = workdir
    yield runs


def check_case(run, name):
    case, result = run["cases"][name], run["results"][name]
    assert result["status"] == "success", f"{name}: {result}"
    depth, model = case["depth"], case["model"]
    assert result["channels"] == list(STORED[model, depth]), result     # the layout the test assumes
    assert (result["depth_after"], result["model_after"]) == (depth, model), result
    shape = case["size"][::-1]
    folder = run["dir"]
    original, filtered, recovered = (decode(folder / f"{name}-{k}.raw", depth, shape, model) for k in "OFR")
    linear = "g10" in result["profile"]
    assert linear == (depth != "U8"), result["profile"]      # Krita's defaults: sRGB TRC for 8-bit only
    if case["entry"] == "apply-filter":
        filtered = np.clip(filtered, 0, 1)
    expected = aarecovery.recover(original.astype(np.float32), filtered.astype(np.float32), backend="numpy",
                                  sigma_d=SIGMAS["sigma-d"], sigma_e=SIGMAS["sigma-e"],
                                  iterations=SIGMAS["iterations"], linear=linear).astype(np.float64)
    if case.get("selection"):
        mask = np.frombuffer((folder / f"{name}-mask.raw").read_bytes(), np.uint8).reshape(shape)[..., None] / 255
        assert ((mask > 0.05) & (mask < 0.95)).any(), f"{name}: the selection is not feathered"
        before = original if case["entry"] == "apply-filter" else filtered
        expected = before + mask * (expected - before)
        assert np.abs(recovered - before)[mask[..., 0] == 0].max() == 0, f"{name}: changed outside the selection"
    error = np.abs(recovered - expected).max()
    assert error <= TOLERANCE, f"{name}: max difference {error * 255:.3f}/255 from aarecovery.recover"
    assert result["summary"].startswith(("repaired ", "returned F unchanged")), result
    if not case.get("smooth"):                     # the test must be able to fail
        assert np.abs(recovered - filtered).max() > 0.05, f"{name}: the result equals the filtered input"
    # The repair is a new layer above (one undoable step); the layer it read is as it was.
    target = "original" if case["entry"] == "apply-filter" else "filtered"
    assert result["added_layers"] == [[f"{target} (repaired)", True]], result
    assert np.array_equal(decode(folder / f"{name}-T.raw", depth, shape, model), original if target == "original"
                          else decode(folder / f"{name}-F.raw", depth, shape, model)), f"{name}: the layer read changed"
    return result, error


IN_PROCESS = ("filter-threshold-u8", "filter-posterize-u8", "filter-gradientmap-u8", "filter-indexcolors-u8",
              "filter-palettize-u8", "filter-desaturate-u8", "filter-threshold-u16",
              "filter-threshold-f32", "filter-threshold-u8-selection", "layer-u8", "layer-u8-selection", "layer-u16",
              "layer-f16", "filter-threshold-graya8")


@pytest.mark.parametrize("name", IN_PROCESS)
def test_in_process_equals_recover(krita_runs, name):
    result, error = check_case(krita_runs["in-process"], name)
    assert result["runner"] == "in-process", result
    print(f"{name}: max |Krita - recover| = {error * 255:.3f}/255 ({result['backend']})", file=sys.stderr)


@pytest.mark.parametrize("name", [n for n in OUT_OF_PROCESS if not n.startswith("error")])
def test_out_of_process_equals_recover(krita_runs, name):
    result, _ = check_case(krita_runs["subprocess"], name)
    assert result["runner"] == "subprocess", result
    # Krita's Python has no NumPy here: the pixels went through the standard-library codec.
    assert not result["numpy_in_krita"], result
    assert result["aarecovery_path"] != "", result


@pytest.mark.parametrize("name", ["error-group", "error-offset", "error-no-layer-below", "error-bad-property"])
def test_errors_are_one_clear_message_and_change_nothing(krita_runs, name):
    for mode in ("in-process", "subprocess"):
        run = krita_runs[mode]
        if name not in run["results"]:
            continue
        result = run["results"][name]
        assert result["status"] == "error", f"{mode} {name}: {result}"
        assert run["cases"][name]["expect"] in result["message"], result
        assert "\n" not in result["message"] and result["added_layers"] == [], result


def test_dialog_renders(krita_runs):
    from PIL import Image
    with Image.open(krita_runs["workdir"] / "dialog.png") as shot:
        assert shot.width > 200 and shot.height > 200, shot.size
