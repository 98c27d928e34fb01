"""A batch on a Dask cluster: one task per image, or per tile of a pair that streams.

Each worker thread keeps its own engine (GL where the worker has a GL context, NumPy
otherwise, as ``backend="auto"`` decides there), made on its first task and reused. Paths
must name storage every worker sees: a shared file system, or fsspec URLs. A task writes
its result atomically; when a worker dies, Dask runs its tasks again elsewhere, and the
new attempt first removes what the dead one left half-written. A pair of TIFFs that can
be read in pieces is split into one task per tile; the tiles come back to this process,
which writes them in order into the tiled result (and plans the pair first, as the local
batch does), so it must see the files too.
"""

import threading
import time
from collections import deque

from ..errors import InputError

__all__ = ["run_dask", "connect"]

# Tiles of a streamed pair in flight per worker thread: enough to keep every worker busy
# while this process writes, few enough to bound the tiles waiting here.
_TILES_PER_THREAD = 2
_ENGINES = threading.local()


def connect(target):
    """A ``distributed.Client`` for ``"local"``, a scheduler address, or a Client; and whether it is ours."""
    try:
        import distributed
    except ImportError:
        raise InputError("--dask needs Dask's distributed scheduler: pip install 'aarecovery[dask]'") from None
    if isinstance(target, distributed.Client):
        return target, False
    if target == "local":
        # One single-threaded worker process per core: each holds one engine.
        cluster = distributed.LocalCluster(threads_per_worker=1, processes=True, dashboard_address=None)
        return distributed.Client(cluster), True
    if not isinstance(target, str):
        raise InputError(f"dask must be 'local', a scheduler address such as tcp://host:8786, or a Client; "
                         f"got {target!r}")
    try:
        return distributed.Client(target, timeout="30s"), True
    except OSError as error:
        raise InputError(f"cannot reach the Dask scheduler at {target}: {error}; check the address and that "
                         "the scheduler runs") from None


def _engine(backend, gl_path="auto"):
    """This worker thread's engine for `backend` and `gl_path`, made on first use."""
    engines = getattr(_ENGINES, "engines", None)
    if engines is None:
        engines = _ENGINES.engines = {}
    if (backend, gl_path) not in engines:
        from ..engine import Engine
        engines[backend, gl_path] = Engine(backend, gl_path=gl_path)
    return engines[backend, gl_path]


def _image_task(job, settings):
    from .work import run_one

    # Temporary files of this result older than this attempt are a dead attempt's.
    return run_one(job, settings, _engine(settings.backend, settings.gl_path), time.time())


def _tile_task(original, filtered, plan, piece, settings):
    from ..io.tiled import tiff_regions
    from ..pipeline import recover_tiles
    from ..stream import StreamedPair

    with StreamedPair(tiff_regions(original), tiff_regions(filtered)) as pair:
        engine = _engine(settings.backend, settings.gl_path)
        [(_, result, _)] = recover_tiles(engine, pair.read, plan, [piece], pair.result_layout,
                                          linear=settings.linear)
        return result, engine.backend


def run_dask(jobs, settings, target, *, progress=None, started=None):
    """Run the jobs on a Dask cluster; return their results in order (see ``recover_many``)."""
    from distributed import as_completed

    from .work import ImageResult

    client, owned = connect(target)
    try:
        results = [None] * len(jobs)
        streamed = {}
        for index, job in enumerate(jobs):
            plan = _streamed_plan(job, settings, client, started)
            if plan is not None:
                streamed[index] = plan
        futures = {client.submit(_image_task, job, settings, retries=2, pure=False): index
                   for index, job in enumerate(jobs) if index not in streamed}
        for index, work in streamed.items():
            results[index] = _run_streamed(client, work, settings)
            if progress is not None:
                progress(results[index])
        for future in as_completed(futures):
            index = futures[future]
            try:
                results[index] = future.result()
            except Exception as error:  # a task that failed three times: its worker kept dying
                results[index] = ImageResult(jobs[index].name, status="failed",
                                             error=f"the Dask task failed: {type(error).__name__}: {error}")
            if progress is not None:
                progress(results[index])
        return results
    finally:
        if owned:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()


def _threads(client):
    return max(1, sum(client.nthreads().values()))


def _streamed_plan(job, settings, client, started):
    """Prepare a pair that streams here (its plan made once); None for every other job."""
    from .. import stream
    from .work import prepare

    if settings.filter is not None or settings.maps is not None or not all(
            isinstance(path, str) and "://" not in path for path in (job.original, job.filtered)):
        return None
    probe = stream.open_pair(job.original, job.filtered, 1, settings.parameters.iterations)
    if probe is None:
        return None
    probe.close()
    # Asked in a task on each worker, so that the engine is made in the thread that runs tasks.
    capabilities = client.gather([client.submit(_capabilities, settings.backend, workers=[address], pure=False,
                                                allow_other_workers=False) for address in client.nthreads()])
    # The smallest tile any worker holds, so that every worker can run every tile.
    smallest = min(capabilities, key=lambda c: (c.max_tile, c.default_tile))
    work = prepare(job, settings, smallest, started)
    if work.pair is None:
        work.finished()
        return None
    work.capabilities = smallest
    return work


def _capabilities(backend):
    return _engine(backend).capabilities


def _run_streamed(client, work, settings):
    """Recover a streamed pair as one task per tile, writing the tiles here in order."""
    from .. import stream
    from ..io.tiled import TiledTiffWriter
    from ..tiling import aligned_tiles, halo_for
    from .storage import publish
    from .work import fail

    result = work.result
    if result.status:
        work.finished()
        return result
    window = deque()
    try:
        side = stream.stream_tile(stream.resolve_tile(work.capabilities, settings.tile_size), work.plan.iterations,
                                  work.plan.reach)
        halo = halo_for(work.plan.iterations, work.plan.reach)
        grid = deque(aligned_tiles(work.pair.height, work.pair.width, side, halo))
        writer = TiledTiffWriter(work.target, work.pair.result_shape, work.pair.result_dtype, side)
        plan = client.scatter(work.plan, broadcast=True)
        backends = set()
        start = time.perf_counter()

        def pieces():
            while grid or window:
                while grid and len(window) < _TILES_PER_THREAD * _threads(client):
                    window.append(client.submit(_tile_task, work.job.original, work.job.filtered, plan,
                                                grid.popleft(), settings, retries=2, pure=False))
                piece, backend = window.popleft().result()
                backends.add(backend)
                yield piece

        if work.plan.keeps_filtered:
            writer.write(work.pair.filtered.read(*inner) for inner, _ in grid)
        else:
            writer.write(pieces())
        result.recover_seconds = time.perf_counter() - start
        result.seconds += result.recover_seconds
        result.backend = ",".join(sorted(backends)) or "-"
        if work.target != work.output:
            publish(work.target, work.output)
        result.output, result.status = work.output, "done"
    except Exception as error:
        for future in window:
            future.cancel()
        fail(work, error)
        return result
    work.finished()
    return result
