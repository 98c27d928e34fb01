"""docs/safe-default.md against the code: each documented constant exists and has its value.

The document's table names a constant as ``module.NAME`` (under ``aarecovery``) and gives its
value as the code writes it (``3.0 / 255``); a renamed or removed constant, a changed value, or
a numeric constant of ``core/plan/`` with no row fails here, with the row to fix.
"""

import ast
import importlib
import math
import re
from pathlib import Path

import pytest

CHECKOUT = Path(__file__).resolve().parents[1]
DOC = CHECKOUT / "docs" / "safe-default.md"
# A table row: | step | `module.NAME` | `value` | evidence |
_ROW = re.compile(r"^\|[^|]*\|\s*`(?P<name>[a-z_.]+\.[A-Za-z_][A-Za-z0-9_]*)`\s*\|\s*`(?P<value>[^`]+)`\s*\|")


def _documented():
    rows = [_ROW.match(line) for line in DOC.read_text(encoding="utf-8").splitlines()]
    return {row["name"]: row["value"] for row in rows if row}


def _number_or_tuple(node):
    """The value of a literal number, a ratio of numbers or a tuple of them; None for anything else."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return node.value
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
        left, right = _number_or_tuple(node.left), _number_or_tuple(node.right)
        return None if left is None or right is None else left / right
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        value = _number_or_tuple(node.operand)
        return None if value is None else -value
    if isinstance(node, ast.Tuple):
        values = [_number_or_tuple(item) for item in node.elts]
        return None if any(v is None for v in values) else tuple(values)
    return None


def _parse_value(text):
    node = ast.parse(text, mode="eval").body
    if isinstance(node, ast.Constant) and isinstance(node.value, str):  # a named choice (a blend space)
        return node.value
    value = _number_or_tuple(node)
    assert value is not None, (f"docs/safe-default.md: value `{text}` is not a number, a ratio, a tuple of them or a "
                               "quoted string")
    return value


def _same(documented, actual):
    if isinstance(documented, str):
        return documented == actual
    if isinstance(documented, tuple):
        return (isinstance(actual, tuple) and len(actual) == len(documented)
                and all(_same(d, a) for d, a in zip(documented, actual)))
    return isinstance(actual, (int, float)) and math.isclose(documented, actual, rel_tol=1e-12, abs_tol=0)


def _plan_constants():
    """``plan.module.NAME`` of every module-level constant of core/plan/ that is a number or tuple of numbers."""
    found = set()
    for path in sorted((CHECKOUT / "core" / "plan").glob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if not isinstance(node, (ast.Assign, ast.AnnAssign)):
                continue
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                names = target.elts if isinstance(target, ast.Tuple) else [target]
                values = (node.value.elts if isinstance(target, ast.Tuple) and isinstance(node.value, ast.Tuple)
                          else [node.value])
                for name, value in zip(names, values):
                    if (isinstance(name, ast.Name) and name.id.lstrip("_").isupper()
                            and _number_or_tuple(value) is not None):
                        found.add(f"plan.{path.stem}.{name.id}")
    return found


DOCUMENTED = _documented()


def test_the_table_is_found():
    assert len(DOCUMENTED) >= 40, "docs/safe-default.md's table of constants was not parsed"


@pytest.mark.parametrize("name", sorted(DOCUMENTED))
def test_documented_constant_has_its_value(name):
    module_name, _, constant = name.rpartition(".")
    module = importlib.import_module(f"aarecovery.{module_name}")
    assert hasattr(module, constant), (f"docs/safe-default.md names {name}, which aarecovery.{module_name} no longer "
                                       "has: rename or remove its row")
    documented, actual = _parse_value(DOCUMENTED[name]), getattr(module, constant)
    assert _same(documented, actual), f"docs/safe-default.md says {name} = {DOCUMENTED[name]}, the code {actual!r}"


def test_every_constant_of_the_plan_is_documented():
    missing = sorted(_plan_constants() - set(DOCUMENTED))
    assert not missing, ("constants of core/plan/ with no row in docs/safe-default.md (add each with its value and "
                         f"the measurement that chose it): {', '.join(missing)}")


def test_the_check_finds_the_plan_constants():
    # The scan above must see what it is meant to: a threshold, a ratio, a tuple, a pair assignment.
    found = _plan_constants()
    assert {"plan.pointwise.POINTWISE_SHARE", "plan.linearity.AFFINE_TOLERANCE", "plan.calibration._STRENGTHS",
            "plan.order._BLEND_LOW", "plan.order._BLEND_HIGH"} <= found
    assert "plan.pointwise.TABLE_KEYS" not in found and "plan.order._LUMA" not in found
