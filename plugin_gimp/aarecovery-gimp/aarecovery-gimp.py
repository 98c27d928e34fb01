#!/usr/bin/env python3
"""GIMP 3 plug-in: Antialiasing Recovery (Yang et al. 2011) through the ``aarecovery`` core.

Two procedures, both under Filters > Enhance:

``plug-in-aarecovery-apply-filter``
    Reads the active layer (O), applies a GIMP filter to a copy of it (F), recovers, and
    writes the result back into the layer as one undo step.
``plug-in-aarecovery-from-layer``
    The user already filtered the active layer (F); another layer (default: the one below)
    holds the original (O).

Pixels are read and written as 32-bit float through GEGL in the image's own tone curve, so an
8- or 16-bit layer is quantised once, on the final write. The result goes through the shadow
buffer, so an active selection limits the change and a feathered one blends.

The core runs in GIMP's Python when ``import aarecovery`` works there: from the bundle that
``aarecovery gimp install --bundle`` puts into ``site-packages`` next to this file (when it was
made for this Python), or from GIMP's own paths (a Linux distribution's package). Otherwise
this same file runs as a worker under a configured Python that has aarecovery:
``python aarecovery-gimp.py --worker O.npy F.npy R.npy PARAMS.json``, the pixels travelling
as ``.npy`` files written without NumPy (GIMP's bundled Python may lack it). The Python is,
in order: the procedure's ``python`` argument, the environment variable ``AARECOVERY_PYTHON``,
or the one ``aarecovery gimp install`` recorded in ``config.json`` next to this file.
"""

import json
import os
import shlex
import struct
import subprocess
import sys
import tempfile
import warnings

PLUGIN = "aarecovery-gimp"
PROC_FILTER = "plug-in-aarecovery-apply-filter"
PROC_LAYER = "plug-in-aarecovery-from-layer"
HERE = os.path.dirname(os.path.abspath(__file__))
CONFIG_FILE = os.path.join(HERE, "config.json")
BUNDLE_DIR = os.path.join(HERE, "site-packages")


def read_config():
    """``config.json`` next to this file as a dict; empty when it is missing or unreadable."""
    try:
        with open(CONFIG_FILE, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}

ORDER_MARK = "order: "
# The recovery's one-line summary travels among the messages too: SUMMARY_MARK when it
# repaired, KEPT_MARK when it returned F unchanged (which the user is told in a message).
SUMMARY_MARK = "summary: "
KEPT_MARK = "kept: "
# How the summary tells a user of the plug-in to force a repair.
FORCE_HINT = "the dialog's Strength with Automatic strength unticked (auto-strength=FALSE, strength=1)"


# ---------------------------------------------------------------------------------------------
# The part shared by both ways of running the core. It needs NumPy and aarecovery, nothing of
# GIMP, so that the worker process can run it too.

def recover_arrays(original, filtered, params):
    """Run ``aarecovery.recover`` on float32 arrays; return ``(result, backend, messages)``.

    ``params`` holds sigma_d, sigma_e, iterations, strength (None: the safe default's),
    backend, linear and clip_filtered (a GIMP filter may overshoot [0, 1] on a float image;
    integer precisions clip it anyway, so the apply-filter entry clips to match). The last
    message is the recovery's summary (SUMMARY_MARK or KEPT_MARK). Raises
    aarecovery.InputError on bad input.
    """
    import numpy as np
    import aarecovery

    params = dict(params)
    if params.pop("clip_filtered", False):
        filtered = np.clip(filtered, 0.0, 1.0)
    with warnings.catch_warnings(record=True) as caught:
        # "auto" falls back to NumPy with a RuntimeWarning; keep it for GIMP's status bar.
        warnings.simplefilter("always")
        engine = aarecovery.Engine(backend=params.pop("backend"))
        result = aarecovery.recover(original, filtered, engine=engine, **params)
    # An order warning (the original layer looks like the filtered one) is marked for a message
    # of its own; the rest (the GL fallback) goes to the status bar.
    messages = [(ORDER_MARK if issubclass(w.category, aarecovery.OrderWarning) else "") + str(w.message)
                for w in caught]
    summary = aarecovery.summarize_recovery(engine.last_plan, original, filtered, result)
    messages.append((KEPT_MARK if summary.plan.keeps_filtered else SUMMARY_MARK) + summary.line(force=FORCE_HINT))
    return np.ascontiguousarray(result, dtype=np.float32), engine.backend, messages


def package_folders():
    """The folders aarecovery and NumPy were imported from; each run reports them back."""
    import numpy
    import aarecovery
    return {"aarecovery": os.path.dirname(os.path.abspath(aarecovery.__file__)),
            "numpy": os.path.dirname(os.path.abspath(numpy.__file__))}


def worker_main(argv):
    """``--worker O.npy F.npy R.npy PARAMS.json``: the out-of-process side; prints one JSON line."""
    import numpy as np
    try:
        import aarecovery
    except ImportError as error:
        print(json.dumps({"error": f"{sys.executable} cannot import aarecovery ({error}); "
                                   "install it there with: pip install aarecovery"}))
        return 0
    o_path, f_path, r_path, p_path = argv
    with open(p_path, encoding="utf-8") as fh:
        params = json.load(fh)
    try:
        result, backend, messages = recover_arrays(np.load(o_path), np.load(f_path), params)
    except aarecovery.InputError as error:
        print(json.dumps({"error": str(error)}))
        return 0
    np.save(r_path, result)
    print(json.dumps({"backend": backend, "messages": messages, "folders": package_folders()}))
    return 0


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "--worker":
    sys.exit(worker_main(sys.argv[2:]))


# ---------------------------------------------------------------------------------------------
# The GIMP side.

def python_platform():
    """This Python's platform in the form the bundle records: sysconfig's, less macOS's version.

    The version is the oldest macOS the Python was built for; wheels for an older one load too.
    """
    import re
    import sysconfig
    return re.sub(r"^macosx-[0-9.]+-", "macosx-", sysconfig.get_platform())


def use_bundle():
    """Put the bundled packages first on ``sys.path`` if they were made for this Python.

    First, so that they shadow a NumPy or moderngl that GIMP's Python has from the system
    (Debian's python3-numpy): the bundled core was installed with the bundled ones. Returns a
    sentence saying why the bundle is not used, or None (it is used, or there is none).
    """
    bundle = read_config().get("bundle")
    if not bundle:
        return None
    if not os.path.isdir(BUNDLE_DIR):
        return (f"the bundle folder {BUNDLE_DIR} is missing; run 'aarecovery gimp install "
                "--bundle' again")
    mine = ("%d.%d" % sys.version_info[:2], python_platform())
    made_for = (bundle.get("python"), bundle.get("platform"))
    if sys.implementation.name != "cpython" or made_for != mine:
        return (f"the packages bundled in {BUNDLE_DIR} are for CPython {made_for[0]} on "
                f"{made_for[1]}, but GIMP runs {sys.implementation.name} {mine[0]} on {mine[1]}; "
                "run 'aarecovery gimp install --bundle' again")
    sys.path.insert(0, BUNDLE_DIR)
    return None


BUNDLE_NOTE = use_bundle()

import gi  # noqa: E402  (the worker above must not need gi)

gi.require_version("Gimp", "3.0")
gi.require_version("GimpUi", "3.0")
gi.require_version("Gegl", "0.4")
from gi.repository import Gegl, Gimp, GimpUi, GLib, GObject  # noqa: E402


class PluginError(Exception):
    """A failure with a message for the user; becomes a PDB execution error."""


# Filters the apply-filter entry offers. "pdb" filters are GIMP's own colour tools, called as
# libgimp drawable methods (their GEGL ops take config objects that libgimp cannot build);
# "gegl" filters run as a Gimp.DrawableFilter. The defaults double as documentation of the
# property names; the user edits them in the "properties" string.
FILTERS = {
    "threshold": ("pdb", "threshold", "Threshold", "channel=value low=0.5 high=1.0"),
    "levels": ("pdb", "levels", "Levels",
               "channel=value low-input=0.2 high-input=0.8 clamp-input=false gamma=1.0 "
               "low-output=0.0 high-output=1.0 clamp-output=false"),
    "curves": ("pdb", "curves_spline", "Curves", "channel=value points=0,0,0.4,0.1,0.6,0.9,1,1"),
    "posterize": ("pdb", "posterize", "Posterize", "levels=3"),
    "desaturate": ("pdb", "desaturate", "Desaturate", "mode=luminance"),
    "gradient-map": ("proc", "plug-in-gradmap", "Gradient Map (active gradient)", ""),
    "color-exchange": ("gegl", "gegl:color-exchange", "Color Exchange",
                       "from-color=#000000 to-color=#ff0000 red-threshold=0.3 "
                       "green-threshold=0.3 blue-threshold=0.3"),
    "mono-mixer": ("gegl", "gegl:mono-mixer", "Mono Mixer", "red=0.333 green=0.333 blue=0.333"),
    "unsharp-mask": ("gegl", "gegl:unsharp-mask", "Unsharp Mask", "std-dev=2.0 scale=1.5 threshold=0"),
    "bilateral": ("gegl", "gegl:bilateral-filter", "Bilateral Filter",
                  "blur-radius=4.0 edge-preservation=8.0"),
    "mean-curvature": ("gegl", "gegl:mean-curvature-blur", "Mean Curvature Blur", "iterations=20"),
    "gegl": ("gegl", None, "Other GEGL operation (by name)", ""),
}
BACKENDS = ("auto", "gl", "numpy")
# The recovery parameters as the core declares them in aarecovery.PARAMETERS. GIMP's Python may
# not be able to import the core, so they are repeated here; tests/gimp/test_install.py checks
# that they match. (GIMP argument name, dialog label, kind, minimum, maximum, default, help.)
# A default of None means the safe default chooses: the dialog then has a box ticked for that
# (AUTOMATIC_ARGUMENTS: its argument name, label and help), and the value starts at the maximum.
RECOVERY_ARGUMENTS = (
    ("sigma-d", "Sigma _d", "float", 0.001, 1.0, 0.1,
     "colour-line distance scale: neighbours further than 3 sigma_d from the colour line are "
     "not blend candidates, and a poor fit lowers the confidence; larger accepts noisier "
     "colour lines"),
    ("sigma-e", "Sigma _e", "float", 0.0001, 1.0, 0.01,
     "edge-strength scale: an edge of strength e gets confidence 1 - exp(-(e/sigma_e)^2); "
     "smaller repairs weaker edges"),
    ("iterations", "_Iterations", "int", 0, 64, 3,
     "Jacobi iterations of the recovery solve; 0 returns the filtered image"),
    ("strength", "_Strength", "float", 0.0, 1.0, None,
     "how much to repair, from 0 (F as it is) to 1 (the full repair); overrides the strength the "
     "safe default chooses, and forces a repair where it keeps F"),
)
AUTOMATIC_ARGUMENTS = {
    "strength": ("auto-strength", "_Automatic strength", "the strength the safe default chooses per image"),
}


# ---- pixels ----------------------------------------------------------------------------------

def pixel_format(image, drawable):
    """Babl format name to read and write `drawable` in float, and whether it is linear.

    Perceptual precisions use the sRGB tone curve in GIMP 3, so they are read as non-linear.
    """
    nick = image.get_precision().value_nick        # e.g. "u8-non-linear", "float-linear"
    linear = nick.endswith("-linear") and not nick.endswith("non-linear")
    trc = "" if linear else "'"
    if drawable.is_rgb():
        model = f"R{trc}G{trc}B{trc}"
    elif drawable.is_gray():
        model = f"Y{trc}"
    else:
        raise PluginError(f"layer '{drawable.get_name()}' is indexed; convert the image with "
                          "Image > Mode > RGB (or Grayscale) first")
    channels = len(model.replace("'", ""))
    if drawable.has_alpha():
        model, channels = model + "A", channels + 1
    return f"{model} float", channels, linear


def read_pixels(drawable, fmt, area=None):
    """Float32 bytes in `fmt`, row-major: all of `drawable`, or the part that layer `area` covers.

    A filter may grow the layer it runs on (a blur's halo), so F is read from the copy at the
    position and size of the original layer.
    """
    x = y = 0
    area = area or drawable
    if area is not drawable:
        _, ax, ay = area.get_offsets()
        _, dx, dy = drawable.get_offsets()
        x, y = ax - dx, ay - dy
    rect = Gegl.Rectangle.new(x, y, area.get_width(), area.get_height())
    return bytes(drawable.get_buffer().get(rect, 1.0, fmt, Gegl.AbyssPolicy.CLAMP))


def write_pixels(drawable, fmt, data):
    """Write float32 bytes through the shadow buffer: undoable, and blended by the selection."""
    w, h = drawable.get_width(), drawable.get_height()
    shadow = drawable.get_shadow_buffer()
    shadow.set(Gegl.Rectangle.new(0, 0, w, h), fmt, data)
    shadow.flush()
    drawable.merge_shadow(True)
    drawable.update(0, 0, w, h)


# ---- .npy without NumPy (for the out-of-process path) ---------------------------------------

def write_npy(path, data, shape):
    """Write float32 little-endian bytes as a version 1.0 .npy file."""
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': %r, }" % (tuple(shape),)
    header += " " * ((-(10 + len(header) + 1)) % 64) + "\n"      # data aligned to 64 bytes
    with open(path, "wb") as fh:
        fh.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1"))
        fh.write(data)


def read_npy(path, nbytes):
    """Read the float32 payload of a .npy file written by ``numpy.save``; check its size."""
    with open(path, "rb") as fh:
        magic = fh.read(8)
        if magic[:6] != b"\x93NUMPY":
            raise PluginError(f"{path} is not a .npy file")
        size = struct.unpack("<H" if magic[6] == 1 else "<I", fh.read(2 if magic[6] == 1 else 4))[0]
        header = fh.read(size).decode("latin1")
        if "'<f4'" not in header or "False" not in header:
            raise PluginError(f"the worker wrote an unexpected array ({header.strip()})")
        data = fh.read()
    if len(data) != nbytes:
        raise PluginError(f"the worker returned {len(data)} bytes, expected {nbytes}")
    return data


# ---- running the core ------------------------------------------------------------------------

def configured_python(config):
    """The Python for the out-of-process core, or None when none is configured."""
    python = (config.get_property("python") or "").strip()
    if python:
        return python
    if os.environ.get("AARECOVERY_PYTHON"):
        return os.environ["AARECOVERY_PYTHON"]
    return read_config().get("python") or None


def run_core(o_data, o_shape, f_data, f_shape, params, config):
    """Recover; return ``(bytes, backend, where, messages, folders)``.

    `where` is the runner used; `folders` says where aarecovery and NumPy came from.
    """
    notes = [BUNDLE_NOTE] if BUNDLE_NOTE else []      # the status bar says why it was skipped
    try:
        import numpy as np
        import aarecovery
    except ImportError as error:
        import_error = error
    else:
        original = np.frombuffer(o_data, dtype=np.float32).reshape(o_shape)
        filtered = np.frombuffer(f_data, dtype=np.float32).reshape(f_shape)
        try:
            result, backend, messages = recover_arrays(original, filtered, params)
        except aarecovery.InputError as error:
            raise PluginError(str(error)) from None
        return result.tobytes(), backend, "in-process", notes + messages, package_folders()

    python = configured_python(config)
    if BUNDLE_DIR in sys.path:              # made for this Python, and yet it does not import
        notes.append(f"the packages bundled in {BUNDLE_DIR} do not import in GIMP's Python "
                     f"({import_error}); run 'aarecovery gimp install --bundle' again")
    if not python:
        if BUNDLE_DIR in sys.path:
            raise PluginError(notes[-1])
        raise PluginError(
            f"GIMP's Python ({sys.executable}, {sys.version.split()[0]}) cannot import "
            f"aarecovery ({import_error}) and no Python with aarecovery is configured"
            + (f" ({BUNDLE_NOTE})" if BUNDLE_NOTE else "") + ". Either run 'aarecovery gimp "
            "install --bundle', or run 'aarecovery gimp install' from a Python that has "
            "aarecovery, set the environment variable AARECOVERY_PYTHON, or enter that Python "
            "in the plug-in's 'Python with aarecovery' field.")
    with tempfile.TemporaryDirectory(prefix="aarecovery-gimp-") as tmp:
        paths = [os.path.join(tmp, n) for n in ("o.npy", "f.npy", "r.npy", "params.json")]
        write_npy(paths[0], o_data, o_shape)
        write_npy(paths[1], f_data, f_shape)
        with open(paths[3], "w", encoding="utf-8") as fh:
            json.dump(params, fh)
        try:
            proc = subprocess.run(
                [python, os.path.abspath(__file__), "--worker", *paths],
                capture_output=True, text=True, timeout=3600,
                creationflags=getattr(subprocess, "CREATE_NO_WINDOW", 0))   # no console on Windows
        except OSError as error:
            raise PluginError(f"cannot run the configured Python '{python}': {error}; fix the "
                              "path ('aarecovery gimp status' shows it)") from None
        lines = proc.stdout.strip().splitlines()
        try:
            reply = json.loads(lines[-1])
        except (IndexError, ValueError):
            tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
            raise PluginError(f"the core under '{python}' failed (exit {proc.returncode}): "
                              f"{tail}") from None
        if "error" in reply:
            raise PluginError(reply["error"])
        nbytes = f_shape[0] * f_shape[1] * f_shape[2] * 4
        return (read_npy(paths[2], nbytes), reply["backend"], "subprocess",
                notes + reply["messages"], reply["folders"])


# ---- filters ---------------------------------------------------------------------------------

def parse_properties(text):
    """``"a=1 b=x"`` -> ``{"a": "1", "b": "x"}``; values may be quoted."""
    props = {}
    for item in shlex.split(text or ""):
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise PluginError(f"filter property '{item}' is not of the form name=value")
        props[key.strip()] = value.strip()
    return props


def to_bool(key, value):
    low = value.lower()
    if low in ("1", "true", "yes", "on"):
        return True
    if low in ("0", "false", "no", "off"):
        return False
    raise PluginError(f"filter property {key}={value}: use true or false")


def to_number(key, value, kind):
    try:
        return kind(value)
    except ValueError:
        raise PluginError(f"filter property {key}={value} is not a number") from None


def to_enum(key, value, enum_type):
    """An enum value from its nick ("luminance") or name ("LUMINANCE")."""
    member = getattr(enum_type, value.upper().replace("-", "_"), None)
    if member is None:
        names = sorted(k.lower().replace("_", "-") for k in dir(enum_type)
                       if k.isupper() and isinstance(getattr(enum_type, k), enum_type))
        raise PluginError(f"filter property {key}={value}: choose one of {', '.join(names)}")
    return member


def pdb_filter(layer, method, props):
    """Run one of GIMP's colour tools (a libgimp Drawable method) on `layer`."""
    def pop(key, convert, default):
        return convert(key, props.pop(key)) if key in props else default

    channel = pop("channel", lambda k, v: to_enum(k, v, Gimp.HistogramChannel),
                  Gimp.HistogramChannel.VALUE)
    if method == "threshold":
        args = (channel, pop("low", lambda k, v: to_number(k, v, float), 0.5),
                pop("high", lambda k, v: to_number(k, v, float), 1.0))
    elif method == "levels":
        num = lambda k, v: to_number(k, v, float)  # noqa: E731
        args = (channel, pop("low-input", num, 0.0), pop("high-input", num, 1.0),
                pop("clamp-input", to_bool, False), pop("gamma", num, 1.0),
                pop("low-output", num, 0.0), pop("high-output", num, 1.0),
                pop("clamp-output", to_bool, False))
    elif method == "curves_spline":
        points = [to_number("points", p, float) for p in props.pop("points", "0,0,1,1").split(",")]
        if len(points) < 4 or len(points) % 2:
            raise PluginError("filter property points= needs x,y pairs, e.g. 0,0,0.5,0.3,1,1")
        args = (channel, points)
    elif method == "posterize":
        args = (pop("levels", lambda k, v: to_number(k, v, int), 3),)
    elif method == "desaturate":
        args = (pop("mode", lambda k, v: to_enum(k, v, Gimp.DesaturateMode),
                    Gimp.DesaturateMode.LUMINANCE),)
    else:
        raise PluginError(f"unknown colour tool {method}")
    if props:
        tool = method.split("_")[0]
        known = next(parse_properties(spec[3]) for spec in FILTERS.values() if spec[1] == method)
        raise PluginError(f"{tool} has no propert{'y' if len(props) == 1 else 'ies'} "
                          f"{', '.join(sorted(props))}; it takes: {', '.join(known)}")
    if not getattr(layer, method)(*args):
        raise PluginError(f"GIMP's {method.split('_')[0]} failed: {Gimp.get_pdb().get_last_error()}")


def gegl_filter(layer, operation, props):
    """Apply the GEGL `operation` with `props` (strings converted by property type)."""
    try:
        drawable_filter = Gimp.DrawableFilter.new(layer, operation, None)
    except (GLib.Error, TypeError) as error:            # unknown name: "constructor returned NULL"
        drawable_filter, message = None, getattr(error, "message", None) or Gimp.get_pdb().get_last_error()
    else:
        message = Gimp.get_pdb().get_last_error()
    if drawable_filter is None:
        raise PluginError(f"GIMP cannot apply the GEGL operation '{operation}' ({message}); "
                          "check the name, e.g. gegl:median-blur")
    settings = drawable_filter.get_config()
    for key, text in props.items():
        pspec = settings.find_property(key)
        if pspec is None:
            names = sorted(p.name for p in settings.list_properties() if not p.name.startswith("gimp-"))
            raise PluginError(f"{operation} has no property '{key}'; it has: {', '.join(names)}")
        vtype = pspec.value_type
        if vtype == GObject.TYPE_BOOLEAN:
            value = to_bool(key, text)
        elif vtype in (GObject.TYPE_INT, GObject.TYPE_UINT, GObject.TYPE_INT64):
            value = to_number(key, text, int)
        elif vtype in (GObject.TYPE_DOUBLE, GObject.TYPE_FLOAT):
            value = to_number(key, text, float)
        elif vtype == GObject.TYPE_STRING:
            value = text
        elif vtype.is_a(Gegl.Color):
            value = Gegl.Color.new(text)
        elif vtype.is_a(GObject.TYPE_ENUM):
            value = _gegl_enum(key, text, pspec)
        else:
            raise PluginError(f"{operation} property '{key}' has type {vtype.name}, which cannot "
                              "be set from text")
        settings.set_property(key, value)
    drawable_filter.update()
    layer.merge_filter(drawable_filter)


def _gegl_enum(key, text, pspec):
    enum_class = pspec.enum_class
    for number, member in enum_class.__enum_values__.items():
        if text in (member.value_nick, member.value_name, str(number)):
            return number
    nicks = ", ".join(m.value_nick for m in enum_class.__enum_values__.values())
    raise PluginError(f"filter property {key}={text}: choose one of {nicks}")


def apply_filter_to(image, layer, config):
    """Run the chosen filter on `layer` (a temporary copy) through GIMP."""
    name = config.get_property("filter")
    kind, target, label, default = FILTERS[name]
    text = config.get_property("properties")
    props = parse_properties(default if text is None or not text.strip() else text)
    if kind == "pdb":
        pdb_filter(layer, target, props)
    elif kind == "proc":
        procedure = Gimp.get_pdb().lookup_procedure(target)
        if procedure is None:
            raise PluginError(f"GIMP has no procedure {target} for the {label} filter")
        settings = procedure.create_config()
        settings.set_property("run-mode", Gimp.RunMode.NONINTERACTIVE)
        settings.set_property("image", image)
        settings.set_core_object_array("drawables", [layer])
        result = procedure.run(settings)
        if result.index(0) != Gimp.PDBStatusType.SUCCESS:
            raise PluginError(f"{label} failed: {result.index(1) if result.length() > 1 else ''}")
    else:
        operation = target or (config.get_property("operation") or "").strip()
        if not operation:
            raise PluginError("enter the GEGL operation's name, e.g. gegl:median-blur")
        gegl_filter(layer, operation, props)


# ---- the two entries -------------------------------------------------------------------------

def single_layer(image, drawables):
    if len(drawables) != 1 or not isinstance(drawables[0], Gimp.Layer):
        raise PluginError("select exactly one layer (not a channel, mask or several layers)")
    layer = drawables[0]
    if layer.is_group():
        raise PluginError(f"'{layer.get_name()}' is a layer group; select a pixel layer")
    return layer


def layer_below(image, layer):
    parent = layer.get_parent()
    siblings = parent.get_children() if parent is not None else image.get_layers()
    ids = [s.get_id() for s in siblings]
    index = ids.index(layer.get_id())
    if index + 1 >= len(siblings):
        raise PluginError(f"there is no layer below '{layer.get_name()}'; choose the layer "
                          "holding the original in the dialog (scripts: 'original-layer')")
    return siblings[index + 1]


def check_aligned(original, filtered):
    """Layers must cover the same pixels: say which way they differ and how to fix it."""
    _, ox, oy = original.get_offsets()
    _, fx, fy = filtered.get_offsets()
    ow, oh, fw, fh = original.get_width(), original.get_height(), filtered.get_width(), filtered.get_height()
    if (ox, oy, ow, oh) != (fx, fy, fw, fh):
        raise PluginError(
            f"the original layer '{original.get_name()}' is {ow}x{oh} at ({ox}, {oy}) but the "
            f"filtered layer '{filtered.get_name()}' is {fw}x{fh} at ({fx}, {fy}); recovery "
            "compares the pixels at the same place, so give both layers the same size and "
            "position (e.g. Layer > Layer to Image Size on both) and run it again")


def core_params(config, linear, clip_filtered):
    recovery = {name.replace("-", "_"): None if name in AUTOMATIC_ARGUMENTS and config.get_property(
                    AUTOMATIC_ARGUMENTS[name][0]) else config.get_property(name)
                for name, *_ in RECOVERY_ARGUMENTS}
    return {**recovery, "backend": config.get_property("backend"), "linear": linear,
            "clip_filtered": clip_filtered}


def grab(image, procedure_name, layer, config):
    """Read O and F for `layer`; return ``(fmt, o, o_shape, f, f_shape, params)``."""
    fmt, channels, linear = pixel_format(image, layer)
    h, w = layer.get_height(), layer.get_width()
    if procedure_name == PROC_LAYER:
        source = config.get_property("original-layer") or layer_below(image, layer)
        if source.get_id() == layer.get_id():
            raise PluginError("the original layer is the active layer itself; choose the "
                              "unfiltered copy")
        check_aligned(source, layer)
        o_fmt, o_channels, _ = pixel_format(image, source)
        return (fmt, read_pixels(source, o_fmt), (h, w, o_channels),
                read_pixels(layer, fmt), (h, w, channels), core_params(config, linear, False))
    # The filter runs on a temporary copy with the selection lifted: F must be the filter's
    # full result; the selection applies once, when the recovered pixels are merged.
    original = read_pixels(layer, fmt)
    saved = None if Gimp.Selection.is_empty(image) else Gimp.Selection.save(image)
    copy = layer.copy()
    image.insert_layer(copy, layer.get_parent(), image.get_item_position(layer))
    try:
        if saved is not None:
            Gimp.Selection.none(image)
        apply_filter_to(image, copy, config)
        filtered = read_pixels(copy, fmt, area=layer)
    finally:
        image.remove_layer(copy)
        if saved is not None:
            image.select_item(Gimp.ChannelOps.REPLACE, saved)
            image.remove_channel(saved)
    return (fmt, original, (h, w, channels), filtered, (h, w, channels),
            core_params(config, linear, True))


def recover_layer(procedure_name, image, layer, config):
    """Do the whole job on `layer` inside one undo group; return (backend, where, folders, summary)."""
    Gimp.progress_init("Antialiasing recovery")
    image.undo_group_start()
    try:
        fmt, o, o_shape, f, f_shape, params = grab(image, procedure_name, layer, config)
        data, backend, where, messages, folders = run_core(o, o_shape, f, f_shape, params, config)
        write_pixels(layer, fmt, data)
        summary = ""
        for message in messages:
            # A swapped pair and an unchanged result need the user: a message each.
            for mark in (ORDER_MARK, KEPT_MARK):
                if message.startswith(mark):
                    Gimp.message(f"aarecovery: {message[len(mark):]}")
            for mark in (SUMMARY_MARK, KEPT_MARK):
                if message.startswith(mark):
                    summary = message[len(mark):]
        notes = [message for message in messages
                 if not message.startswith((ORDER_MARK, SUMMARY_MARK, KEPT_MARK))]
        # The repair's summary (or the GL fallback note) goes to the status bar, not a dialog.
        if notes or summary:
            Gimp.progress_set_text(f"aarecovery: {(notes or [summary])[-1]}")
    finally:
        image.undo_group_end()
        Gimp.progress_end()
    return backend, where, folders, summary


# ---- dialog ----------------------------------------------------------------------------------

def show_dialog(procedure, config, image, layer):
    """The ProcedureDialog with an on-canvas preview toggle; returns True on OK."""
    GimpUi.init(PLUGIN)
    dialog = GimpUi.ProcedureDialog.new(procedure, config, procedure.get_menu_label())
    names = [part for name, *_ in RECOVERY_ARGUMENTS
             for part in ([AUTOMATIC_ARGUMENTS[name][0]] if name in AUTOMATIC_ARGUMENTS else []) + [name]]
    names += ["backend", "python"]
    if procedure.get_name() == PROC_FILTER:
        names = ["filter", "operation", "properties"] + names

        def on_filter(*_):
            config.set_property("properties", FILTERS[config.get_property("filter")][3])
        if not (config.get_property("properties") or "").strip():
            on_filter()                                   # show the property names to edit
        config.connect("notify::filter", on_filter)
    else:
        names = ["original-layer"] + names
    dialog.fill(names)

    # Preview: the result goes into a temporary layer above the active one, like GIMP's own
    # on-canvas filter previews; undo is frozen so the preview leaves no undo steps.
    from gi.repository import Gtk
    toggle = Gtk.CheckButton.new_with_mnemonic("_Preview")
    dialog.get_content_area().pack_end(toggle, False, False, 6)
    toggle.show()
    state = {"layer": None, "source": None}

    def clear():
        if state["layer"] is not None:
            image.remove_layer(state["layer"])
            state["layer"] = None
            Gimp.displays_flush()

    def refresh(*_):
        image.undo_freeze()
        try:
            clear()
            if not toggle.get_active():
                return
            preview = layer.copy()
            image.insert_layer(preview, layer.get_parent(), image.get_item_position(layer))
            state["layer"] = preview
            if procedure.get_name() == PROC_LAYER and config.get_property("original-layer") is None:
                config.set_property("original-layer", layer_below(image, layer))
            try:
                fmt, o, o_shape, f, f_shape, params = grab(image, procedure.get_name(), layer, config)
                data = run_core(o, o_shape, f, f_shape, params, config)[0]
            except PluginError as error:
                Gimp.message(str(error))
                return
            shadow = preview.get_shadow_buffer()
            shadow.set(Gegl.Rectangle.new(0, 0, preview.get_width(), preview.get_height()), fmt, data)
            shadow.flush()
            preview.merge_shadow(False)
            preview.update(0, 0, preview.get_width(), preview.get_height())
            Gimp.displays_flush()
        finally:
            image.undo_thaw()

    toggle.connect("toggled", refresh)
    config.connect("notify", lambda *_: toggle.get_active() and refresh())
    ok = dialog.run()
    image.undo_freeze()
    clear()
    image.undo_thaw()
    dialog.destroy()
    return ok


# ---- registration ----------------------------------------------------------------------------

def run(procedure, run_mode, image, drawables, config, data):
    try:
        layer = single_layer(image, drawables)
        if run_mode == Gimp.RunMode.INTERACTIVE:
            if not show_dialog(procedure, config, image, layer):
                return procedure.new_return_values(Gimp.PDBStatusType.CANCEL, GLib.Error())
        backend, where, folders, summary = recover_layer(procedure.get_name(), image, layer, config)
    except PluginError as error:
        return procedure.new_return_values(Gimp.PDBStatusType.EXECUTION_ERROR, GLib.Error(str(error)))
    except Exception as error:            # a bug: still a message, never a silent failure
        import traceback
        traceback.print_exc()
        return procedure.new_return_values(
            Gimp.PDBStatusType.EXECUTION_ERROR,
            GLib.Error(f"aarecovery plug-in failed unexpectedly: {type(error).__name__}: {error}"))
    Gimp.displays_flush()
    values = procedure.new_return_values(Gimp.PDBStatusType.SUCCESS, GLib.Error())
    for index, value in ((1, backend), (2, where), (3, folders["aarecovery"]),
                         (4, folders["numpy"]), (5, summary)):
        values.remove(index)
        values.insert(index, GObject.Value(GObject.TYPE_STRING, value))
    return values


class AntialiasingRecovery(Gimp.PlugIn):
    """Registers the two procedures."""

    def do_set_i18n(self, name):
        return False

    def do_query_procedures(self):
        return [PROC_FILTER, PROC_LAYER]

    def do_create_procedure(self, name):
        procedure = Gimp.ImageProcedure.new(self, name, Gimp.PDBProcType.PLUGIN, run, None)
        procedure.set_image_types("RGB*, GRAY*")
        procedure.set_sensitivity_mask(Gimp.ProcedureSensitivityMask.DRAWABLE)
        procedure.set_attribution("aarecovery developers", "aarecovery developers", "2025")
        flags = GObject.ParamFlags.READWRITE
        if name == PROC_FILTER:
            procedure.set_menu_label("Antialiasing Recovery (apply filter)...")
            procedure.set_documentation(
                "Apply a filter and repair the antialiased edges it damaged",
                "Runs a GIMP filter on the active layer, then restores its antialiased edges "
                "from the layer as it was before (Yang et al., Antialiasing Recovery, 2011). "
                "One undo step; an active selection limits the change.", name)
            choice = Gimp.Choice.new()
            for index, (key, spec) in enumerate(FILTERS.items()):
                choice.add(key, index, spec[2], spec[3])
            procedure.add_choice_argument("filter", "_Filter", "The filter to apply", choice,
                                          "threshold", flags)
            procedure.add_string_argument("operation", "_GEGL operation",
                                          "GEGL operation name when filter is 'gegl', e.g. "
                                          "gegl:median-blur", "", flags)
            procedure.add_string_argument("properties", "Filter _properties",
                                          "name=value pairs for the filter; empty: its defaults",
                                          "", flags)
        else:
            procedure.set_menu_label("Antialiasing Recovery (from layer)...")
            procedure.set_documentation(
                "Repair the antialiased edges of a filtered layer from its original",
                "The active layer holds a filtered copy; 'original-layer' (default: the layer "
                "below) holds it before the filter. Restores the antialiased edges (Yang et al., "
                "Antialiasing Recovery, 2011) in one undo step; a selection limits the change.",
                name)
            procedure.add_layer_argument("original-layer", "_Original layer",
                                         "The layer before the filter (none: the layer below)",
                                         True, flags)
        procedure.add_menu_path("<Image>/Filters/Enhance")        # after the label: GIMP needs it
        for name, label, kind, minimum, maximum, default, blurb in RECOVERY_ARGUMENTS:
            if default is None:
                automatic, automatic_label, automatic_blurb = AUTOMATIC_ARGUMENTS[name]
                procedure.add_boolean_argument(automatic, automatic_label,
                                               f"Ticked: {automatic_blurb}; unticked: the value below", True, flags)
                default = maximum
            add = procedure.add_int_argument if kind == "int" else procedure.add_double_argument
            add(name, label, blurb[0].upper() + blurb[1:], minimum, maximum, default, flags)
        backends = Gimp.Choice.new()
        for index, key in enumerate(BACKENDS):
            backends.add(key, index, key, "")
        procedure.add_choice_argument("backend", "_Backend", "auto: OpenGL, else NumPy",
                                      backends, "auto", flags)
        procedure.add_string_argument("python", "P_ython with aarecovery",
                                      "Used only when GIMP's Python cannot import aarecovery; "
                                      "empty: $AARECOVERY_PYTHON or the one recorded at install",
                                      "", flags)
        procedure.add_string_return_value("backend", "Backend", "gl or numpy", "", flags)
        procedure.add_string_return_value("runner", "Runner", "in-process or subprocess", "", flags)
        procedure.add_string_return_value("aarecovery-path", "aarecovery path",
                                          "The folder the core was imported from", "", flags)
        procedure.add_string_return_value("numpy-path", "NumPy path",
                                          "The folder NumPy was imported from", "", flags)
        procedure.add_string_return_value("summary", "Summary",
                                          "What the recovery did, in one line", "", flags)
        return procedure


Gimp.main(AntialiasingRecovery.__gtype__, sys.argv)
