"""The work of both menu entries, without any dialog: what the tests drive inside Krita.

:func:`repair` takes a document, its active paint layer and the settings (the dialog's values),
reads O and F as float32, runs the core through ``aarecovery_bridge`` and writes the result
back into the layer in its own colour model and depth, blended by the selection.
"""

from aarecovery_bridge import PluginError, check_version, filters, parameters, worker

from . import AARECOVERY_VERSION, BUNDLE_NOTE, HOST
from .pixels import blend, from_float, layout_of, to_float

FROM_LAYER, APPLY_FILTER = "from-layer", "apply-filter"
#: The dialog's values when nothing was chosen: the core's defaults, the first filter.
DEFAULTS = {**{row[0]: row[5] for row in parameters.RECOVERY_ARGUMENTS if row[5] is not None},
            "auto-strength": True, "strength": 1.0, "backend": "auto", "python": "",
            "filter": next(iter(filters.KRITA_FILTERS)), "properties": "", "keep-copy": True}
BEFORE_SUFFIX = " (before repair)"


def paint_layer(node, role="the active layer"):
    """`node` if it is a paint layer; else the reason it cannot be repaired."""
    if node is None:
        raise PluginError(f"there is no {role.split()[-1]}; select a paint layer")
    if node.type() == "grouplayer":
        raise PluginError(f"'{node.name()}' is a group layer; select a paint layer inside it")
    if node.type() != "paintlayer":
        raise PluginError(f"{role} '{node.name()}' is a {node.type()}; select a paint layer "
                          "(a vector, fill or file layer can be converted with Layer > Convert > to Paint Layer)")
    return node


def layer_below(node):
    siblings = node.parentNode().childNodes()          # bottom first
    index = [s.uniqueId() for s in siblings].index(node.uniqueId())
    if index == 0:
        raise PluginError(f"there is no layer below '{node.name()}'; put the unfiltered original "
                          "directly below the filtered layer")
    return paint_layer(siblings[index - 1], "the layer below")


def place(node, doc):
    """``(name, x, y, width, height)`` for the alignment check: Krita's layers span the image,
    so only a layer's offset (the Move tool) can put its pixels elsewhere."""
    return (node.name(), node.position().x(), node.position().y(), doc.width(), doc.height())


def read(node, doc, layout):
    return to_float(bytes(node.pixelData(0, 0, doc.width(), doc.height())), layout)


def run_filter(node, doc, key, text):
    """Apply Krita's own filter `key` of the catalogue, configured by `text`, to `node`."""
    from krita import Krita
    filter_id, label, default = filters.KRITA_FILTERS[key]
    host_filter = Krita.instance().filter(filter_id)
    if host_filter is None:
        raise PluginError(f"this Krita has no filter '{filter_id}' ({label})")
    config = host_filter.configuration()
    known = config.properties()
    for name, value in filters.parse_properties(text if text.strip() else default).items():
        if name not in known:
            raise PluginError(f"{label} has no property '{name}'; it has: {', '.join(sorted(known))}")
        config.setProperty(name, filters.convert_like(name, value, known[name]))
    host_filter.setConfiguration(config)
    host_filter.apply(node, 0, 0, doc.width(), doc.height())
    doc.waitForDone()


def copy_of(node):
    """The layer as it is, hidden, named for what it holds: Krita 5's Python API gives pixel
    writes no undo step, so the plug-in keeps this above the layer it repaired."""
    copy = node.duplicate()
    copy.setName(node.name() + BEFORE_SUFFIX)
    copy.setVisible(False)
    return copy


def repair(doc, node, entry, settings):
    """Repair `node` of `doc`; return the :class:`aarecovery_bridge.worker.Outcome`.

    Parameters
    ----------
    entry : str
        FROM_LAYER (the layer below is O, `node` is F) or APPLY_FILTER (`node` is O; the
        filter ``settings["filter"]`` with ``settings["properties"]`` makes F).
    settings : dict
        The dialog's values; missing ones take :data:`DEFAULTS`.
    """
    check_version(AARECOVERY_VERSION, __file__, "aarecovery krita install")
    settings = {**DEFAULTS, **settings}
    paint_layer(node)
    layout = layout_of(node)
    shape = (doc.height(), doc.width(), layout.channels)
    selection = doc.selection()
    mask = None if selection is None else bytes(selection.pixelData(0, 0, doc.width(), doc.height()))
    params = parameters.core_params(settings.get, settings["backend"], layout.linear, entry == APPLY_FILTER)
    if entry == FROM_LAYER:
        source = layer_below(node)
        misplaced = filters.alignment_error(place(source, doc), place(node, doc),
                                            "move one with the Move tool, or Layer > Transform > Offset")
        if misplaced:
            raise PluginError(misplaced)
        source_layout = layout_of(source)
        original, filtered = read(source, doc, source_layout), read(node, doc, layout)
        o_shape, before = shape[:2] + (source_layout.channels,), filtered
    else:
        stored = bytes(node.pixelData(0, 0, doc.width(), doc.height()))
        original, o_shape = to_float(stored, layout), shape
        before = original
    backup = copy_of(node) if settings["keep-copy"] else None
    try:
        if entry == APPLY_FILTER:
            run_filter(node, doc, settings["filter"], settings["properties"])
            filtered = read(node, doc, layout)
        outcome = worker.run_core(HOST, (original, o_shape), (filtered, shape), params,
                                  settings["python"], BUNDLE_NOTE)
    except BaseException:
        if entry == APPLY_FILTER:                # the filter ran: put the layer back as it was
            node.setPixelData(stored, 0, 0, doc.width(), doc.height())
        raise
    result = outcome.data if mask is None else blend(before, outcome.data, mask, layout.channels)
    node.setPixelData(from_float(result, layout), 0, 0, doc.width(), doc.height())
    if backup is not None:
        node.parentNode().addChildNode(backup, node)
    doc.refreshProjection()
    return outcome
