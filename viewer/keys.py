"""The viewer's views and keys, in one table that the help overlay and the docs both show."""

__all__ = ["VIEW_MODES", "KEY_HELP", "key_help_markdown"]

#: ``(name, label, number key)`` of every view, in number-key order.
VIEW_MODES = (
    ("result", "R, the recovered image", "1"),
    ("filtered", "F, the filtered image", "2"),
    ("original", "O, the original image", "3"),
    ("split", "split: F (or O) | R", "4"),
    ("difference", "heat-map of |R - F|", "5"),
    ("alpha", "alpha map (blend coverage)", "6"),
    ("beta", "beta map (confidence)", "7"),
    ("edge_strength", "edge strength / (3 sigma_e)", "8"),
    ("residual", "residual / sigma_d", "9"),
    ("strength", "strength map (the safe default's, per region)", "0"),
)

#: ``(keys, action)`` rows of the help overlay.
KEY_HELP = (
    ("1 ... 9, 0", "views: R, F, O, split, |R - F|, alpha, beta, edge strength, residual, strength"),
    ("S", "split view on/off"),
    ("Space", "flicker: swap R and F (or O; C picks) in place"),
    ("K", "automatic flicker on/off"),
    ("C", "compare R with F or with O"),
    ("mouse wheel", "zoom around the cursor (up to 32x, whole pixels)"),
    ("+ / -", "zoom in / out around the centre"),
    ("F", "fit the image to the window"),
    ("Z", "1:1, one image pixel per screen pixel"),
    ("drag", "pan; in split view, drag the divider to move it"),
    ("Tab", "hide or show the panel"),
    ("Ctrl+O", "open the files named in the panel"),
    ("Ctrl+S", "save R (asks before replacing a file)"),
    ("Ctrl+Shift+C", "copy the parameters as a command line"),
    ("H or F1", "this help; Esc closes it"),
    ("Ctrl+Q", "quit"),
)


def key_help_markdown():
    """The key table as Markdown, for ``docs/viewer.md``."""
    rows = ["| Keys | Action |", "| --- | --- |"]
    rows += [f"| {keys} | {action} |" for keys, action in KEY_HELP]
    return "\n".join(rows)
