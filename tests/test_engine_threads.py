"""One ``Engine`` shared by threads: every call gets its own pair's result, or a clear refusal."""

import threading

import numpy as np
import pytest

import aarecovery
from scenes import shapes


def pairs(count, size=192):
    made = []
    for seed in range(count):
        original = shapes(size, seed=seed)
        made.append((original, np.where(original > 127, 255, 0).astype(original.dtype)))
    return made


def in_threads(work, count):
    """Run ``work(index)`` in `count` threads started together; return {index: result or exception}."""
    barrier, outcome = threading.Barrier(count), {}

    def run(index):
        barrier.wait()
        try:
            outcome[index] = work(index)
        except Exception as error:
            outcome[index] = error

    threads = [threading.Thread(target=run, args=(index,)) for index in range(count)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return outcome


def test_recover_with_a_shared_engine_gives_each_thread_its_own_result(backend):
    images = pairs(6)
    expected = [aarecovery.recover(*pair, backend=backend, mode="paper") for pair in images]
    with aarecovery.Engine(backend) as engine:
        outcome = in_threads(lambda index: aarecovery.recover(*images[index % 6], engine=engine, mode="paper"), 12)
    for index, result in outcome.items():
        assert not isinstance(result, Exception), result
        np.testing.assert_array_equal(result, expected[index % 6])


def test_holding_the_lock_around_set_images_and_recover_shares_the_stateful_api(backend):
    images = pairs(4, size=96)
    expected = [aarecovery.recover(*pair, backend=backend, mode="paper") for pair in images]
    with aarecovery.Engine(backend) as engine:
        def work(index):
            with engine.lock:
                engine.set_images(*images[index % 4])
                return engine.recover(mode="paper")
        outcome = in_threads(work, 8)
    for index, result in outcome.items():
        np.testing.assert_array_equal(result, expected[index % 4])


def test_a_pair_loaded_by_another_thread_is_refused(backend):
    first, second = pairs(2, size=64)
    with aarecovery.Engine(backend) as engine:
        engine.set_images(*first)
        loaded = threading.Thread(target=engine.set_images, args=second)
        loaded.start()
        loaded.join()
        with pytest.raises(aarecovery.InputError, match="loaded by another thread.*one Engine per thread"):
            engine.recover(mode="paper")
        engine.set_images(*first)
        np.testing.assert_array_equal(engine.recover(mode="paper"),
                                      aarecovery.recover(*first, backend=backend, mode="paper"))
