"""Out of memory, for real: the command runs under an address-space limit a little above what
it holds before it starts, and must say in one line what the image needs and what to do."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from aarecovery import write_image

# Runs `aarecovery ARGS` in a process whose address space may grow by only HEADROOM_MB once
# NumPy's BLAS (and, for GL, the driver) has taken what it takes up front: a native library
# that fails its own allocation exits on the spot (OpenBLAS), which no message can follow.
_LIMITED = textwrap.dedent("""
    import resource, sys
    import numpy as np
    from aarecovery.cli import main
    from aarecovery.engine import Engine

    headroom, args = int(sys.argv[1]) * 10**6, sys.argv[2:]
    np.linalg.solve(np.eye(30) + 1, np.ones(30))
    if "gl" in args:
        Engine("gl").release()
    with open("/proc/self/status") as status:
        size = next(int(line.split()[1]) * 1024 for line in status if line.startswith("VmSize:"))
    resource.setrlimit(resource.RLIMIT_AS, (size + headroom, size + headroom))
    sys.exit(main(args))
""")


def run_limited(headroom_mb, *args):
    # One malloc arena: each thread's own arena (the two decoding threads) would otherwise
    # reserve 64 MB of address space, a figure that depends on the machine's cores.
    return subprocess.run([sys.executable, "-c", _LIMITED, str(headroom_mb), *map(str, args)],
                          capture_output=True, text=True, timeout=300, env={**os.environ, "MALLOC_ARENA_MAX": "1"})


@pytest.fixture(scope="module")
def large_pair(tmp_path_factory):
    """A 4096 x 4096 RGB pair as .npy files: 50 MB per image."""
    folder = tmp_path_factory.mktemp("large")
    original = np.random.default_rng(0).integers(0, 256, (4096, 4096, 3), dtype=np.uint8)
    np.save(folder / "o.npy", original)
    np.save(folder / "f.npy", np.where(original > 127, 255, 0).astype(np.uint8))
    return folder


def one_line(done):
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.splitlines()
    assert line.startswith("aarecovery: error: not enough memory to ")
    return line


def test_recovery_out_of_memory_says_what_it_needs(large_pair, tmp_path, backend):
    # Room for reading the pair (100 MB) but not for R and a tile beside it (the GL driver
    # fails on a texture or a framebuffer made when a pass first needs it). GL needs room for
    # llvmpipe to compile the fit pass before that: LLVM cannot fail an allocation, it
    # crashes. At 225 MB the fit with the best pair's search (spec.blend_model.best_pair)
    # crashed there in about half the runs; at 275 MB the recovery completes.
    done = run_limited(150 if backend == "numpy" else 250, "recover", large_pair / "o.npy", large_pair / "f.npy",
                       "-o", tmp_path / "r.npy", "--backend", backend)
    line = one_line(done)
    assert f"recover this 4096x4096 pair on the {backend} backend" in line
    assert "it needs about" in line and "151 MB for the whole images" in line
    if backend == "gl":
        assert "--tile-size 512" in line and "--backend numpy" in line
    assert list(tmp_path.iterdir()) == []


def test_decoding_out_of_memory_does_not_blame_the_file(tmp_path):
    noise = np.random.default_rng(1).integers(0, 256, (2048, 2048, 3), dtype=np.uint8)  # 12.6 MB decoded
    write_image(tmp_path / "noise.png", noise)
    done = run_limited(4, "filter", "gamma", tmp_path / "noise.png", "-o", tmp_path / "out.png")
    line = one_line(done)
    assert "decode" in line and "noise.png" in line and "is the file complete" not in line


def test_out_of_memory_advice_names_only_options_the_command_has(tmp_path):
    # The filter itself (a float copy of the image) runs out: no tiles, no recovery backend.
    noise = np.random.default_rng(1).integers(0, 256, (2048, 2048, 3), dtype=np.uint8)
    write_image(tmp_path / "noise.png", noise)
    done = run_limited(30, "filter", "gamma", tmp_path / "noise.png", "-o", tmp_path / "out.png")
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.splitlines()
    assert "--tile-size" not in line and "--backend" not in line and "more memory" in line
