"""The library API: every Engine state gives the same clear error on every backend, and
parameters take NumPy scalars but nothing outside the ranges ``aarecovery.PARAMETERS`` declares."""

import warnings

import numpy as np
import pytest

import aarecovery
from aarecovery import InputError
from aarecovery.cli import main


def edge_pair(seed=0, size=(20, 24)):
    original = (np.random.default_rng(seed).random(size + (3,)) * 255).astype(np.uint8)
    return original, np.where(original > 127, 255, 0).astype(np.uint8)


# --- C: engine states ------------------------------------------------------------------------------


def test_result_and_maps_before_images(backend):
    with aarecovery.Engine(backend) as engine:
        for call in (engine.result, engine.maps, engine.compute, engine.plan):
            with pytest.raises(InputError, match=r"no images loaded: call set_images"):
                call()


def test_result_and_maps_before_compute(backend):
    with aarecovery.Engine(backend) as engine:
        engine.set_images(*edge_pair())
        with pytest.raises(InputError, match=r"nothing computed .* call compute\(\) or recover\(\) first"):
            engine.result()
        with pytest.raises(InputError, match=r"nothing computed .* call compute\(maps=True\) first"):
            engine.maps()


def test_maps_need_a_compute_that_kept_them(backend):
    with aarecovery.Engine(backend) as engine:
        engine.set_images(*edge_pair())
        engine.compute()
        with pytest.raises(InputError, match=r"kept no maps: call compute\(maps=True\)"):
            engine.maps()
        engine.compute(maps=True)
        assert engine.maps().beta.shape == (20, 24)


def test_a_new_pair_has_no_result_until_computed(backend):
    first, second = edge_pair(1), edge_pair(2)
    with aarecovery.Engine(backend) as engine:
        engine.set_images(*first)
        engine.compute(maps=True)
        engine.set_images(*second)
        for call in (engine.result, engine.maps):
            with pytest.raises(InputError, match="nothing computed"):
                call()
        engine.compute()
        np.testing.assert_array_equal(engine.result(), aarecovery.recover(*second, backend=backend))


def test_released_engine_says_so(backend):
    engine = aarecovery.Engine(backend)
    engine.set_images(*edge_pair())
    engine.compute()
    engine.release()
    engine.release()  # idempotent
    for call in (engine.result, engine.maps, engine.compute, lambda: engine.set_images(*edge_pair())):
        with pytest.raises(InputError, match="this engine was released; create a new aarecovery.Engine"):
            call()


@pytest.mark.gl
def test_gl_map_textures_follow_the_same_states():
    with aarecovery.Engine("gl") as engine:
        engine.set_images(*edge_pair())
        engine.compute()
        with pytest.raises(InputError, match=r"call compute\(maps=True\)"):
            engine.texture("beta")
        engine.compute(maps=True)
        assert engine.texture("beta").channel == 1


# --- D: NumPy scalars ---------------------------------------------------------------------------------


@pytest.mark.parametrize("sigma_d", [np.float32(0.1), np.float64(0.1), 0.1])
@pytest.mark.parametrize("iterations", [np.int64(3), np.int32(3), np.uint8(3), 3])
def test_numpy_scalars_are_accepted(sigma_d, iterations):
    original, filtered = edge_pair()
    expected = aarecovery.recover(original, filtered, backend="numpy")
    got = aarecovery.recover(original, filtered, backend="numpy", sigma_d=sigma_d, sigma_e=np.float32(0.01),
                             iterations=iterations)
    np.testing.assert_array_equal(got, expected)


def test_numpy_scalars_reach_the_engine_and_tiles(backend):
    original, filtered = edge_pair(size=(100, 90))
    with aarecovery.Engine(backend) as engine:
        engine.set_images(original, filtered)
        result = engine.recover(sigma_d=np.float32(0.1), sigma_e=np.float16(0.01), iterations=np.int64(3))
    tiled = aarecovery.recover(original, filtered, backend=backend, tile_size=np.int64(64),
                               sigma_d=np.float32(0.1), sigma_e=np.float16(0.01))
    np.testing.assert_array_equal(tiled, result)


# --- 13: values beyond the declared ranges ------------------------------------------------------------


@pytest.mark.parametrize("name, value", [
    ("sigma_d", 1e308), ("sigma_d", 1e39), ("sigma_d", np.float64(1e39)), ("sigma_e", 1e-320),
    ("sigma_e", np.float32(1e-40)), ("sigma_e", float("inf")), ("sigma_d", float("nan")),
    ("iterations", np.int64(2**40)), ("iterations", 3.0), ("iterations", True), ("sigma_d", "0.1"),
])
def test_values_outside_the_declared_ranges_are_refused(name, value):
    spec = aarecovery.PARAMETERS[name]
    with pytest.raises(InputError) as caught:
        aarecovery.recover(*edge_pair(), backend="numpy", **{name: value})
    message = str(caught.value)
    assert name in message and f"from {spec.minimum:g} to {spec.maximum:g}" in message


@pytest.mark.parametrize("option, value", [("--sigma-d", "1e308"), ("--sigma-d", "1e39"),
                                           ("--sigma-e", "1e-320"), ("--sigma-e", "-0.01"),
                                           ("--iterations", "-1")])
def test_the_command_line_refuses_them_in_one_line(tmp_path, capsys, option, value):
    original, filtered = edge_pair()
    aarecovery.write_image(tmp_path / "o.png", original)
    aarecovery.write_image(tmp_path / "f.png", filtered)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warnings either
        status = main(["recover", str(tmp_path / "o.png"), str(tmp_path / "f.png"), "-o", str(tmp_path / "r.png"),
                       "--backend", "numpy", option, value])
    err = capsys.readouterr().err
    assert status == 1
    assert len(err.splitlines()) == 1 and err.startswith("aarecovery: error: "), err
    assert option.lstrip("-").replace("-", "_") in err
    assert not (tmp_path / "r.png").exists()


def test_a_black_original_under_a_gradient_map_is_recovered():
    # Its analysis once met a singular matrix: a traceback instead of F back.
    original = np.zeros((40, 50, 3), np.float32)
    filtered = aarecovery.filters.apply("gradientmap", original)
    np.testing.assert_array_equal(aarecovery.recover(original, filtered, backend="numpy"), filtered)
