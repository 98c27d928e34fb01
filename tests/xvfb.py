"""A real X server for tests (Xvfb on a free display), or a loud failure in CI where it is missing."""

import os
import shutil
import subprocess
from contextlib import contextmanager

import pytest


def missing(reason):
    """Fail with `reason` where the environment variable CI is set (packaging/test.sh installs
    what the tests need there), else skip with it."""
    if os.environ.get("CI"):
        pytest.fail(reason, pytrace=False)
    pytest.skip(reason)


@contextmanager
def xvfb_server(screen="1400x900x24"):
    """Run Xvfb on a free display number inside the block; yields its name, such as ``":0"``."""
    executable = shutil.which("Xvfb")
    if executable is None:
        missing("Xvfb is not installed: apt-get install xvfb (packaging/test.sh does as root)")
    read_end, write_end = os.pipe()
    # -displayfd: Xvfb picks a free display number and writes it to the pipe once it is ready.
    # -noreset: an X server resets when its last client leaves, and a test connecting during
    # that reset failed with "Failed to open display" (seen in about one run in three).
    server = subprocess.Popen([executable, "-displayfd", str(write_end), "-screen", "0", screen, "-nolisten", "tcp",
                               "-noreset"], pass_fds=(write_end,), stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    os.close(write_end)
    try:
        with os.fdopen(read_end) as pipe:
            number = pipe.readline().strip()
        if not number:
            pytest.fail("Xvfb started but reported no display number")
        yield f":{number}"
    finally:
        server.terminate()
        server.wait(timeout=10)
