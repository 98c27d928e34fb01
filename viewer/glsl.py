"""The viewer's GLSL sources, shipped as package resources next to this module."""

from importlib import resources

__all__ = ["shader_source", "program"]


def shader_source(name):
    """Return the text of ``shaders/<name>``.

    Parameters
    ----------
    name : str
        File name, e.g. ``"image_view.frag.glsl"``.
    """
    return resources.files(__package__).joinpath("shaders", name).read_text(encoding="utf-8")


def program(context, vertex, fragment, defines=None):
    """Compile and link a program from two shader files in the given context.

    Parameters
    ----------
    context : moderngl.Context
        The context to build it in (passed explicitly; the viewer never relies on a global one).
    vertex, fragment : str
        Shader file names under ``shaders/``.
    defines : dict, optional
        ``#define NAME VALUE`` lines for the fragment shader, whose file then has no
        ``#version`` line of its own (it must come first, so it is written here).

    Returns
    -------
    moderngl.Program
    """
    fragment_source = shader_source(fragment)
    if defines is not None:
        lines = ["#version 330 core"] + [f"#define {name} {value}" for name, value in defines.items()]
        fragment_source = "\n".join(lines) + "\n" + fragment_source
    return context.program(vertex_shader=shader_source(vertex), fragment_shader=fragment_source)
