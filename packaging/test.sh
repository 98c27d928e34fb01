#!/usr/bin/env bash
# Install everything the test suite needs on a fresh Debian machine, then run it.
#
#   bash packaging/test.sh [PYTEST ARGS...]
#
# As root it installs the Debian packages the tests drive for real (Mesa's EGL/llvmpipe for
# the GL backend, Xvfb for the viewer window, gegl and gmic for the eval's peer tools and,
# with imagemagick and the DejaVu fonts, its real-tools suite (imagemagick and gmic also for
# the batch's filter commands), debootstrap for the GIMP 3 sandbox, Krita 5 with PyQt5 for the
# Krita plug-in's tests, about 300 MB) and builds or refreshes
# the GIMP 3 sandbox (a Debian trixie root, cached outside the checkout). Without root it
# installs nothing system-wide and
# says loudly what is missing; the tests that need it then fail in CI or skip with a message.
# The Python side always goes into .venv in the checkout.
set -euo pipefail
cd "$(dirname "$0")/.."

DEBIAN_PACKAGES=(libegl1 libgl1 libegl-mesa0 libgl1-mesa-dri xvfb xauth gegl gmic imagemagick fonts-dejavu-core
                 debootstrap krita python3-pyqt5)

missing=()
for package in "${DEBIAN_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "ok installed" || missing+=("$package")
done
if [ ${#missing[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ]; then
        echo "test.sh: installing ${missing[*]}"
        # Waits for apt's locks (busy right after boot) and retries the network, then one line.
        bash packaging/apt-install.sh "${missing[@]}"
    else
        echo "test.sh: WARNING: not root, so these Debian packages cannot be installed: ${missing[*]}" >&2
        echo "test.sh: WARNING: the tests that need them will fail in CI or be skipped loudly" >&2
    fi
fi

python=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$python" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
# Strict editable mode: the checkout maps three folders into one package (core/, viewer/,
# plugin_gimp/), and only a link tree of the assembled package (build/__editable__.*) lets
# import-linter see aarecovery.viewer and aarecovery.gimp, so that `lint-imports` runs in this
# .venv. A new module needs this line again (it runs on every test.sh).
.venv/bin/python -m pip install -q -e '.[viewer,eval,test]' --config-settings editable_mode=strict

if [ "$(id -u)" = 0 ]; then
    sh packaging/gimp-sandbox.sh
else
    echo "test.sh: WARNING: not root, so the GIMP 3 sandbox cannot be built; GIMP tests will skip loudly" >&2
fi

exec .venv/bin/python -m pytest "$@"
