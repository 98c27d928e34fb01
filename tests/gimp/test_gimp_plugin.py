"""The GIMP 3 plug-in, run for real in ``gimp-console-3.0`` inside a Debian trixie root.

Build the root once with ``sudo packaging/gimp-sandbox.sh`` (packaging/test.sh does it when run
as root). Without the root these tests skip with the command to build it, except under CI
(environment variable CI set), where they fail: CI must exercise GIMP.

Three batch runs share one throwaway GIMP profile into which ``python -m aarecovery.gimp
install`` (run inside the root, from the venv) installs the plug-in:

* in-process: ``PYTHONPATH`` lets GIMP's Python import aarecovery;
* out-of-process: GIMP's Python cannot import it, so the plug-in runs the core in the Python
  that the installer recorded (the venv);
* no-gl: in-process where no OpenGL context can be made.

A fourth run uses a profile installed with ``--bundle``: GIMP's Python imports the core, NumPy
and moderngl from the plug-in's own folder, with no aarecovery anywhere else it can see. Its
wheels come from the package index through pip, as in CI.

Every exported result is compared with ``aarecovery.recover`` on the pixels GIMP exported as
its input; they must agree within 1/255.
"""

import json
import os
import shutil
import sys
import time
import uuid
from contextlib import contextmanager
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
        layer_case("layer-rgb8-strength", "rgb", 8, args={**SIGMAS, "auto-strength": False, "strength": 0.4}),
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


OUT_OF_PROCESS = ("layer-rgb8", "layer-rgb8-feathered-selection", "layer-rgb8-strength", "filter-threshold-rgba8",
                  "filter-unsharp-float", "error-offset-layer")
NO_GL = ("layer-rgb8", "filter-threshold-rgba8")
BUNDLED = ("layer-rgb8", "layer-greya8", "layer-rgba-float-linear", "layer-rgb8-feathered-selection",
           "filter-threshold-rgba8", "filter-unsharp-float", "error-offset-layer")


# ---- running GIMP ----------------------------------------------------------------------------

@pytest.fixture(scope="session")
def installed_root():
    """The trixie root with the checkout installed in it (site dir and venv), mounted."""
    missing = sandbox.missing_piece()
    if missing:
        message = (f"GIMP 3 plug-in tests cannot run: {missing}. Build the sandbox with: "
                   f"{sandbox.BUILD_HINT}")
        if os.environ.get("CI"):
            pytest.fail(message)
        print(f"\n*** SKIPPING THE GIMP TESTS: {message} ***\n", file=sys.stderr)
        pytest.skip(message)
    with sandbox.Sandbox() as box:
        seconds = box.install_checkout()
        print(f"\nGIMP tests: checkout installed into the root in {seconds:.1f} s", file=sys.stderr)
        yield box


@contextmanager
def scratch_folder(box):
    """A throwaway folder inside the root with the driver in it: ``(path inside, host path)``."""
    inside = f"/tmp/aarecovery-test-{uuid.uuid4().hex[:8]}"
    workdir = box.host_path(inside)
    workdir.mkdir(parents=True)
    try:
        shutil.copy(Path(__file__).with_name("driver.py"), workdir / "driver.py")
        yield inside, workdir
    finally:
        if os.environ.get("AARECOVERY_KEEP_GIMP_TEST"):     # for debugging a failure
            print(f"kept the GIMP test files in {workdir}", file=sys.stderr)
        else:
            shutil.rmtree(workdir, ignore_errors=True)


def batch_run(box, inside, mode, profile, env, cases):
    """Run the driver on `cases` in GIMP with the plug-ins of `profile`; return the run."""
    run_dir = box.host_path(inside) / mode
    run_dir.mkdir()
    (run_dir / "cases.json").write_text(json.dumps(cases))
    start = time.monotonic()
    proc = box.gimp_batch(f"{inside}/driver.py", env={
        "GIMP3_DIRECTORY": profile, "AARECOVERY_CASES": f"{inside}/{mode}/cases.json", **env})
    seconds = time.monotonic() - start
    results_file = run_dir / "results.json"
    if not results_file.exists():
        pytest.fail(f"the {mode} GIMP batch run wrote no results (exit "
                    f"{proc.returncode}):\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
    return {"exit": proc.returncode, "log": proc.stdout + proc.stderr, "dir": run_dir,
            "seconds": seconds, "cases": {c["name"]: c for c in cases},
            "results": {r["name"]: r for r in json.loads(results_file.read_text())}}


@pytest.fixture(scope="session")
def gimp_runs(installed_root):
    """The plug-in installed as a pip user has it; the three batch runs' results."""
    box = installed_root
    with scratch_folder(box) as (inside, workdir):
        profile = f"{inside}/profile"
        box.run([sandbox.VENV_PYTHON, "-m", "aarecovery.gimp", "install"],
                env={"GIMP3_DIRECTORY": profile})
        cases = build_cases(workdir, inside)
        runs = {}
        for mode, env, names in (
                ("in-process", {"PYTHONPATH": sandbox.SITE}, None),
                ("subprocess", {}, OUT_OF_PROCESS),
                # No EGL vendor and no display: GL cannot start inside GIMP.
                ("no-gl", {"PYTHONPATH": sandbox.SITE, "__EGL_VENDOR_LIBRARY_FILENAMES": "/nonexistent.json"},
                 NO_GL)):
            chosen = [c for c in cases if names is None or c["name"] in names]
            runs[mode] = batch_run(box, inside, mode, profile, env, chosen)
        print("\nGIMP test timings (s): " +
              ", ".join(f"{k} {v['seconds']:.1f}" for k, v in runs.items()), file=sys.stderr)
        yield runs


@pytest.fixture(scope="session")
def bundled_run(installed_root):
    """The plug-in installed with ``--bundle``, which GIMP's Python must use: no other core.

    The installer asks GIMP's Python (the root's /usr/bin/python3) for its version and
    platform, and pip downloads the wheels through this machine's registry access into a
    wheel folder kept inside the root. Debian's python3-numpy and python3-moderngl stay
    installed: the bundle has to shadow them.
    """
    box = installed_root
    probe = box.run(["python3", "-c", "import aarecovery"], check=False)
    assert probe.returncode != 0, "aarecovery is importable by the root's Python: the test is void"
    with scratch_folder(box) as (inside, workdir):
        profile = f"{inside}/profile-bundled"
        start = time.monotonic()
        installed = box.run([sandbox.VENV_PYTHON, "-m", "aarecovery.gimp", "install", "--bundle",
                             "--wheel-dir", sandbox.WHEEL_CACHE],
                            env={"GIMP3_DIRECTORY": profile, **sandbox.pip_env()}, timeout=900)
        install_seconds = time.monotonic() - start
        status = box.run([sandbox.VENV_PYTHON, "-m", "aarecovery.gimp", "status"],
                         env={"GIMP3_DIRECTORY": profile}, check=False)
        cases = [c for c in build_cases(workdir, inside) if c["name"] in BUNDLED]
        run = batch_run(box, inside, "bundled", profile, {}, cases)
        run.update(install=installed.stdout, status=status,
                   site=f"{profile}/plug-ins/aarecovery-gimp/site-packages")
        print(f"\nGIMP bundled run (s): install {install_seconds:.1f}, batch {run['seconds']:.1f}"
              f"\n{installed.stdout.strip()}", file=sys.stderr)
        yield run


CASE_NAMES = [
    "layer-rgb8", "layer-rgba8", "layer-grey8", "layer-greya8", "layer-rgb16",
    "layer-rgb-float", "layer-rgba-float-linear", "layer-rgb8-feathered-selection",
    "layer-rgb8-strength", "filter-threshold-rgba8", "filter-posterize-grey16", "filter-unsharp-float",
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
                                  iterations=case["args"]["iterations"], linear=linear, backend="numpy",
                                  strength=None if case["args"].get("auto-strength", True) else case["args"]["strength"],
                                  ).astype(np.float64)
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
    # What happened, in the line the status bar shows (and a message, when F was kept).
    assert result["summary"].startswith(("repaired ", "returned F unchanged")), result
    if not case["args"].get("auto-strength", True):
        assert f"strength {case['args']['strength']:g}" in result["summary"], result
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


def test_bundle_is_made_for_the_python_gimp_runs(bundled_run):
    # Asked, not assumed: the root's GIMP runs #!/usr/bin/env python3 with /usr/bin/python3.
    assert "for CPython 3.13 on linux-x86_64 (/usr/bin/python3)" in bundled_run["install"]
    status = bundled_run["status"]
    assert status.returncode == 0, status.stdout + status.stderr
    assert "GIMP's Python:  CPython 3.13 on linux-x86_64" in status.stdout
    assert "(up to date)" in status.stdout and "numpy" in status.stdout


def test_bundled_batch_run_exits_cleanly(bundled_run):
    assert bundled_run["exit"] == 0, bundled_run["log"][-4000:]
    assert "Traceback" not in bundled_run["log"], bundled_run["log"]
    error = bundled_run["results"]["error-offset-layer"]
    assert error["status"] == "execution-error" and "same size and position" in error["message"]


@pytest.mark.parametrize("name", [n for n in BUNDLED if n in CASE_NAMES])
def test_bundled_plugin_gives_the_pixels_of_recover(bundled_run, name):
    result = check_case(bundled_run, name)
    assert result["runner"] == "in-process", result
    # The bundle's copies, not Debian's /usr/lib/python3/dist-packages/numpy.
    assert result["aarecovery_path"] == f"{bundled_run['site']}/aarecovery", result
    assert result["numpy_path"] == f"{bundled_run['site']}/numpy", result
    assert result["backend"] == "gl", result
