#!/usr/bin/env bash
# Install Debian packages patiently, then fail in one line: the apt step of test.sh.
#
#   bash packaging/apt-install.sh PACKAGE...
#
# Right after a machine boots, unattended-upgrades or cloud-init often hold apt's locks for a
# minute or more, and a plain apt-get then exits 100 at once. Here:
# * the dpkg lock is waited for by apt itself (DPkg::Lock::Timeout);
# * the package lists' lock, which apt-get update does not wait for (apt 2.6), is retried
#   until the same timeout has passed;
# * a network failure is retried a few times, with growing pauses;
# * what still fails ends in one line naming the step and apt's own last error.
#
# AARECOVERY_APT_LOCK_TIMEOUT (seconds, default 600) and AARECOVERY_APT_ATTEMPTS (default 4)
# change the patience.
set -uo pipefail

lock_timeout=${AARECOVERY_APT_LOCK_TIMEOUT:-600}
attempts=${AARECOVERY_APT_ATTEMPTS:-4}
export DEBIAN_FRONTEND=noninteractive

# retry STEP COMMAND...: run COMMAND until it succeeds. Waiting for a lock held by another
# process does not use up an attempt, until lock_timeout seconds have passed.
retry() {
    local step=$1
    shift
    local log attempt=1 started=$SECONDS last
    log=$(mktemp)
    while ! "$@" >"$log" 2>&1; do
        last=$(grep -E '^(E|Err):' "$log" | tail -n 1)
        [ -n "$last" ] || last=$(tail -n 1 "$log")
        if grep -q "Could not get lock" "$log"; then
            if [ $((SECONDS - started)) -lt "$lock_timeout" ]; then
                sleep 2
                continue
            fi
            # The line that names the lock and the process holding it.
            last="$(grep -m 1 "Could not get lock" "$log") (waited $((SECONDS - started)) s; set"
            last="$last AARECOVERY_APT_LOCK_TIMEOUT to wait longer)"
        elif [ "$attempt" -lt "$attempts" ]; then
            sleep $((attempt * 5))
            attempt=$((attempt + 1))
            continue
        fi
        echo "apt-install.sh: error: $step failed (attempt $attempt of $attempts): $last" >&2
        rm -f "$log"
        return 1
    done
    rm -f "$log"
}

apt_get() {
    apt-get -o DPkg::Lock::Timeout="$lock_timeout" "$@"
}

retry "apt-get update" apt_get update -qq || exit 1
retry "apt-get install $*" apt_get install -y -qq --no-install-recommends "$@" || exit 1
