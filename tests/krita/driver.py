"""Run by ``kritarunner -s driver`` (Krita 5's scripting environment) for tests/krita.

Reads ``$AARECOVERY_KRITA_CASES`` (JSON written by the test). For every case it makes a
document of the case's depth, puts the test's pixels (raw bytes in Krita's own channel order)
into paint layers, exports O and F as Krita holds them (for the apply-filter entry, F from the
driver's own run of the same Krita filter on a copy), runs the installed plug-in's
``repair`` (what the menu entry runs after its dialog) and exports the repaired layer. It
writes ``results.json`` next to the cases file; with ``$AARECOVERY_KRITA_SCREENSHOT`` it also
renders the plug-in's dialog into that PNG.

Krita's Python imports the plug-in from the resource folder the test installed it into
(``$AARECOVERY_KRITA_PYKRITA``); ``$AARECOVERY_KRITA_SITE`` (optional) is a site folder to add
first, so that Krita's Python can import aarecovery in process.
"""

import importlib.util
import json
import os
import site
import sys
import traceback


def layer(doc, name, raw=None):
    node = doc.createNode(name, "paintlayer")
    doc.rootNode().addChildNode(node, None)          # on top
    if raw is not None:
        node.setPixelData(raw, 0, 0, doc.width(), doc.height())
    return node


def export(node, doc, path):
    with open(path, "wb") as fh:
        fh.write(bytes(node.pixelData(0, 0, doc.width(), doc.height())))


def reference_filter(krita, doc, node, filter_id, props):
    """The driver's own run of Krita's filter on a copy of `node`, for the expected F."""
    copy = node.duplicate()
    doc.rootNode().addChildNode(copy, None)
    host_filter = krita.filter(filter_id)
    config = host_filter.configuration()
    for key, value in props.items():
        config.setProperty(key, value)
    host_filter.setConfiguration(config)
    host_filter.apply(copy, 0, 0, doc.width(), doc.height())
    doc.waitForDone()
    return copy


def run_case(krita, case, out, repair):
    from krita import Selection
    name, (w, h) = case["name"], case["size"]
    read = lambda suffix: open(os.path.join(out, f"{name}-{suffix}.raw"), "rb").read()  # noqa: E731
    doc = krita.createDocument(w, h, name, case.get("model", "RGBA"), case["depth"], "", 72.0)
    try:
        for default in doc.rootNode().childNodes():        # createDocument's "Background"
            default.remove()
        original = layer(doc, "original", read("in-O"))
        record = {"name": name, "depth": original.colorDepth(), "profile": original.colorProfile(),
                  "numpy_in_krita": importlib.util.find_spec("numpy") is not None,
                  "channels": [c.name() for c in original.channels()]}
        export(original, doc, os.path.join(out, f"{name}-O.raw"))
        if case.get("alone"):
            target = original
        elif case["entry"] == "from-layer":
            target = layer(doc, "filtered", read("in-F"))
            if case.get("offset"):
                target.move(*case["offset"])
        else:
            target = original
            reference = reference_filter(krita, doc, original, case["filter_id"], case["reference_props"])
            export(reference, doc, os.path.join(out, f"{name}-F.raw"))
            reference.remove()
        if case["entry"] == "from-layer" and not case.get("alone"):
            export(target, doc, os.path.join(out, f"{name}-F.raw"))
        if case.get("group"):
            target = doc.createGroupLayer("a group")
            doc.rootNode().addChildNode(target, None)
        if case.get("selection"):
            x, y, sw, sh, feather = case["selection"]
            selection = Selection()
            selection.select(x, y, sw, sh, 255)
            if feather:
                selection.feather(feather)
            doc.setSelection(selection)
            with open(os.path.join(out, f"{name}-mask.raw"), "wb") as fh:
                fh.write(bytes(doc.selection().pixelData(0, 0, w, h)))
        before = {n.uniqueId() for n in doc.rootNode().childNodes()}
        try:
            repaired, outcome = repair.repair(doc, target, case["entry"], case["settings"])
        except repair.PluginError as error:
            record.update(status="error", message=str(error))
        else:
            record.update(status="success", backend=outcome.backend, runner=outcome.runner,
                          summary=outcome.summary, alerts=outcome.alerts, notes=outcome.notes,
                          aarecovery_path=outcome.folders["aarecovery"], depth_after=repaired.colorDepth(),
                          model_after=repaired.colorModel())
            export(repaired, doc, os.path.join(out, f"{name}-R.raw"))
            export(target, doc, os.path.join(out, f"{name}-T.raw"))          # the layer it read
        # What the plug-in added (Krita adds the selection's own mask node by itself).
        record["added_layers"] = [(n.name(), n.visible()) for n in doc.rootNode().childNodes()
                                  if n.uniqueId() not in before and n.type() != "selectionmask"]
        return record
    finally:
        doc.close()


def screenshot(path):
    """Render the apply-filter dialog (offscreen Qt) into `path`."""
    from aarecovery_krita import dialog
    from krita import Krita
    shown = dialog.RepairDialog(dialog.APPLY_FILTER, dialog.remembered(Krita.instance()))
    shown.resize(shown.sizeHint())
    shown.show()
    if not shown.grab().save(path, "PNG"):
        raise RuntimeError(f"could not save {path}")


def __main__(args):
    from krita import Krita
    if os.environ.get("AARECOVERY_KRITA_SITE"):
        site.addsitedir(os.environ["AARECOVERY_KRITA_SITE"])
    sys.path.insert(0, os.environ["AARECOVERY_KRITA_PYKRITA"])
    cases_file = os.environ["AARECOVERY_KRITA_CASES"]
    out = os.path.dirname(cases_file)
    results = []
    try:
        from aarecovery_krita import repair
        with open(cases_file) as fh:
            cases = json.load(fh)
        for case in cases:
            try:
                results.append(run_case(Krita.instance(), case, out, repair))
            except Exception:
                results.append({"name": case["name"], "status": "driver-error", "message": traceback.format_exc()})
        if os.environ.get("AARECOVERY_KRITA_SCREENSHOT"):
            screenshot(os.environ["AARECOVERY_KRITA_SCREENSHOT"])
    except Exception:
        results.append({"name": "driver", "status": "driver-error", "message": traceback.format_exc()})
    with open(os.path.join(out, "results.json"), "w") as fh:
        json.dump(results, fh, indent=1)
