"""The GIMP 3 plug-in, run for real in ``gimp-console-3.0`` inside a Debian trixie root.

Build the root once with ``sudo packaging/gimp-sandbox.sh`` (packaging/test.sh does it when run
as root). Without the root these tests skip with the command to build it, except under CI
(environment variable CI set), where they fail: CI must exercise GIMP.

Two batch runs share one throwaway GIMP profile into which ``python -m aarecovery.gimp
install`` (run inside the root, from the venv) installs the plug-in:

* in-process: ``PYTHONPATH`` lets GIMP's Python import aarecovery;
* out-of-process: GIMP's Python cannot import it, so the plug-in runs the core in the Python
  that the installer recorded (the venv).

Every exported result is compared with ``aarecovery.recover`` on the pixels GIMP exported as
its input; they must agree within 1/255.
"""

import json
import os
import shutil
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest

import aarecovery

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1]))
import sandbox  # noqa: E402
from scenes import disc_and_bar as scene  # noqa: E402

TOLERANCE = 1 / 255 + 1e-6
SIGMAS = {"sigma-d": 0.1, "sigma-e": 0.01, "iterations": 3}
THRESHOLD = {"filter": "threshold", "properties": "channel=value low=0.5 high=1.0"}


# ---- test images -----------------------------------------------------------------------------

def threshold(image):
    """A per-channel threshold at 0.5 (colour channels only): the classic edge-damaging filter."""
    out = image.copy()
    out[..., :3] = (image[..., :3] >= 0.5)
    return out


def as_model(rgba, model):
    if model == "rgb":
        return rgba[..., :3]
    if model == "rgba":
        return rgba
    grey = rgba[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    return grey if model == "grey" else np.stack([grey, rgba[..., 3]], -1)


def to_linear(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def to_srgb(v):
    return np.where(v <= 0.0031308, v * 12.92, 1.055 * np.maximum(v, 0) ** (1 / 2.4) - 0.055)


def write_png(path, image, bits):
    import imagecodecs
    scale = 255 if bits == 8 else 65535
    data = np.round(np.clip(image, 0, 1) * scale).astype(np.uint8 if bits == 8 else np.uint16)
    Path(path).write_bytes(imagecodecs.png_encode(data))


def read_image(path):
    """An exported file as float in [0, 1], shape (H, W, C); and its integer scale (or None)."""
    if str(path).endswith(".png"):
        import imagecodecs
        data = imagecodecs.png_decode(Path(path).read_bytes())
    else:
        import tifffile
        data = tifffile.imread(path)
    if data.ndim == 2:
        data = data[..., None]
    if data.dtype.kind == "u":
        scale = np.iinfo(data.dtype).max
        return data.astype(np.float64) / scale, scale
    return data.astype(np.float64), None


# ---- the cases -------------------------------------------------------------------------------

def build_cases(workdir, inside):
    """Write the input files; return the case list (paths as seen inside the root)."""
    rgba = scene()
    made = {}

    def source(model, bits, filtered=False):
        key = f"{model}{bits}{'-f' if filtered else ''}"
        if key not in made:
            image = as_model(threshold(rgba) if filtered else rgba, model)
            write_png(workdir / f"in-{key}.png", image, bits)
            made[key] = f"{inside}/in-{key}.png"
        return made[key]

    def layer_case(name, model, bits, **extra):
        case = {"name": name, "entry": "from-layer", "original": source(model, bits),
                "filtered": source(model, bits, True), "ext": "png", "args": dict(SIGMAS),
                "expect": "success"}
        case.update(extra)
        return case

    def filter_case(name, model, bits, args, reference, **extra):
        case = {"name": name, "entry": "apply-filter", "original": source(model, bits),
                "ext": "png", "args": {**SIGMAS, **args}, "reference": reference,
                "expect": "success"}
        case.update(extra)
        return case

    ellipse = [10, 6, 34, 26, 6]                     # x, y, w, h, feather radius
    return [
        layer_case("layer-rgb8", "rgb", 8),
        layer_case("layer-rgba8", "rgba", 8),
        layer_case("layer-grey8", "grey", 8),
        layer_case("layer-greya8", "greya", 8),
        layer_case("layer-rgb16", "rgb", 16),
        layer_case("layer-rgb-float", "rgb", 8, precision="FLOAT_NON_LINEAR", ext="tif"),
        layer_case("layer-rgba-float-linear", "rgba", 16, precision="FLOAT_LINEAR", ext="tif"),
        layer_case("layer-rgb8-feathered-selection", "rgb", 8, selection=ellipse,
                   original_arg=True),
        filter_case("filter-threshold-rgba8", "rgba", 8, THRESHOLD,
                    {"kind": "threshold", "low": 0.5, "high": 1.0}),
        filter_case("filter-posterize-grey16", "grey", 16,
                    {"filter": "posterize", "properties": "levels=3"},
                    {"kind": "method", "method": "posterize", "args": [3]}),
        filter_case("filter-unsharp-float", "rgb", 8,
                    {"filter": "unsharp-mask", "properties": "std-dev=2.0 scale=1.5 threshold=0"},
                    {"kind": "gegl", "operation": "gegl:unsharp-mask",
                     "set": {"std-dev": 2.0, "scale": 1.5, "threshold": 0.0}},
                    precision="FLOAT_NON_LINEAR", ext="tif"),
        filter_case("filter-gegl-median-selection", "rgb", 8,
                    {"filter": "gegl", "operation": "gegl:median-blur", "properties": "radius=2"},
                    {"kind": "gegl", "operation": "gegl:median-blur", "set": {"radius": 2}},
                    selection=ellipse),
        # The rest of the menu, each checked against the driver's own call of the same filter.
        filter_case("filter-levels-rgb8", "rgb", 8,
                    {"filter": "levels", "properties": "low-input=0.3 high-input=0.6 gamma=1.2"},
                    {"kind": "method", "method": "levels",
                     "args": ["VALUE", 0.3, 0.6, False, 1.2, 0.0, 1.0, False]}),
        filter_case("filter-curves-rgb8", "rgb", 8,
                    {"filter": "curves", "properties": "points=0,0,0.45,0.05,0.55,0.95,1,1"},
                    {"kind": "method", "method": "curves_spline",
                     "args": ["VALUE", [0, 0, 0.45, 0.05, 0.55, 0.95, 1, 1]]}),
        filter_case("filter-desaturate-rgb8", "rgb", 8,
                    {"filter": "desaturate", "properties": "mode=lightness"},
                    {"kind": "method", "method": "desaturate", "args": ["LIGHTNESS"]}),
        filter_case("filter-gradient-map-rgb8", "rgb", 8, {"filter": "gradient-map"},
                    {"kind": "proc", "procedure": "plug-in-gradmap"}, smooth=True),
        filter_case("filter-color-exchange-rgb8", "rgb", 8,
                    {"filter": "color-exchange", "properties":
                     "from-color=#e6bf33 to-color=#ff0000 red-threshold=0.2 "
                     "green-threshold=0.2 blue-threshold=0.2"},
                    {"kind": "gegl", "operation": "gegl:color-exchange",
                     "set": {"from-color": "#e6bf33", "to-color": "#ff0000", "red-threshold": 0.2,
                             "green-threshold": 0.2, "blue-threshold": 0.2}}),
        filter_case("filter-mono-mixer-rgb8", "rgb", 8,
                    {"filter": "mono-mixer", "properties": "red=0.9 green=0.3 blue=-0.2"},
                    {"kind": "gegl", "operation": "gegl:mono-mixer",
                     "set": {"red": 0.9, "green": 0.3, "blue": -0.2}}),
        filter_case("filter-bilateral-rgb8", "rgb", 8,
                    {"filter": "bilateral", "properties": "blur-radius=3 edge-preservation=4"},
                    {"kind": "gegl", "operation": "gegl:bilateral-filter",
                     "set": {"blur-radius": 3.0, "edge-preservation": 4.0}}),
        filter_case("filter-mean-curvature-rgb8", "rgb", 8,
                    {"filter": "mean-curvature", "properties": "iterations=15"},
                    {"kind": "gegl", "operation": "gegl:mean-curvature-blur",
                     "set": {"iterations": 15}}),
        layer_case("error-offset-layer", "rgb", 8, offset=[3, 2], expect="execution-error"),
        filter_case("error-unknown-operation", "rgb", 8,
                    {"filter": "gegl", "operation": "gegl:no-such-filter"},
                    {"kind": "threshold", "low": 0.5, "high": 1.0}, expect="execution-error"),
        filter_case("error-bad-property", "rgb", 8,
                    {"filter": "threshold", "properties": "lowest=0.5"},
                    {"kind": "threshold", "low": 0.5, "high": 1.0}, expect="execution-error"),
    ]


OUT_OF_PROCESS = ("layer-rgb8", "layer-rgb8-feathered-selection", "filter-threshold-rgba8",
                  "filter-unsharp-float", "error-offset-layer")
NO_GL = ("layer-rgb8", "filter-threshold-rgba8")


# ---- running GIMP ----------------------------------------------------------------------------

@pytest.fixture(scope="session")
def gimp_runs():
    """Install the checkout into the root, run both batch runs; yield their results."""
    missing = sandbox.missing_piece()
    if missing:
        message = (f"GIMP 3 plug-in tests cannot run: {missing}. Build the sandbox with: "
                   f"{sandbox.BUILD_HINT}")
        if os.environ.get("CI"):
            pytest.fail(message)
        print(f"\n*** SKIPPING THE GIMP TESTS: {message} ***\n", file=sys.stderr)
        pytest.skip(message)

    timings = {}
    with sandbox.Sandbox() as box:
        timings["install"] = box.install_checkout()
        inside = f"/tmp/aarecovery-test-{uuid.uuid4().hex[:8]}"
        workdir = box.host_path(inside)
        workdir.mkdir(parents=True)
        try:
            profile = f"{inside}/profile"
            box.run([sandbox.VENV_PYTHON, "-m", "aarecovery.gimp", "install"],
                    env={"GIMP3_DIRECTORY": profile})
            shutil.copy(Path(__file__).with_name("driver.py"), workdir / "driver.py")
            cases = build_cases(workdir, inside)
            runs = {}
            for mode, env, names in (
                    ("in-process", {"PYTHONPATH": sandbox.SITE}, None),
                    ("subprocess", {}, OUT_OF_PROCESS),
                    # No EGL vendor and no display: GL cannot start inside GIMP.
                    ("no-gl", {"PYTHONPATH": sandbox.SITE, "__EGL_VENDOR_LIBRARY_FILENAMES": "/nonexistent.json"},
                     NO_GL)):
                run_dir = workdir / mode
                run_dir.mkdir()
                chosen = [c for c in cases if names is None or c["name"] in names]
                (run_dir / "cases.json").write_text(json.dumps(chosen))
                start = time.monotonic()
                proc = box.gimp_batch(f"{inside}/driver.py", env={
                    "GIMP3_DIRECTORY": profile, "AARECOVERY_CASES": f"{inside}/{mode}/cases.json",
                    **env})
                timings[mode] = time.monotonic() - start
                results_file = run_dir / "results.json"
                if not results_file.exists():
                    pytest.fail(f"the {mode} GIMP batch run wrote no results (exit "
                                f"{proc.returncode}):\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
                runs[mode] = {"exit": proc.returncode, "log": proc.stdout + proc.stderr,
                              "dir": run_dir, "cases": {c["name"]: c for c in chosen},
                              "results": {r["name"]: r for r in json.loads(results_file.read_text())}}
            print("\nGIMP test timings (s): " +
                  ", ".join(f"{k} {v:.1f}" for k, v in timings.items()), file=sys.stderr)
            yield runs
        finally:
            if os.environ.get("AARECOVERY_KEEP_GIMP_TEST"):     # for debugging a failure
                print(f"kept the GIMP test files in {workdir}", file=sys.stderr)
            else:
                shutil.rmtree(workdir, ignore_errors=True)


CASE_NAMES = [
    "layer-rgb8", "layer-rgba8", "layer-grey8", "layer-greya8", "layer-rgb16",
    "layer-rgb-float", "layer-rgba-float-linear", "layer-rgb8-feathered-selection",
    "filter-threshold-rgba8", "filter-posterize-grey16", "filter-unsharp-float",
    "filter-gegl-median-selection", "filter-levels-rgb8", "filter-curves-rgb8",
    "filter-desaturate-rgb8", "filter-gradient-map-rgb8", "filter-color-exchange-rgb8",
    "filter-mono-mixer-rgb8", "filter-bilateral-rgb8", "filter-mean-curvature-rgb8"]
ERROR_CASES = {
    "error-offset-layer": "same size and position",
    "error-unknown-operation": "gegl:no-such-filter",
    "error-bad-property": "lowest",
}


def test_batch_runs_exit_cleanly(gimp_runs):
    # The driver raises when any call's status differs from the expected one: exit 64.
    for mode, run in gimp_runs.items():
        assert run["exit"] == 0, f"{mode} batch run failed:\n{run['log'][-4000:]}"
    for mode, run in gimp_runs.items():
        assert "Traceback" not in run["log"], f"{mode}: a traceback in GIMP's output:\n{run['log']}"


def check_case(run, name):
    case, result = run["cases"][name], run["results"][name]
    assert result["status"] == "success", f"{name}: {result}"
    folder, ext = run["dir"], case["ext"]
    original, scale = read_image(folder / f"{name}-O.{ext}")
    filtered, _ = read_image(folder / f"{name}-F.{ext}")
    recovered, _ = read_image(folder / f"{name}-R.{ext}")
    linear = result["precision"].endswith("-linear") and "non-linear" not in result["precision"]
    if case["entry"] == "apply-filter":
        filtered = np.clip(filtered, 0, 1)           # the plug-in clips a filter's overshoot
    else:
        # Sanity: GIMP held the pixels the test wrote (non-linear precisions keep them).
        written, _ = read_image(folder.parent / Path(case["original"]).name)
        if not linear:
            assert np.abs(written - original).max() < 1e-6, f"{name}: GIMP changed the input"
    expected = aarecovery.recover(original.astype(np.float32), filtered.astype(np.float32),
                                  sigma_d=case["args"]["sigma-d"], sigma_e=case["args"]["sigma-e"],
                                  iterations=case["args"]["iterations"], linear=linear,
                                  backend="numpy").astype(np.float64)
    if case.get("selection"):
        # The result merges through the selection mask onto what the layer held before; GIMP
        # composites in linear light, as it does for its own filters.
        mask = np.load(folder / f"{name}-mask.npy")[..., None]
        before = original if case["entry"] == "apply-filter" else filtered
        assert ((mask > 0.05) & (mask < 0.95)).any(), f"{name}: the selection is not feathered"
        if linear:
            expected = before + mask * (expected - before)
        else:
            expected = to_srgb(to_linear(before) + mask * (to_linear(expected) - to_linear(before)))
    assert recovered.shape == expected.shape, f"{name}: {recovered.shape} vs {expected.shape}"
    error = np.abs(recovered - expected).max()
    assert error <= TOLERANCE, f"{name}: max difference {error * 255:.3f}/255 from aarecovery.recover"
    # The test must be able to fail: the recovery changed something the filter had damaged.
    changed = np.abs(recovered - filtered).max()
    if not case.get("selection") and not case.get("smooth"):   # a smooth tone map damages no edge
        assert changed > 0.05, f"{name}: the result equals the filtered input"
    return result


@pytest.mark.parametrize("name", CASE_NAMES)
def test_in_process(gimp_runs, name):
    result = check_case(gimp_runs["in-process"], name)
    assert result["runner"] == "in-process"
    assert result["backend"] in ("gl", "numpy")


@pytest.mark.parametrize("name", NO_GL)
def test_numpy_fallback_when_gl_cannot_start(gimp_runs, name):
    # The same pixels from the NumPy backend; the in-process run above had GL.
    result = check_case(gimp_runs["no-gl"], name)
    assert result["backend"] == "numpy", result
    assert gimp_runs["in-process"]["results"][name]["backend"] == "gl"


@pytest.mark.parametrize("name", [n for n in OUT_OF_PROCESS if n in CASE_NAMES])
def test_out_of_process(gimp_runs, name):
    result = check_case(gimp_runs["subprocess"], name)
    assert result["runner"] == "subprocess"


@pytest.mark.parametrize("name", sorted(ERROR_CASES))
def test_errors_are_pdb_errors_with_a_message(gimp_runs, name):
    for mode, run in gimp_runs.items():
        if name not in run["results"]:
            continue
        result = run["results"][name]
        assert result["status"] == "execution-error", f"{mode} {name}: {result}"
        assert result["message"] and ERROR_CASES[name] in result["message"], (mode, result)
        # Nothing left behind: no temporary layer, the image has its input layers only.
        assert result["layers"] == (2 if name == "error-offset-layer" else 1), result


def test_dialog_opens_under_xvfb(gimp_runs, tmp_path):
    # The interactive path: GIMP's GUI under Xvfb must show the ProcedureDialog (the same run
    # makes docs/images/gimp-dialog.png). gimp_runs only orders this after the batch runs.
    import dialog_screenshot
    out = tmp_path / "dialog.png"
    dialog_screenshot.main(str(out))
    from PIL import Image
    with Image.open(out) as shot:
        assert shot.width > 200 and shot.height > 200, shot.size
