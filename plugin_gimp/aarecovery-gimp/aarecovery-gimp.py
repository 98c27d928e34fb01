#!/usr/bin/env python3
"""GIMP 3 plug-in: Antialiasing Recovery (Yang et al. 2011) through the ``aarecovery`` core.

Two procedures under Filters > Enhance: apply a GIMP filter to the active layer and recover
(``plug-in-aarecovery-apply-filter``), or repair a filtered layer from another, by default the
one below (``plug-in-aarecovery-from-layer``). This file holds pixels, dialog and registration;
GIMP's filters run in ``gimp_filters.py``, and the host-neutral rest (running the core here or
in a worker process, the parameters, the filter catalogue) is ``aarecovery_bridge`` beside it,
shared with the Krita plug-in. Pixels travel as float32 in the image's own tone curve and go
back through the shadow buffer: one undo step, limited and blended by the selection.
"""

import os
import sys

AARECOVERY_VERSION = "0.1.0"          # aarecovery_bridge must be the same release
PLUGIN = "aarecovery-gimp"
PROC_FILTER = "plug-in-aarecovery-apply-filter"
PROC_LAYER = "plug-in-aarecovery-from-layer"
HERE = os.path.dirname(os.path.abspath(__file__))   # first on sys.path: aarecovery_bridge is here

from aarecovery_bridge import PluginError, check_version  # noqa: E402
from aarecovery_bridge import filters, parameters, worker  # noqa: E402

if __name__ == "__main__" and sys.argv[1:2] == ["--worker"]:     # O.npy F.npy R.npy PARAMS.json
    sys.exit(worker.worker_main(sys.argv[2:]))

HOST = worker.Host("GIMP", "aarecovery gimp", HERE, "the plug-in's 'Python with aarecovery' field",
                   "the dialog's Strength with Automatic strength unticked (auto-strength=FALSE, strength=1)")
BUNDLE_NOTE = worker.use_bundle(HOST)

import gi  # noqa: E402

gi.require_version("Gimp", "3.0")
gi.require_version("GimpUi", "3.0")
gi.require_version("Gegl", "0.4")
from gi.repository import Gegl, Gimp, GimpUi, GLib, GObject  # noqa: E402

from gimp_filters import filtered_copy  # noqa: E402

# ---- pixels ----------------------------------------------------------------------------------

def pixel_format(image, drawable):
    """Babl float format of `drawable`, its channels, and whether it is linear (perceptual
    precisions use the sRGB tone curve in GIMP 3, so they are read as non-linear)."""
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
    channels = len(model.replace("'", "")) + drawable.has_alpha()
    return f"{model}{'A' if drawable.has_alpha() else ''} float", channels, linear


def read_pixels(drawable, fmt, area=None):
    """Float32 bytes of `drawable`, or of the part that layer `area` covers (a filter may grow
    the layer it runs on, a blur's halo, so F is read at the original layer's place)."""
    x = y = 0
    area = area or drawable
    if area is not drawable:
        x, y = area.get_offsets()[1] - drawable.get_offsets()[1], area.get_offsets()[2] - drawable.get_offsets()[2]
    rect = Gegl.Rectangle.new(x, y, area.get_width(), area.get_height())
    return bytes(drawable.get_buffer().get(rect, 1.0, fmt, Gegl.AbyssPolicy.CLAMP))


def write_pixels(drawable, fmt, data, undo=True):
    """Write float32 bytes through the shadow buffer: blended by the selection."""
    w, h = drawable.get_width(), drawable.get_height()
    shadow = drawable.get_shadow_buffer()
    shadow.set(Gegl.Rectangle.new(0, 0, w, h), fmt, data)
    shadow.flush()
    drawable.merge_shadow(undo)
    drawable.update(0, 0, w, h)


# ---- the two entries -------------------------------------------------------------------------

def single_layer(drawables):
    if len(drawables) != 1 or not isinstance(drawables[0], Gimp.Layer):
        raise PluginError("select exactly one layer (not a channel, mask or several layers)")
    if drawables[0].is_group():
        raise PluginError(f"'{drawables[0].get_name()}' is a layer group; select a pixel layer")
    return drawables[0]


def layer_below(image, layer):
    parent = layer.get_parent()
    siblings = parent.get_children() if parent is not None else image.get_layers()
    index = [s.get_id() for s in siblings].index(layer.get_id())
    if index + 1 >= len(siblings):
        raise PluginError(f"there is no layer below '{layer.get_name()}'; choose the layer "
                          "holding the original in the dialog (scripts: 'original-layer')")
    return siblings[index + 1]


def place(layer):
    return (layer.get_name(), *layer.get_offsets()[1:], layer.get_width(), layer.get_height())


def grab(image, procedure_name, layer, config):
    """Read O and F for `layer`; return ``(fmt, (o, shape), (f, shape), params)``."""
    fmt, channels, linear = pixel_format(image, layer)
    shape = (layer.get_height(), layer.get_width(), channels)
    params = parameters.core_params(config.get_property, config.get_property("backend"), linear,
                                    procedure_name == PROC_FILTER)
    if procedure_name == PROC_LAYER:
        source = config.get_property("original-layer") or layer_below(image, layer)
        if source.get_id() == layer.get_id():
            raise PluginError("the original layer is the active layer itself; choose the unfiltered copy")
        misplaced = filters.alignment_error(place(source), place(layer), "e.g. Layer > Layer to Image Size on both")
        if misplaced:
            raise PluginError(misplaced)
        o_fmt, o_channels, _ = pixel_format(image, source)
        return fmt, (read_pixels(source, o_fmt), shape[:2] + (o_channels,)), (read_pixels(layer, fmt), shape), params
    filtered = filtered_copy(image, layer, config, lambda copy: read_pixels(copy, fmt, area=layer))
    return fmt, (read_pixels(layer, fmt), shape), (filtered, shape), params


def recover(image, procedure_name, layer, config):
    """Read O and F, run the core; return ``(fmt, worker.Outcome)``."""
    fmt, original, filtered, params = grab(image, procedure_name, layer, config)
    return fmt, worker.run_core(HOST, original, filtered, params, config.get_property("python"), BUNDLE_NOTE)


def recover_layer(procedure_name, image, layer, config):
    """Do the whole job on `layer` inside one undo group; return the outcome."""
    Gimp.progress_init("Antialiasing recovery")
    image.undo_group_start()
    try:
        fmt, outcome = recover(image, procedure_name, layer, config)
        write_pixels(layer, fmt, outcome.data)
        for alert in outcome.alerts:
            Gimp.message(f"aarecovery: {alert}")
        # The summary (or the GL fallback note) goes to the status bar, not a dialog.
        if outcome.notes or outcome.summary:
            Gimp.progress_set_text(f"aarecovery: {(outcome.notes or [outcome.summary])[-1]}")
    finally:
        image.undo_group_end()
        Gimp.progress_end()
    return outcome


# ---- dialog ----------------------------------------------------------------------------------

def show_dialog(procedure, config, image, layer):
    """The ProcedureDialog with an on-canvas preview toggle; returns True on OK."""
    GimpUi.init(PLUGIN)
    dialog = GimpUi.ProcedureDialog.new(procedure, config, procedure.get_menu_label())
    names = parameters.dialog_order() + ["backend", "python"]
    if procedure.get_name() == PROC_FILTER:
        def on_filter(*_):
            config.set_property("properties", filters.GIMP_FILTERS[config.get_property("filter")][3])
        if not (config.get_property("properties") or "").strip():
            on_filter()                                   # show the property names to edit
        config.connect("notify::filter", on_filter)
    dialog.fill((["filter", "operation", "properties"] if procedure.get_name() == PROC_FILTER
                 else ["original-layer"]) + names)

    # Preview: the result goes into a temporary layer above the active one, like GIMP's own
    # on-canvas filter previews; undo is frozen so the preview leaves no undo steps.
    from gi.repository import Gtk
    toggle = Gtk.CheckButton.new_with_mnemonic("_Preview")
    dialog.get_content_area().pack_end(toggle, False, False, 6)
    toggle.show()
    state = {"layer": None}

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
            state["layer"] = preview = layer.copy()
            image.insert_layer(preview, layer.get_parent(), image.get_item_position(layer))
            if procedure.get_name() == PROC_LAYER and config.get_property("original-layer") is None:
                config.set_property("original-layer", layer_below(image, layer))
            try:
                fmt, outcome = recover(image, procedure.get_name(), layer, config)
            except PluginError as error:
                Gimp.message(str(error))
                return
            write_pixels(preview, fmt, outcome.data, undo=False)
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
        check_version(AARECOVERY_VERSION, __file__, "aarecovery gimp install")
        layer = single_layer(drawables)
        if run_mode == Gimp.RunMode.INTERACTIVE and not show_dialog(procedure, config, image, layer):
            return procedure.new_return_values(Gimp.PDBStatusType.CANCEL, GLib.Error())
        outcome = recover_layer(procedure.get_name(), image, layer, config)
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
    for index, value in enumerate((outcome.backend, outcome.runner, outcome.folders["aarecovery"],
                                   outcome.folders["numpy"], outcome.summary), start=1):
        values.remove(index)
        values.insert(index, GObject.Value(GObject.TYPE_STRING, value))
    return values


ENTRIES = {   # name: (menu label, blurb, help)
    PROC_FILTER: ("Antialiasing Recovery (apply filter)...", "Apply a filter and repair the edges it damaged",
                  "Runs a GIMP filter on the active layer, then restores its antialiased edges from the layer as "
                  "it was (Yang et al., 2011). One undo step; a selection limits the change."),
    PROC_LAYER: ("Antialiasing Recovery (from layer)...", "Repair the antialiased edges of a filtered layer",
                 "The active layer holds a filtered copy, 'original-layer' (default: the layer below) the original. "
                 "Restores the antialiased edges (Yang et al., 2011) in one undo step; a selection limits the change."),
}
RETURNS = (("backend", "Backend", "gl or numpy"), ("runner", "Runner", "in-process or subprocess"),
           ("aarecovery-path", "aarecovery path", "The folder the core was imported from"),
           ("numpy-path", "NumPy path", "The folder NumPy was imported from"),
           ("summary", "Summary", "What the recovery did, in one line"))


class AntialiasingRecovery(Gimp.PlugIn):
    """Registers the two procedures."""

    def do_set_i18n(self, name):
        return False

    def do_query_procedures(self):
        return list(ENTRIES)

    def do_create_procedure(self, name):
        procedure = Gimp.ImageProcedure.new(self, name, Gimp.PDBProcType.PLUGIN, run, None)
        procedure.set_image_types("RGB*, GRAY*")
        procedure.set_sensitivity_mask(Gimp.ProcedureSensitivityMask.DRAWABLE)
        procedure.set_attribution("aarecovery developers", "aarecovery developers", "2025")
        label, blurb, help_text = ENTRIES[name]
        procedure.set_menu_label(label)
        procedure.set_documentation(blurb, help_text, name)
        flags = GObject.ParamFlags.READWRITE
        if name == PROC_FILTER:
            choice = Gimp.Choice.new()
            for index, (key, spec) in enumerate(filters.GIMP_FILTERS.items()):
                choice.add(key, index, spec[2], spec[3])
            procedure.add_choice_argument("filter", "_Filter", "The filter to apply", choice, "threshold", flags)
            procedure.add_string_argument("operation", "_GEGL operation", "GEGL operation name when filter "
                                          "is 'gegl', e.g. gegl:median-blur", "", flags)
            procedure.add_string_argument("properties", "Filter _properties",
                                          "name=value pairs for the filter; empty: its defaults", "", flags)
        else:
            procedure.add_layer_argument("original-layer", "_Original layer",
                                         "The layer before the filter (none: the layer below)", True, flags)
        procedure.add_menu_path("<Image>/Filters/Enhance")        # after the label: GIMP needs it
        for arg, arg_label, kind, minimum, maximum, default, arg_help in parameters.RECOVERY_ARGUMENTS:
            if default is None:
                automatic, automatic_label, automatic_help = parameters.AUTOMATIC_ARGUMENTS[arg]
                procedure.add_boolean_argument(automatic, automatic_label,
                                               f"Ticked: {automatic_help}; unticked: the value below", True, flags)
                default = maximum
            add = procedure.add_int_argument if kind == "int" else procedure.add_double_argument
            add(arg, arg_label, arg_help[0].upper() + arg_help[1:], minimum, maximum, default, flags)
        backends = Gimp.Choice.new()
        for index, key in enumerate(parameters.BACKENDS):
            backends.add(key, index, key, "")
        procedure.add_choice_argument("backend", "_Backend", "auto: OpenGL, else NumPy", backends, "auto", flags)
        procedure.add_string_argument("python", "P_ython with aarecovery",
                                      "Used only when GIMP's Python cannot import aarecovery; "
                                      "empty: $AARECOVERY_PYTHON or the one recorded at install", "", flags)
        for key, value_label, value_help in RETURNS:
            procedure.add_string_return_value(key, value_label, value_help, "", flags)
        return procedure


Gimp.main(AntialiasingRecovery.__gtype__, sys.argv)
