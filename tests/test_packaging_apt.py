"""packaging/apt-install.sh, test.sh's apt step, against apt's real locks held by another process.

apt takes POSIX record locks (fcntl), so the holder below takes those too (``flock`` would
not block apt). The package asked for is one every Debian has, so nothing is installed;
``apt-get update`` runs for real.
"""

import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parent.parent / "packaging" / "apt-install.sh"
LOCKS = ("/var/lib/apt/lists/lock", "/var/lib/dpkg/lock-frontend")

_HOLDER = textwrap.dedent("""
    import fcntl, os, sys, time
    descriptors = [os.open(path, os.O_RDWR | os.O_CREAT) for path in sys.argv[2:]]
    for descriptor in descriptors:
        fcntl.lockf(descriptor, fcntl.LOCK_EX)
    print("held", flush=True)
    time.sleep(float(sys.argv[1]))
""")


@pytest.fixture(autouse=True)
def _root_and_apt():
    if os.geteuid() != 0 or shutil.which("apt-get") is None:
        message = "the apt lock tests need root and apt-get (CI runs as root on Debian)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip("APT TESTS NOT RUN: " + message)


def run_script_while_locked(hold_seconds, lock_timeout):
    """Run the script while another process holds apt's locks for `hold_seconds`."""
    holder = subprocess.Popen([sys.executable, "-c", _HOLDER, str(hold_seconds), *LOCKS], stdout=subprocess.PIPE,
                              text=True)
    try:
        assert holder.stdout.readline() == "held\n"
        env = {**os.environ, "AARECOVERY_APT_LOCK_TIMEOUT": str(lock_timeout), "AARECOVERY_APT_ATTEMPTS": "2"}
        start = time.monotonic()
        done = subprocess.run(["bash", str(SCRIPT), "coreutils"], capture_output=True, text=True, timeout=600,
                              env=env)
        return done, time.monotonic() - start
    finally:
        holder.kill()
        holder.wait()


def test_waits_for_locks_another_apt_holds():
    done, seconds = run_script_while_locked(4, lock_timeout=120)
    assert done.returncode == 0, done.stderr
    assert seconds >= 3.5


def test_a_lock_held_too_long_fails_in_one_line():
    done, seconds = run_script_while_locked(60, lock_timeout=3)
    assert done.returncode == 1
    (line,) = done.stderr.splitlines()
    assert line.startswith("apt-install.sh: error: apt-get update failed")
    assert "Could not get lock" in line and "AARECOVERY_APT_LOCK_TIMEOUT" in line
    assert seconds < 30


def test_test_sh_uses_it():
    text = (SCRIPT.parent / "test.sh").read_text()
    assert 'bash packaging/apt-install.sh "${missing[@]}"' in text
    assert "apt-get update" not in text


def test_gimp_sandbox_uses_it_on_the_host():
    # The host's apt runs only to get debootstrap; it must be as patient as test.sh's.
    text = (SCRIPT.parent / "gimp-sandbox.sh").read_text()
    assert "apt-install.sh\" debootstrap" in text
    assert "apt-get -o DPkg::Lock::Timeout=600 update" not in text
