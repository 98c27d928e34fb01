"""The batch report: one row per image, as CSV or JSON, and the summary line."""

import csv
import dataclasses
import json
import os

from ..errors import InputError
from .work import REPORT_FIELDS, ImageResult

__all__ = ["write_report", "read_report", "summary", "REPORT_FORMATS"]

REPORT_FORMATS = (".csv", ".json")


def check_report_path(path):
    """Raise :class:`InputError` unless `path` ends in .csv or .json in an existing folder."""
    extension = os.path.splitext(path)[1].lower()
    if extension not in REPORT_FORMATS:
        raise InputError(f"--report {path}: the report is written as CSV or JSON; end its name in .csv or .json")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(f"--report {path}: folder {folder} does not exist; create it first")


def _row(result):
    row = {name: getattr(result, name) for name in REPORT_FIELDS}
    for name in ("seconds", "recover_seconds"):
        row[name] = round(row[name], 4)
    return row


#: What a skipped image's row takes from the report of the run that made its result, so that
#: the report of a resumed batch describes every image.
_CARRIED = ("width", "height", "dtype", "mode", "blend_space", "strength", "reason", "backend", "streamed")
_TYPES = {f.name: f.type for f in dataclasses.fields(ImageResult)}


def _typed(name, text):
    """A CSV cell as the ``ImageResult`` field `name` holds it."""
    kind = _TYPES[name]
    if kind in (int, float):
        return None if text in ("", None) else (int if kind is int else float)(text)
    if kind is bool:
        return text in (True, "True", "true", "1")
    return "" if text is None and kind is str else text


def read_report(path):
    """The rows of a report :func:`write_report` wrote, as dicts of ``ImageResult`` fields.

    Raises
    ------
    InputError
        When the file cannot be read as a report.
    """
    path = os.fspath(path)
    try:
        with open(path, newline="") as file:
            rows = json.load(file) if path.lower().endswith(".json") else list(csv.DictReader(file))
        return [{name: _typed(name, row.get(name)) for name in REPORT_FIELDS} for row in rows]
    except (OSError, ValueError, TypeError, AttributeError, KeyError) as error:
        raise InputError(f"cannot read the report {path}: {error}") from None


def _carried_over(rows, path):
    """`rows`, each skipped image's plan and size taken from the previous report at `path`."""
    if not any(row["status"] == "skipped" for row in rows) or not os.path.isfile(path):
        return rows
    try:
        previous = {row["name"]: row for row in read_report(path) if row["status"] in ("done", "skipped")}
    except InputError:  # not a report of ours: nothing to carry over
        return rows
    for row in rows:
        earlier = previous.get(row["name"])
        if row["status"] == "skipped" and earlier is not None and earlier["output"] == row["output"]:
            row.update({name: earlier[name] for name in _CARRIED})
    return rows


def write_report(path, results):
    """Write one row per image (``ImageResult`` fields but the pixels) to a .csv or .json file, atomically.

    A skipped image (up to date) keeps the size and plan that the report already at `path`
    gives it, so that the report of a resumed batch describes the whole batch.
    """
    check_report_path(path)
    rows = _carried_over([_row(result) for result in results], path)
    temporary = f"{path}.part"
    try:
        # A file name that is not UTF-8 (os.fsdecode's surrogates) is written escaped (\udcff).
        with open(temporary, "w", newline="", encoding="utf-8", errors="backslashreplace") as out:
            if path.lower().endswith(".json"):
                json.dump(rows, out, indent=1)
                out.write("\n")
            else:
                writer = csv.DictWriter(out, fieldnames=REPORT_FIELDS)
                writer.writeheader()
                writer.writerows(rows)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


def summary(results, seconds):
    """One line: how many images were recovered, skipped and failed, and the rate."""
    counts = {status: sum(result.status == status for result in results) for status in ("done", "skipped", "failed")}
    kept = sum(result.status == "done" and result.strength == 0 for result in results)
    done = counts["done"]
    rate = f", {done / seconds:.2f} images/s" if done and seconds > 0 else ""
    return (f"{done} recovered ({kept} left as filtered by the safe plan), {counts['skipped']} up to date, "
            f"{counts['failed']} failed in {seconds:.1f} s{rate}")
