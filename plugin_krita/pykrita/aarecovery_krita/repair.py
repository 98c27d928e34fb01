"""The work of both menu entries, without any dialog: what the tests drive inside Krita.

:func:`repair` takes a document, its active paint layer and the settings (the dialog's values),
reads O and F as float32, runs the core through ``aarecovery_bridge`` and writes the result,
blended by the selection, into a new layer above in the layer's own colour model and depth.
"""

from aarecovery_bridge import PluginError, check_version, filters, parameters, worker

from . import AARECOVERY_VERSION, HOST
from .pixels import blend, from_float, layout_of, to_float

FROM_LAYER, APPLY_FILTER = "from-layer", "apply-filter"
#: The dialog's values when nothing was chosen: the core's defaults, the first filter.
DEFAULTS = {**{row[0]: row[5] for row in parameters.RECOVERY_ARGUMENTS if row[5] is not None},
            "auto-strength": True, "strength": 1.0, "backend": "auto", "python": "",
            "filter": next(iter(filters.KRITA_FILTERS)), "properties": ""}
REPAIRED_SUFFIX = " (repaired)"


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


def configured_filter(key, text):
    """Krita's own filter `key` of the catalogue, configured by the ``name=value`` `text`."""
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
    return host_filter


def repaired_layer(node):
    """A copy of `node` above it, named for what it will hold.

    Krita 5's Python API writes pixels outside the undo history (``Node.setPixelData``;
    measured in tests/krita/test_krita_gui.py), but adding a layer is one undoable step: so
    the repair goes into this new layer and `node` is never written, and one Edit > Undo
    takes the whole repair back.
    """
    copy = node.duplicate()
    copy.setName(node.name() + REPAIRED_SUFFIX)
    node.parentNode().addChildNode(copy, node)
    return copy


def repair(doc, node, entry, settings):
    """Repair `node` of `doc` into a new layer above it; return ``(that layer, outcome)``.

    Parameters
    ----------
    entry : str
        FROM_LAYER (the layer below is O, `node` is F) or APPLY_FILTER (`node` is O; the
        filter ``settings["filter"]`` with ``settings["properties"]`` makes F).
    settings : dict
        The dialog's values; missing ones take :data:`DEFAULTS`.

    Returns
    -------
    (krita.Node, aarecovery_bridge.worker.Outcome)
        The new layer, in `node`'s colour model and depth, and what the recovery did.
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
        original = before = read(node, doc, layout)
        o_shape = shape
        host_filter = configured_filter(settings["filter"], settings["properties"])   # typos fail here
    target = repaired_layer(node)
    try:
        if entry == APPLY_FILTER:
            host_filter.apply(target, 0, 0, doc.width(), doc.height())
            doc.waitForDone()
            filtered = read(target, doc, layout)
        outcome = worker.run_core(HOST, (original, o_shape), (filtered, shape), params, settings["python"])
    except BaseException:
        target.remove()
        raise
    result = outcome.data if mask is None else blend(before, outcome.data, mask, layout.channels)
    target.setPixelData(from_float(result, layout), 0, 0, doc.width(), doc.height())
    doc.setActiveNode(target)
    doc.refreshProjection()
    return target, outcome
