"""Running GIMP's own filters for the plug-in's apply-filter entry (GIMP 3, libgimp).

The catalogue of filters and the parsing of their ``name=value`` properties are host-neutral,
in ``aarecovery_bridge.filters``; this module hands the values to GIMP.
"""

import gi

gi.require_version("Gimp", "3.0")
gi.require_version("Gegl", "0.4")
from gi.repository import Gegl, Gimp, GLib, GObject  # noqa: E402

from aarecovery_bridge import PluginError, filters  # noqa: E402

GEGL_KINDS = {GObject.TYPE_BOOLEAN: "bool", GObject.TYPE_INT: "int", GObject.TYPE_UINT: "int",
              GObject.TYPE_INT64: "int", GObject.TYPE_DOUBLE: "float", GObject.TYPE_FLOAT: "float",
              GObject.TYPE_STRING: "str"}


def enum_choices(name):
    enum = getattr(Gimp, name)
    return {k.lower().replace("_", "-"): getattr(enum, k) for k in dir(enum)
            if k.isupper() and isinstance(getattr(enum, k), enum)}


def gegl_filter(layer, operation, props):
    """Apply the GEGL `operation` with `props` (text converted by property type)."""
    try:
        drawable_filter = Gimp.DrawableFilter.new(layer, operation, None)
        message = Gimp.get_pdb().get_last_error()
    except (GLib.Error, TypeError) as error:            # unknown name: "constructor returned NULL"
        drawable_filter, message = None, getattr(error, "message", None) or Gimp.get_pdb().get_last_error()
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
        if vtype.is_a(Gegl.Color):
            value = Gegl.Color.new(text)
        elif vtype.is_a(GObject.TYPE_ENUM):
            members = pspec.enum_class.__enum_values__.items()
            value = filters.choose(key, text, {name: number for number, member in members
                                               for name in (member.value_nick, member.value_name, str(number))})
        elif vtype in GEGL_KINDS:
            value = filters.convert(key, text, GEGL_KINDS[vtype])
        else:
            raise PluginError(f"{operation} property '{key}' has type {vtype.name}, which cannot be set from text")
        settings.set_property(key, value)
    drawable_filter.update()
    layer.merge_filter(drawable_filter)


def apply_filter_to(image, layer, config):
    """Run the chosen filter on `layer` (a temporary copy) through GIMP."""
    kind, target, label, default = filters.GIMP_FILTERS[config.get_property("filter")]
    text = config.get_property("properties")
    props = filters.parse_properties(default if text is None or not text.strip() else text)
    if kind == "pdb":
        if not getattr(layer, target)(*filters.colour_tool_arguments(target, props, enum_choices)):
            raise PluginError(f"GIMP's {target.split('_')[0]} failed: {Gimp.get_pdb().get_last_error()}")
    elif kind == "proc":
        procedure = Gimp.get_pdb().lookup_procedure(target)
        if procedure is None:
            raise PluginError(f"GIMP has no procedure {target} for the {label} filter")
        settings = procedure.create_config()
        for key, value in (("run-mode", Gimp.RunMode.NONINTERACTIVE), ("image", image)):
            settings.set_property(key, value)
        settings.set_core_object_array("drawables", [layer])
        result = procedure.run(settings)
        if result.index(0) != Gimp.PDBStatusType.SUCCESS:
            raise PluginError(f"{label} failed: {result.index(1) if result.length() > 1 else ''}")
    else:
        operation = target or (config.get_property("operation") or "").strip()
        if not operation:
            raise PluginError("enter the GEGL operation's name, e.g. gegl:median-blur")
        gegl_filter(layer, operation, props)


def filtered_copy(image, layer, config, read):
    """F: the chosen filter run on a temporary copy of `layer`, as `read(copy)` returns it.

    The selection is lifted meanwhile, so F is the filter's full result; the selection
    applies once, when the recovered pixels are merged.
    """
    saved = None if Gimp.Selection.is_empty(image) else Gimp.Selection.save(image)
    copy = layer.copy()
    image.insert_layer(copy, layer.get_parent(), image.get_item_position(layer))
    try:
        if saved is not None:
            Gimp.Selection.none(image)
        apply_filter_to(image, copy, config)
        return read(copy)
    finally:
        image.remove_layer(copy)
        if saved is not None:
            image.select_item(Gimp.ChannelOps.REPLACE, saved)
            image.remove_channel(saved)
