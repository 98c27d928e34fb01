"""The host filters the plug-ins offer, and their ``name=value`` properties.

The apply-filter entries run one of the host's own filters on the layer before they recover;
the user edits its settings as text, e.g. ``channel=value low=0.5 high=1.0``. This module
holds each host's catalogue (GIMP's in :data:`GIMP_FILTERS`, Krita's in
:data:`KRITA_FILTERS`) and turns the text into values; the plug-ins hand those to the host.
"""

import shlex

from . import PluginError

__all__ = ["GIMP_FILTERS", "GIMP_COLOUR_TOOLS", "KRITA_FILTERS", "parse_properties", "convert",
           "convert_like", "choose", "colour_tool_arguments", "alignment_error"]

# Filters GIMP's apply-filter entry offers: key -> (kind, target, label, default properties).
# "pdb" filters are GIMP's own colour tools, called as libgimp drawable methods (their GEGL ops
# take config objects that libgimp cannot build); "proc" a PDB procedure; "gegl" filters run as
# a Gimp.DrawableFilter. The defaults double as documentation of the property names.
GIMP_FILTERS = {
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
# The libgimp methods' arguments in order: (property, kind, value when not given). An
# "enum:Name" kind is a member of Gimp.Name, given by its nick.
GIMP_COLOUR_TOOLS = {
    "threshold": (("channel", "enum:HistogramChannel", "value"), ("low", "float", 0.5),
                  ("high", "float", 1.0)),
    "levels": (("channel", "enum:HistogramChannel", "value"), ("low-input", "float", 0.0),
               ("high-input", "float", 1.0), ("clamp-input", "bool", False), ("gamma", "float", 1.0),
               ("low-output", "float", 0.0), ("high-output", "float", 1.0),
               ("clamp-output", "bool", False)),
    "curves_spline": (("channel", "enum:HistogramChannel", "value"),
                      ("points", "points", [0.0, 0.0, 1.0, 1.0])),
    "posterize": (("levels", "int", 3),),
    "desaturate": (("mode", "enum:DesaturateMode", "luminance"),),
}
# Filters Krita's apply-filter action offers: key -> (Krita's filter id, label, default
# properties). The properties are those of the filter's own configuration
# (Krita.instance().filter(id).configuration()); the text sets some of them.
KRITA_FILTERS = {
    "threshold": ("threshold", "Threshold", "threshold=128"),
    "posterize": ("posterize", "Posterize", "steps=4"),
    # Empty: Krita's default gradient; gradientXML='<gradient type="stop">...' sets another.
    "gradientmap": ("gradientmap", "Gradient Map", ""),
    "indexcolors": ("indexcolors", "Index Colors", ""),
    "palettize": ("palettize", "Palettize", ""),
    "desaturate": ("desaturate", "Desaturate", ""),
}
TRUE, FALSE = ("1", "true", "yes", "on"), ("0", "false", "no", "off")


def parse_properties(text):
    """``"a=1 b=x"`` -> ``{"a": "1", "b": "x"}``; values may be quoted."""
    props = {}
    for item in shlex.split(text or ""):
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise PluginError(f"filter property '{item}' is not of the form name=value")
        props[key.strip()] = value.strip()
    return props


def convert(key, text, kind):
    """Property `key`'s value `text` as `kind`: "bool", "int", "float", "str" or "points"."""
    if kind == "bool":
        if text.lower() in TRUE + FALSE:
            return text.lower() in TRUE
        raise PluginError(f"filter property {key}={text}: use true or false")
    if kind == "str":
        return text
    if kind == "points":
        points = [convert(key, part, "float") for part in text.split(",")]
        if len(points) < 4 or len(points) % 2:
            raise PluginError(f"filter property {key}= needs x,y pairs, e.g. 0,0,0.5,0.3,1,1")
        return points
    try:
        return {"int": int, "float": float}[kind](text)
    except ValueError:
        raise PluginError(f"filter property {key}={text} is not a number") from None


def convert_like(key, text, current):
    """`text` as a value of the type `current` has (a host configuration's present value)."""
    kind = {bool: "bool", int: "int", float: "float"}.get(type(current), "str")
    return convert(key, text, kind)


def choose(key, text, choices):
    """``choices[text]``, or an error listing them (`choices`: name -> value)."""
    if text in choices:
        return choices[text]
    raise PluginError(f"filter property {key}={text}: choose one of {', '.join(choices)}")


def colour_tool_arguments(method, props, enum_choices):
    """The arguments of GIMP's colour tool `method` from `props` (consumed).

    `enum_choices(name)` gives the members of ``Gimp.<name>`` by nick.
    """
    args = []
    for key, kind, default in GIMP_COLOUR_TOOLS[method]:
        text = props.pop(key, None)
        if kind.startswith("enum:"):
            args.append(choose(key, str(default) if text is None else text.lower(),
                               enum_choices(kind[len("enum:"):])))
        else:
            args.append(default if text is None else convert(key, text, kind))
    if props:
        known = [key for key, *_ in GIMP_COLOUR_TOOLS[method]]
        raise PluginError(f"{method.split('_')[0]} has no propert{'y' if len(props) == 1 else 'ies'} "
                          f"{', '.join(sorted(props))}; it takes: {', '.join(known)}")
    return args


def alignment_error(original, filtered, fix):
    """The message for two layers that do not cover the same pixels, or None when they do.

    `original` and `filtered` are ``(name, x, y, width, height)``; `fix` says how to align
    them in the host.
    """
    (o_name, *o_rect), (f_name, *f_rect) = original, filtered
    if o_rect == f_rect:
        return None
    return (f"the original layer '{o_name}' is {o_rect[2]}x{o_rect[3]} at ({o_rect[0]}, "
            f"{o_rect[1]}) but the filtered layer '{f_name}' is {f_rect[2]}x{f_rect[3]} at "
            f"({f_rect[0]}, {f_rect[1]}); recovery compares the pixels at the same place, so give "
            f"both layers the same size and position ({fix}) and run it again")
