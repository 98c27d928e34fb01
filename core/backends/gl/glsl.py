"""GLSL sources as package resources, with a tiny ``#include`` and compile-time defines.

``#include "name.glsl"`` is replaced by that file (once per program), wrapped in ``#line``
directives so that compiler messages point at the right file and line: GLSL 3.30 numbers
source strings, so each file gets a number listed in the error text.
"""

import re
from functools import lru_cache
from importlib import resources

__all__ = ["load_source", "read_source", "ShaderSourceError"]

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')


class ShaderSourceError(RuntimeError):
    """A shader file is missing or includes itself."""


@lru_cache(maxsize=None)
def read_source(name):
    """The text of shader file `name` as stored (no includes expanded)."""
    try:
        return resources.files(__package__).joinpath("shaders", name).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ShaderSourceError(f"shader source {name!r} is missing from the aarecovery package") from None


def load_source(name, defines=None):
    """Return the text of shader `name` with includes expanded and `defines` inserted.

    Parameters
    ----------
    name : str
        File name under ``aarecovery/backends/gl/shaders``.
    defines : dict of str to int or str, optional
        ``#define KEY VALUE`` lines placed right after ``#version`` (a str value is a word,
        such as an image format).

    Returns
    -------
    str
    """
    files = [name]
    included = set()

    def expand(file_name, stack):
        if file_name in stack:
            raise ShaderSourceError(f"shader {file_name!r} includes itself through {' -> '.join(stack)}")
        number = files.index(file_name) if file_name in files else len(files)
        if file_name not in files:
            files.append(file_name)
        out = [f"#line 1 {number}"] if stack else []
        for line_number, line in enumerate(read_source(file_name).splitlines(), start=1):
            match = _INCLUDE.match(line)
            if match is None:
                out.append(line)
                continue
            child = match.group(1)
            if child not in included:
                included.add(child)
                out.append(expand(child, stack + (file_name,)))
            out.append(f"#line {line_number + 1} {number}")
        return "\n".join(out)

    text = expand(name, ())
    lines = text.split("\n")
    if not lines[0].startswith("#version"):
        raise ShaderSourceError(f"shader {name!r} must start with #version")
    header = [f"#define {key} {value if isinstance(value, str) else int(value)}"
              for key, value in sorted((defines or {}).items())]
    legend = "// source numbers: " + ", ".join(f"{i}={f}" for i, f in enumerate(files))
    return "\n".join([lines[0], legend] + header + ["#line 2 0"] + lines[1:]) + "\n"
