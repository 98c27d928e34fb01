"""The viewer uses only the public API of the core: names in ``aarecovery.__all__``."""

import ast
from pathlib import Path

import aarecovery

VIEWER = Path(__file__).resolve().parents[2] / "viewer"


def core_names_used(tree):
    """``(line, name)`` of every core module or name that a viewer module reaches."""
    used = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module.split(".")[0] == "aarecovery":
            if node.module == "aarecovery":
                used += [(node.lineno, alias.name) for alias in node.names]
            else:
                used.append((node.lineno, node.module.split(".", 1)[1]))
        elif isinstance(node, ast.Import):
            used += [(node.lineno, alias.name.split(".", 1)[1]) for alias in node.names
                     if alias.name.startswith("aarecovery.")]
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "aarecovery":
            used.append((node.lineno, node.attr))
    return used


def test_the_viewer_uses_only_public_names():
    private = []
    for path in sorted(VIEWER.glob("*.py")):
        for line, name in core_names_used(ast.parse(path.read_text(encoding="utf-8"))):
            if name.split(".")[0] not in aarecovery.__all__ and not name.startswith("viewer"):
                private.append(f"{path.name}:{line}: aarecovery.{name}")
    assert not private, "the viewer reaches private parts of the core:\n" + "\n".join(private)


def test_the_check_sees_private_imports():
    tree = ast.parse("import aarecovery.cli\nfrom aarecovery.params import SIGMA_D\nfrom aarecovery import plan\n"
                     "aarecovery.engine.Engine")
    assert [name for _, name in core_names_used(tree)] == ["cli", "params", "plan", "engine"]
