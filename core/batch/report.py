"""The batch report: one row per image, as CSV or JSON, and the summary line."""

import csv
import json
import os

from ..errors import InputError
from .work import REPORT_FIELDS

__all__ = ["write_report", "summary", "REPORT_FORMATS"]

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


def write_report(path, results):
    """Write one row per image (``ImageResult`` fields but the pixels) to a .csv or .json file, atomically."""
    check_report_path(path)
    rows = [_row(result) for result in results]
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
