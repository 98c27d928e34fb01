"""One image of a batch, in three stages: prepare, compute, store.

``prepare`` (a worker thread) decides whether the image is already done, reads O, makes or
reads F and makes the plan (the safe analysis runs here, in NumPy, beside the engine);
``compute`` (the thread that owns the engine) runs the recovery; ``store`` (a worker thread)
encodes and writes R, and F and the maps when they are kept. A pair of TIFFs that can be
read in pieces (``aarecovery.stream``) is read and written tile by tile inside ``compute``.
Every stage turns a bad file or a failing filter into a failed :class:`ImageResult`, never
an exception that would stop the batch.
"""

import glob
import os
import shutil
import tempfile
import time
from dataclasses import dataclass, field, fields

from .. import stream
from ..contract import check_same_size, check_values, layout_of
from ..errors import InputError
from ..io import check_output_path, os_error_line, read_image, read_quantization, warn_if_orientations_differ, write_image, write_images
from ..io.formats import lossless_extension
from ..io.maps import map_paths, maps_as_images
from ..params import Parameters
from ..memory import check_pair_files
from ..pipeline import recover, tile_side
from ..plan import make_plan
from ..sample import array_sample
from . import storage
from .filtering import BuiltinFilter, FilterCommand
from .jobs import output_name

__all__ = ["Settings", "ImageResult", "Work", "prepare", "compute", "store", "run_one", "fail", "REPORT_FIELDS",
           "destinations", "kept_filtered_path", "maps_folder"]


@dataclass(frozen=True)
class Settings:
    """Everything a batch applies to each image: ``recover``'s options and the batch's own.

    Attributes
    ----------
    parameters : Parameters
    mode : {"safe", "paper"}
    linear : bool
    blend_space : {"linear", "srgb"} or None
    backend : {"auto", "gl", "numpy"}
    gl_path : {"auto", "fragment", "compute"}
    tile_size : int or None
    output : str or None
        The folder results go to (relative paths kept); None returns them as arrays.
    format : str or None
        An extension (``".png"``) for every result instead of the filtered image's own.
    filter : BuiltinFilter or FilterCommand or None
        Makes F from O when the jobs have no F.
    keep_filtered : str or None
        A folder in which F is kept, under the image's relative path.
    maps : str or None
        A folder in which each image's maps are written, in a folder named after it.
    force : bool
        Redo results that are complete and newer than their inputs.
    overwrite : bool
        Allow a result to replace one of its inputs.
    max_bytes : int or float or None
        The decompression-bomb limit of each image read whole (``read_image``'s).
    """

    parameters: Parameters = field(default_factory=Parameters)
    mode: str = "safe"
    linear: bool = False
    blend_space: str = None
    backend: str = "auto"
    gl_path: str = "auto"
    tile_size: int = None
    output: str = None
    format: str = None
    filter: object = None
    keep_filtered: str = None
    maps: str = None
    force: bool = False
    overwrite: bool = False
    max_bytes: float = None


@dataclass
class ImageResult:
    """What happened to one image of a batch (a row of the report).

    Attributes
    ----------
    name : str
        The image's relative path.
    status : {"done", "skipped", "failed"}
        ``"skipped"``: the result was complete and newer than its inputs. Empty while the
        image is in progress.
    output : str or None
        The result's file.
    error : str
        Why it failed (one line), else empty.
    width, height : int or None
    dtype : str
        R's dtype (the filtered image's).
    mode, blend_space, decision, reason : str
    strength : float or None
        The plan: 0 means F was kept as it is; `decision` names the plan's exit and `reason`
        says why.
    backend : str
        ``"gl"`` or ``"numpy"``.
    streamed : bool
        Read and written tile by tile (a pair of TIFFs).
    seconds : float
        Time spent on the image in all stages (they overlap with other images').
    recover_seconds : float
        Of which the recovery itself (the engine).
    image : ndarray or None
        R, when the batch returns arrays (not in the report).
    """

    name: str
    status: str = ""
    output: str = None
    error: str = ""
    width: int = None
    height: int = None
    dtype: str = ""
    mode: str = ""
    blend_space: str = ""
    strength: float = None
    decision: str = ""
    reason: str = ""
    backend: str = ""
    streamed: bool = False
    seconds: float = 0.0
    recover_seconds: float = 0.0
    image: object = field(default=None, repr=False)


#: The report's columns, in order.
REPORT_FIELDS = tuple(f.name for f in fields(ImageResult) if f.name != "image")


@dataclass
class Work:
    """One image between stages."""

    job: object
    result: ImageResult
    output: str = None
    target: str = None
    original: object = None
    filtered: object = None
    filtered_file: str = None
    pair: object = None
    plan: object = None
    capabilities: object = None
    recovered: object = None
    maps: object = None
    scratch: str = None

    def finished(self):
        """Release what the image held (its scratch folder, its open files)."""
        if self.pair is not None:
            self.pair.close()
            self.pair = None
        if self.scratch is not None:
            shutil.rmtree(self.scratch, ignore_errors=True)
            self.scratch = None
        self.original = self.filtered = self.recovered = self.maps = None


def _scratch(work):
    """The image's private temporary folder (removed when it is finished)."""
    if work.scratch is None:
        work.scratch = tempfile.mkdtemp(prefix="aarecovery-batch-")
    return work.scratch


def _local(work, path):
    """A local file for an input: the path itself, or a copy of a URL in the scratch folder."""
    path = os.fspath(path)
    return storage.fetch(path, _scratch(work)) if storage.is_url(path) else path


def fail(work, error):
    """Mark `work` failed with `error` (one line; an unexpected error says so) and finish it."""
    work.result.status = "failed"
    work.result.error = os_error_line(error) if isinstance(error, OSError) else str(error) if isinstance(
        error, InputError) else \
        f"{type(error).__name__}: {error} (an internal error; please report it)"
    work.finished()
    return work


class _Timed:
    def __init__(self, result, field_name=None):
        self.result, self.field_name = result, field_name

    def __enter__(self):
        self.start = time.perf_counter()

    def __exit__(self, *exc):
        seconds = time.perf_counter() - self.start
        self.result.seconds += seconds
        if self.field_name:
            setattr(self.result, self.field_name, getattr(self.result, self.field_name) + seconds)


def _is_path(value):
    return isinstance(value, (str, os.PathLike))


def _up_to_date(job, settings, output, inputs):
    """The result exists (so it is complete: every write is atomic) and is newer than its
    inputs, and every other file of the image (kept F, maps) exists."""
    made = storage.modified(output)
    if made is None:
        return False
    stamps = [storage.modified(path) for path in inputs]
    return all(stamp is not None and stamp <= made for stamp in stamps) and \
        all(storage.exists(path) for role, path in destinations(job, settings) if role != "result")


def remove_stale_parts(output, before):
    """Remove temporary files of `output` that an interrupted run left (older than `before`, a time)."""
    if storage.is_url(output):
        return
    folder, name = os.path.split(os.path.abspath(output))
    stem, extension = os.path.splitext(name)
    for path in glob.glob(os.path.join(glob.escape(folder), f".{glob.escape(stem)}.*.part{glob.escape(extension)}")):
        try:
            if os.stat(path).st_mtime < before:
                os.unlink(path)
        except OSError:
            pass


def _kept_path(folder, name, extension=None):
    stem, own = os.path.splitext(name)
    return os.path.join(folder, *(stem + (own if extension is None else extension)).split("/"))


def kept_filtered_path(settings, job):
    """Where the filtered image the batch makes for `job` is kept (``settings.keep_filtered``)."""
    if isinstance(settings.filter, FilterCommand):
        original = os.fspath(job.original) if _is_path(job.original) else job.name
        return _kept_path(settings.keep_filtered, job.name, settings.filter.output_extension(original))
    return _kept_path(settings.keep_filtered, job.name, lossless_extension(os.path.splitext(job.name)[1]))


def maps_folder(settings, job):
    """The folder `job`'s maps are written into (``settings.maps``/NAME without its extension)."""
    return _kept_path(settings.maps, job.name, "")


def destinations(job, settings):
    """``(role, path)`` of every file the batch writes for `job`: its result, the filtered
    image it keeps, its maps (none without an output folder)."""
    if settings.output is None:
        return
    yield "result", storage.join(settings.output, output_name(job.name, settings.format))
    if settings.keep_filtered is not None and job.filtered is None:
        yield "kept filtered image", kept_filtered_path(settings, job)
    if settings.maps is not None:
        for path in map_paths(maps_folder(settings, job)).values():
            yield "map", path


def prepare(job, settings, capabilities, started, planner=make_plan):
    """Stage 1: skip, read, filter, plan. Returns a :class:`Work`, failed or skipped ones included.

    Parameters
    ----------
    job : Job
    settings : Settings
    capabilities : Capabilities
        The engine's (which pairs stream).
    started : float
        When the batch started (``time.time()``), for clearing stale temporary files.
    planner : callable
        ``aarecovery.plan.make_plan``, or a stand-in that runs it in another process.
    """
    work = Work(job, ImageResult(job.name))
    try:
        with _Timed(work.result):
            _prepare(work, settings, capabilities, started, planner)
    except Exception as error:
        return fail(work, error)
    return work


def _prepare(work, settings, capabilities, started, planner):
    job, result = work.job, work.result
    if job.filtered is None and settings.filter is None:
        raise InputError(f"{job.name}: no filtered image and no filter to make one")
    inputs = [os.fspath(path) for path in (job.original, job.filtered) if _is_path(path)]
    if settings.output is not None:
        work.output = work.target = storage.join(settings.output, output_name(job.name, settings.format))
        remove_stale_parts(work.output, started)
        if not settings.force and inputs and _up_to_date(job, settings, work.output, inputs):
            result.status, result.output = "skipped", work.output
            return
        if storage.is_url(work.output):
            work.target = os.path.join(_scratch(work), "result" + os.path.splitext(work.output)[1])
        else:
            os.makedirs(os.path.dirname(os.path.abspath(work.output)), exist_ok=True)
    original_path, filtered_path = (_local(work, path) if _is_path(path) else None
                                    for path in (job.original, job.filtered))
    if isinstance(settings.filter, FilterCommand) and job.filtered is None:
        if original_path is None:
            raise InputError(f"{job.name}: a filter command needs the original as a file, not an array")
        filtered_path = work.filtered_file = settings.filter.run(original_path, _scratch(work))
    streamable = (work.output is not None and settings.maps is None and original_path and filtered_path
                  and not (isinstance(settings.filter, BuiltinFilter) and job.filtered is None))
    if streamable:
        work.pair = stream.open_pair(original_path, filtered_path,
                                     stream.resolve_tile(capabilities, settings.tile_size),
                                     settings.parameters.iterations, max_bytes=settings.max_bytes)
    if work.pair is not None:
        result.streamed = True
        result.height, result.width = work.pair.height, work.pair.width
        result.dtype = str(work.pair.result_dtype)
        check_output_path(work.target, work.pair.result_shape)
        stream.check_room(work.pair, work.target)
        work.plan = stream.plan_pair(work.pair, settings.parameters, mode=settings.mode, linear=settings.linear,
                                     blend_space=settings.blend_space, planner=planner)
    else:
        if original_path:
            check_pair_files(original_path, filtered_path, tile_side(capabilities, settings.tile_size),
                             maps=settings.maps is not None, max_bytes=settings.max_bytes)
        original = read_image(original_path, max_bytes=settings.max_bytes) if original_path else job.original
        if filtered_path:
            filtered = read_image(filtered_path, max_bytes=settings.max_bytes)
        elif job.filtered is not None:
            filtered = job.filtered
        else:
            filtered = settings.filter.apply(original)
        o_layout, f_layout = layout_of(original, "original"), layout_of(filtered, "filtered")
        check_same_size(o_layout, f_layout)
        check_values(original, o_layout, "original")
        check_values(filtered, f_layout, "filtered")
        result.height, result.width, result.dtype = f_layout.height, f_layout.width, str(f_layout.dtype)
        if work.output is not None:
            check_output_path(work.target, f_layout.shape)
        work.original, work.filtered = original, filtered
        # A JPEG original's tables bound its compression noise (arrays: the plan finds the grid).
        work.plan = planner(*array_sample(original, filtered), settings.parameters, mode=settings.mode,
                            linear=settings.linear, blend_space=settings.blend_space,
                            quantization=read_quantization(original_path) if original_path else None)
    if original_path and filtered_path:
        warn_if_orientations_differ(original_path, filtered_path, job.name)
    plan = work.plan
    result.mode, result.blend_space, result.strength, result.reason = (plan.mode, plan.blend_space, plan.strength,
                                                                      plan.reason)
    result.decision = str(plan.decision)


def compute(work, engine, settings):
    """Stage 2, on the engine's thread: recover (and, for a streamed pair, read and write)."""
    if work.result.status:
        return work
    work.result.backend = engine.backend
    try:
        with _Timed(work.result, "recover_seconds"):
            if work.pair is not None:
                stream.recover_pair(work.pair, work.target, work.plan, engine=engine, tile=settings.tile_size,
                                    linear=settings.linear)
            else:
                recovered = recover(work.original, work.filtered, plan=work.plan, engine=engine,
                                    tile_size=settings.tile_size, linear=settings.linear,
                                    return_maps=settings.maps is not None)
                if settings.maps is not None:
                    recovered, work.maps = recovered
                work.recovered = recovered
    except Exception as error:
        return fail(work, error)
    return work


def store(work, settings):
    """Stage 3: write R (atomically), and F and the maps when they are kept; finish the image."""
    result = work.result
    if result.status:
        work.finished()
        return result
    try:
        with _Timed(result):
            if work.output is None:
                result.image = work.recovered
            else:
                _keep_filtered(work, settings)
                images = {} if work.pair is not None else {work.target: work.recovered}
                if settings.maps is not None and work.maps is not None:
                    folder = maps_folder(settings, work.job)
                    os.makedirs(folder, exist_ok=True)
                    images.update(maps_as_images(folder, work.maps))
                # The result last and with its maps, all or none: a result that exists means
                # that every file of the image was written (a re-run skips it).
                write_images(images)
                if work.target != work.output:
                    storage.publish(work.target, work.output)
        result.output = work.output
        result.status = "done"
    except Exception as error:
        fail(work, error)
        return result
    work.finished()
    return result


def _keep_filtered(work, settings):
    if settings.keep_filtered is None or work.job.filtered is not None:
        return
    if work.filtered_file is not None:
        kept = kept_filtered_path(settings, work.job)
        os.makedirs(os.path.dirname(kept), exist_ok=True)
        # The tool's own file, byte for byte, renamed into place.
        descriptor, temporary = tempfile.mkstemp(dir=os.path.dirname(kept), prefix=".kept.", suffix=".part")
        os.close(descriptor)
        try:
            shutil.copyfile(work.filtered_file, temporary)
            os.replace(temporary, kept)
        except BaseException:
            if os.path.exists(temporary):
                os.unlink(temporary)
            raise
    elif work.filtered is not None:
        kept = kept_filtered_path(settings, work.job)
        os.makedirs(os.path.dirname(kept), exist_ok=True)
        write_image(kept, work.filtered)


def run_one(job, settings, engine, started):
    """All three stages of one image in this thread (a Dask task, or a batch of one)."""
    return store(compute(prepare(job, settings, engine.capabilities, started), engine, settings), settings)
