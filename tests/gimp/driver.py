"""Batch driver, run by ``gimp-console-3.0 --batch-interpreter=python-fu-eval`` in the sandbox.

It reads ``$AARECOVERY_CASES`` (JSON written by the test), and for every case loads the
images, sets precision and selection, exports the inputs as GIMP holds them, calls one of the
plug-in's procedures non-interactively, and exports the result. It writes ``results.json``
next to the cases file.

An exception inside a plug-in does not fail a batch run (GIMP returns EXECUTION_ERROR with no
message and exits 0), so the driver checks every returned status against the case's
expectation and raises at the end if one differs: gimp-console then exits non-zero.

Runs with Gimp, GObject, GLib, Gio and sys already imported by python-fu-eval.
"""

import json
import os

import gi

gi.require_version("Gegl", "0.4")
gi.require_version("Babl", "0.1")
from gi.repository import Babl, Gegl, Gimp, Gio  # noqa: E402,F811

import numpy as np  # noqa: E402

PROCS = {"apply-filter": "plug-in-aarecovery-apply-filter",
         "from-layer": "plug-in-aarecovery-from-layer"}


def load_layer(image, path):
    layer = Gimp.file_load_layer(Gimp.RunMode.NONINTERACTIVE, image, Gio.File.new_for_path(path))
    image.insert_layer(layer, None, 0)
    return layer


def export_layer(image, layer, path):
    """Export `layer` alone: a one-layer image of the same precision, so the exporter neither
    merges other layers, nor writes them as extra TIFF pages, nor adds an alpha channel."""
    single = Gimp.Image.new_with_precision(layer.get_width(), layer.get_height(),
                                           image.get_base_type(), image.get_precision())
    try:
        copy = Gimp.Layer.new_from_drawable(layer, single)
        single.insert_layer(copy, None, 0)
        copy.set_offsets(0, 0)
        if not Gimp.file_save(Gimp.RunMode.NONINTERACTIVE, single, Gio.File.new_for_path(path), None):
            raise RuntimeError(f"exporting {path} failed: {Gimp.get_pdb().get_last_error()}")
    finally:
        single.delete()


def reference_filter(image, layer, spec):
    """The driver's own way of running the filter the plug-in runs, for the expected F."""
    kind = spec["kind"]
    if kind == "threshold":
        ok = layer.threshold(Gimp.HistogramChannel.VALUE, spec["low"], spec["high"])
    elif kind == "method":
        # A libgimp Drawable method; "VALUE"-style strings name HistogramChannel/DesaturateMode.
        enums = (Gimp.HistogramChannel, Gimp.DesaturateMode)
        args = [next((getattr(e, a) for e in enums if isinstance(a, str) and hasattr(e, a)), a)
                for a in spec["args"]]
        ok = getattr(layer, spec["method"])(*args)
    elif kind == "proc":
        procedure = Gimp.get_pdb().lookup_procedure(spec["procedure"])
        config = procedure.create_config()
        config.set_property("run-mode", Gimp.RunMode.NONINTERACTIVE)
        config.set_property("image", image)
        config.set_core_object_array("drawables", [layer])
        ok = procedure.run(config).index(0) == Gimp.PDBStatusType.SUCCESS
    elif kind == "gegl":
        drawable_filter = Gimp.DrawableFilter.new(layer, spec["operation"], None)
        settings = drawable_filter.get_config()
        for key, value in spec.get("set", {}).items():
            if key.endswith("-color"):
                value = Gegl.Color.new(value)
            settings.set_property(key, value)
        drawable_filter.update()
        layer.merge_filter(drawable_filter)
        ok = True
    else:
        raise ValueError(f"unknown reference filter {kind}")
    if not ok:
        raise RuntimeError(f"reference filter {spec} failed")


def run_case(case, out):
    name = case["name"]
    image = Gimp.file_load(Gimp.RunMode.NONINTERACTIVE, Gio.File.new_for_path(case["original"]))
    try:
        original = image.get_layers()[0]
        original.set_name("original")
        ext = case["ext"]
        if case["entry"] == "from-layer":
            target = load_layer(image, case["filtered"])          # on top: the original is below
            target.set_name("filtered")
            if case.get("offset"):
                target.set_offsets(*case["offset"])
        else:
            target = original
        if case.get("precision"):
            image.convert_precision(getattr(Gimp.Precision, case["precision"]))
        record = {"name": name, "precision": image.get_precision().value_nick,
                  "format": Babl.format_get_encoding(target.get_format())}
        export_layer(image, original, f"{out}/{name}-O.{ext}")
        if case["entry"] == "apply-filter":
            reference = original.copy()
            image.insert_layer(reference, None, 0)
            reference_filter(image, reference, case["reference"])
            # A blur may grow the layer; keep the original's area, as the plug-in reads it.
            _, ox, oy = original.get_offsets()
            _, rx, ry = reference.get_offsets()
            reference.resize(original.get_width(), original.get_height(), rx - ox, ry - oy)
            export_layer(image, reference, f"{out}/{name}-F.{ext}")
            image.remove_layer(reference)
        else:
            export_layer(image, target, f"{out}/{name}-F.{ext}")
        if case.get("selection"):
            x, y, w, h, feather = case["selection"]
            image.select_ellipse(Gimp.ChannelOps.REPLACE, x, y, w, h)
            if feather:
                Gimp.Selection.feather(image, feather)
            mask = image.get_selection()
            rect = Gegl.Rectangle.new(0, 0, image.get_width(), image.get_height())
            raw = mask.get_buffer().get(rect, 1.0, "Y float", Gegl.AbyssPolicy.CLAMP)
            np.save(f"{out}/{name}-mask.npy",
                    np.frombuffer(raw, np.float32).reshape(image.get_height(), image.get_width()))

        procedure = Gimp.get_pdb().lookup_procedure(PROCS[case["entry"]])
        if procedure is None:
            raise RuntimeError(f"{PROCS[case['entry']]} is not registered: is the plug-in "
                               "installed and executable?")
        config = procedure.create_config()
        config.set_property("run-mode", Gimp.RunMode.NONINTERACTIVE)
        config.set_property("image", image)
        config.set_core_object_array("drawables", [target])
        for key, value in case.get("args", {}).items():
            config.set_property(key, value)
        if case.get("original_arg"):
            config.set_property("original-layer", original)
        result = procedure.run(config)
        status = result.index(0)
        record["status"] = status.value_nick
        if status == Gimp.PDBStatusType.SUCCESS:
            record["backend"], record["runner"] = result.index(1), result.index(2)
            record["aarecovery_path"], record["numpy_path"] = result.index(3), result.index(4)
            record["summary"] = result.index(5)
            export_layer(image, target, f"{out}/{name}-R.{ext}")
        else:
            record["message"] = result.index(1) if result.length() > 1 else None
        record["layers"] = len(image.get_layers())
        return record
    finally:
        image.delete()


def main():
    cases_file = os.environ["AARECOVERY_CASES"]
    out = os.path.dirname(cases_file)
    with open(cases_file) as fh:
        cases = json.load(fh)
    results, wrong = [], []
    for case in cases:
        try:
            record = run_case(case, out)
        except Exception as error:                 # keep going; report every case
            record = {"name": case["name"], "status": "driver-error",
                      "message": f"{type(error).__name__}: {error}"}
        results.append(record)
        if record["status"] != case["expect"]:
            wrong.append(f"{case['name']}: expected {case['expect']}, got {record['status']} "
                         f"({record.get('message')})")
    with open(os.path.join(out, "results.json"), "w") as fh:
        json.dump(results, fh, indent=1)
    if wrong:
        raise RuntimeError("plug-in calls ended other than expected:\n" + "\n".join(wrong))


main()
