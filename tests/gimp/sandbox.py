"""Run commands inside the Debian trixie root that packaging/gimp-sandbox.sh builds.

The tests drive the real GIMP 3 (``gimp-console-3.0``) there. The checkout is installed into
the root twice, from one wheel built from a copy of the working tree:

``/opt/aarecovery/site``
    ``pip install --target``; on ``PYTHONPATH`` only for the in-process runs, so that GIMP's
    own Python imports the core.
``/opt/aarecovery/venv``
    a venv over Debian's numpy/moderngl (``--system-site-packages``) with aarecovery in it:
    the "configured Python" of the out-of-process runs, where GIMP's Python cannot import it,
    and the Python that installs the bundled plug-in (its pip fetches the wheels: ``pip_env``).
"""

import os
import shutil
import subprocess
import time
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[2]
ROOT = Path(os.environ.get("AARECOVERY_GIMP_ROOT", "/var/cache/aarecovery/gimp3-trixie"))
SANDBOX_SCRIPT = CHECKOUT / "packaging" / "gimp-sandbox.sh"
BUILD_HINT = f"sudo {SANDBOX_SCRIPT.relative_to(CHECKOUT)}"
SITE = "/opt/aarecovery/site"
VENV = "/opt/aarecovery/venv"
VENV_PYTHON = f"{VENV}/bin/python"
# pip inside the root trusts the host's CA bundle (a TLS proxy may sit in between).
PIP_ENV = {"PIP_CERT": "/etc/aarecovery/host-ca.crt"}
# The bundle's wheels, kept between runs inside the cached root: later runs fetch only what is
# new. (pip's own HTTP cache is no help where an index serves its files as uncacheable.)
WHEEL_CACHE = "/var/cache/aarecovery/gimp-bundle-wheels"
# The host's index and proxy settings, passed through where set (a CI mirror, say).
PIP_HOST_SETTINGS = ("PIP_INDEX_URL", "HTTPS_PROXY", "https_proxy", "HTTP_PROXY", "http_proxy",
                     "NO_PROXY", "no_proxy")


def pip_env():
    """The environment for running pip inside the root with this machine's registry access."""
    return {**PIP_ENV, **{k: os.environ[k] for k in PIP_HOST_SETTINGS if os.environ.get(k)}}


def missing_piece():
    """Why the GIMP tests cannot run here, or None when they can."""
    if os.name != "posix" or not hasattr(os, "geteuid"):
        return "the GIMP 3 sandbox needs Linux"
    if os.geteuid() != 0:
        return "the GIMP 3 sandbox needs root (chroot and bind mounts); run the tests as root"
    stamp = ROOT / ".aarecovery-sandbox"
    if not stamp.is_file() or not (ROOT / "usr/bin/gimp-console-3.0").is_file():
        return f"no GIMP 3 root at {ROOT} (set AARECOVERY_GIMP_ROOT to use another)"
    return None


class Sandbox:
    """The trixie root with /proc, /sys, /dev mounted for the lifetime of this object."""

    def __init__(self, root=ROOT):
        self.root = Path(root)
        self._mounted = []

    def __enter__(self):
        for d in ("proc", "sys", "dev", "dev/pts"):
            target = self.root / d
            target.mkdir(parents=True, exist_ok=True)
            if not os.path.ismount(target):
                subprocess.run(["mount", "--bind", f"/{d}", str(target)], check=True)
                self._mounted.append(target)
        return self

    def __exit__(self, *exc):
        for target in reversed(self._mounted):
            subprocess.run(["umount", "-l", str(target)], check=False)
        self._mounted.clear()

    def host_path(self, inside):
        """The host path of a path inside the root."""
        return self.root / str(inside).lstrip("/")

    def run(self, argv, env=None, timeout=300, check=True, input=None):
        """Run `argv` inside the root with a clean environment plus `env`."""
        base = {"HOME": "/root", "PATH": "/usr/sbin:/usr/bin:/sbin:/bin", "LANG": "C.UTF-8"}
        base.update(env or {})
        cmd = ["chroot", str(self.root), "/usr/bin/env", "-i",
               *[f"{k}={v}" for k, v in base.items()], *argv]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, input=input)
        if check and proc.returncode != 0:
            raise RuntimeError(f"{' '.join(argv)} exited {proc.returncode} in {self.root}:\n"
                               f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
        return proc

    def install_checkout(self):
        """Install this working tree into the root (site dir and venv); return seconds taken."""
        start = time.monotonic()
        src = self.host_path("/opt/aarecovery/src")
        shutil.rmtree(self.host_path("/opt/aarecovery"), ignore_errors=True)
        # Only the files git would ship (tracked + untracked-not-ignored): no .venv, no .git.
        listed = subprocess.run(["git", "-C", str(CHECKOUT), "ls-files", "-z", "-co",
                                 "--exclude-standard"], capture_output=True, check=True).stdout
        for rel in filter(None, listed.decode().split("\0")):
            source = CHECKOUT / rel
            if source.is_file():
                dest = src / rel
                dest.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(source, dest)
        pip = ["python3", "-m", "pip", "--disable-pip-version-check", "-q"]
        # Offline and without build isolation: Debian's setuptools builds the pure-Python wheel.
        self.run([*pip, "wheel", "--no-deps", "--no-build-isolation", "--no-index",
                  "-w", "/opt/aarecovery/wheels", "/opt/aarecovery/src"])
        wheel = next(self.host_path("/opt/aarecovery/wheels").glob("aarecovery-*.whl")).name
        self.run([*pip, "install", "--no-deps", "--no-index", "--break-system-packages",
                  "--target", SITE, f"/opt/aarecovery/wheels/{wheel}"])
        self.run(["python3", "-m", "venv", "--system-site-packages", "--without-pip", VENV])
        self.run([*pip, "--python", VENV_PYTHON, "install", "--no-deps", "--no-index",
                  f"/opt/aarecovery/wheels/{wheel}"])
        return time.monotonic() - start

    def gimp_batch(self, script_inside, env, timeout=300):
        """Run a Python file inside ``gimp-console-3.0`` batch mode; return the process."""
        code = f"exec(open({str(script_inside)!r}).read())"
        return self.run(["gimp-console-3.0", "-i", "-n", "--batch-interpreter=python-fu-eval",
                         "-b", code, "--quit"], env=env, timeout=timeout, check=False)
