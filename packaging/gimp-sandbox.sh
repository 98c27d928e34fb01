#!/bin/sh
# Build or refresh a Debian trixie root in which GIMP 3 runs headless, for the plug-in tests.
#
# Debian 12 ships GIMP 2.10 without Python; trixie ships GIMP 3.0 with Python 3, numpy, Pillow
# and moderngl as Debian packages. The root lives outside the checkout (it is ~1 GB):
#
#     AARECOVERY_GIMP_ROOT   where the root is (default /var/cache/aarecovery/gimp3-trixie)
#     AARECOVERY_GIMP_MIRROR Debian mirror (default http://deb.debian.org/debian)
#
# Usage: sudo packaging/gimp-sandbox.sh [--check | --shell | --remove]
#     (no option)  build the root if it is missing or its package list changed; else quick exit
#     --check      exit 0 if the root is ready, 1 (with the reason) if not; builds nothing
#     --shell      open a shell inside the root (for debugging)
#     --remove     delete the root
#
# Idempotent: a stamp file records the package list the root was built with; a run on a ready
# root only checks the stamp (well under a second). A half-built root is never left behind as
# ready: debootstrap works in ROOT.partial and the stamp is written last. Needs root (chroot,
# mounts); installs debootstrap on the host with apt-get if it is missing and changes nothing
# else on the host.
set -eu

ROOT=${AARECOVERY_GIMP_ROOT:-/var/cache/aarecovery/gimp3-trixie}
MIRROR=${AARECOVERY_GIMP_MIRROR:-http://deb.debian.org/debian}
SUITE=trixie
# libegl1/libgl1 provide libEGL.so.1/libGL.so.1 (glvnd), which glcontext needs next to the
# Mesa drivers; python3-setuptools lets `pip install --no-build-isolation` build the checkout
# offline; xvfb/xauth/x11-apps are for the optional screenshot of the dialog.
PACKAGES="gimp python3-gi gir1.2-gimp-3.0 python3-numpy python3-pil python3-moderngl \
libegl1 libgl1 libegl-mesa0 libgl1-mesa-dri python3-pip python3-setuptools ca-certificates \
xvfb xauth x11-apps"
STAMP="$ROOT/.aarecovery-sandbox"
STAMP_TEXT="suite=$SUITE packages=$PACKAGES"

say() { printf 'gimp-sandbox: %s\n' "$*" >&2; }
die() { say "error: $*"; exit 1; }

ready() {
    [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$STAMP_TEXT" ] && [ -x "$ROOT/usr/bin/gimp-console-3.0" ]
}

MOUNTED=""
unmount_all() {
    # Reverse order, lazily: a process that is still exiting must not leave the host's /dev
    # mounted inside the cache folder.
    for m in $MOUNTED; do umount -l "$m" 2>/dev/null || true; done
    MOUNTED=""
}
mount_all() {
    target=$1
    for d in proc sys dev dev/pts; do
        mkdir -p "$target/$d"
        if ! mountpoint -q "$target/$d"; then
            mount --bind "/$d" "$target/$d"
            MOUNTED="$target/$d $MOUNTED"
        fi
    done
}
in_root() {
    # A clean environment: the host's PATH, locale and proxies variables mean nothing inside.
    target=$1; shift
    chroot "$target" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin \
        LANG=C.UTF-8 DEBIAN_FRONTEND=noninteractive "$@"
}

case "${1:-}" in
    --check)
        if ready; then say "ready: $ROOT"; exit 0; fi
        say "not ready: $ROOT (build it with: sudo packaging/gimp-sandbox.sh)"; exit 1 ;;
    --remove)
        [ "$(id -u)" = 0 ] || die "needs root"
        for d in dev/pts dev sys proc; do umount -l "$ROOT/$d" 2>/dev/null || true; done
        rm -rf "$ROOT" "$ROOT.partial"; say "removed $ROOT"; exit 0 ;;
    --shell)
        [ "$(id -u)" = 0 ] || die "needs root"
        ready || die "the root is not ready; build it first with: sudo $0"
        trap unmount_all EXIT INT TERM
        mount_all "$ROOT"
        in_root "$ROOT" /bin/bash; exit $? ;;
    "") ;;
    *) die "unknown option '$1' (use --check, --shell or --remove)" ;;
esac

if ready; then
    say "ready: $ROOT (nothing to do)"
    exit 0
fi
[ "$(id -u)" = 0 ] || die "building the GIMP 3 root needs root (debootstrap, chroot, mounts); run: sudo $0"

trap unmount_all EXIT INT TERM
start=$(date +%s)

if ! command -v debootstrap >/dev/null 2>&1; then
    say "installing debootstrap on the host"
    # apt-install.sh waits for both of apt's locks (a fresh machine's unattended upgrades
    # hold them) and retries the network, as test.sh's own apt step does.
    bash "$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/apt-install.sh" debootstrap || die "could not install debootstrap"
fi

if [ -x "$ROOT/usr/bin/apt-get" ]; then
    # An existing root whose package list changed: reuse it, only install what is new.
    target=$ROOT
    say "refreshing the packages of $ROOT"
else
    target=$ROOT.partial
    for d in dev/pts dev sys proc; do umount -l "$target/$d" 2>/dev/null || true; done
    rm -rf "$target"
    mkdir -p "$(dirname "$ROOT")"
    say "debootstrap $SUITE into $target (about a minute)"
    debootstrap --variant=minbase "$SUITE" "$target" "$MIRROR" >"$target.log" 2>&1 \
        || { tail -n 20 "$target.log" >&2; die "debootstrap failed; full log: $target.log"; }
fi

# Never start services inside the root.
printf '#!/bin/sh\nexit 101\n' >"$target/usr/sbin/policy-rc.d"
chmod 755 "$target/usr/sbin/policy-rc.d"
# pip inside the root must trust the same CAs as the host (a TLS proxy may sit in between).
mkdir -p "$target/etc/aarecovery"
cp /etc/ssl/certs/ca-certificates.crt "$target/etc/aarecovery/host-ca.crt"

mount_all "$target"
say "installing GIMP 3 and Python packages (about two minutes)"
# shellcheck disable=SC2086
in_root "$target" sh -c "apt-get update -qq && apt-get install -y -qq --no-install-recommends $PACKAGES >/dev/null && apt-get clean" \
    || die "apt-get inside $target failed"

# Check the pieces the tests rely on before calling the root ready.
in_root "$target" gimp-console-3.0 --version >/dev/null || die "gimp-console-3.0 does not start in $target"
in_root "$target" python3 -c "import gi, numpy, moderngl; gi.require_version('Gimp', '3.0')" \
    || die "GIMP's Python lacks gi/numpy/moderngl in $target"
unmount_all

if [ "$target" != "$ROOT" ]; then
    rm -rf "$ROOT"
    mv "$target" "$ROOT"
    mv "$target.log" "$ROOT/.debootstrap.log" 2>/dev/null || true
fi
printf '%s' "$STAMP_TEXT" >"$STAMP"
say "ready: $ROOT ($(( $(date +%s) - start )) s)"
