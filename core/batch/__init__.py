"""Many images at once: ``aarecovery batch`` and :func:`aarecovery.recover_many`.

One engine (one GL context, its programs compiled once) recovers every image while worker
threads read, filter, plan and write around it (:mod:`.local`), or a Dask cluster runs one
task per image, or per tile of a gigapixel pair (:mod:`.distributed`). :mod:`.jobs` pairs
the files, :mod:`.filtering` makes F with a built-in filter or any command-line tool,
:mod:`.work` is one image's stages and :mod:`.report` the per-image report.
"""

from .api import make_jobs, make_settings, recover_many, run_jobs
from .filtering import BuiltinFilter, FilterCommand, FilterFailed
from .jobs import IMAGE_EXTENSIONS, Job, find_images, find_pairs
from .local import default_workers
from .report import check_report_path, read_report, summary, write_report
from .work import REPORT_FIELDS, ImageResult, Settings

__all__ = ["recover_many", "run_jobs", "make_jobs", "make_settings", "BuiltinFilter", "FilterCommand",
           "FilterFailed", "Job", "IMAGE_EXTENSIONS", "find_images", "find_pairs", "default_workers",
           "write_report", "read_report", "check_report_path", "summary", "ImageResult", "Settings", "REPORT_FIELDS"]
