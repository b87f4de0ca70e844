#!/bin/sh
# The packaged service under a booted systemd (make test-boot; .ci/run runs it after make test):
# a Debian 12 root made by debootstrap, `make deb`'s package installed in it by apt (so its
# Depends are what pulls the libraries in), booted with systemd-nspawn --boot. Checks that the
# hardened unit (tools/install/lamprig.service.in) starts under its sandbox, that the rig renders
# (the frame count in its STATUS= line grows), that `systemctl reload` reloads it in place (same
# main PID, the reload counted, frames going on), that the watchdog never restarted it, that
# `systemd-analyze security` scores it at most 2.5 and that `systemctl stop` ends it cleanly.
#
# Needs root, systemd-nspawn (systemd-container) and debootstrap (make deps installs both), and
# the Debian mirror the host's apt uses. The base root is made once and kept in
# $LAMPRIG_BOOT_CACHE (default /var/cache/lamprig-boot); each run boots a fresh copy of it.
# What nspawn cannot show: the real devices (DeviceAllow= for /dev/dri, gpiochip, hidraw, serial
# ports are accepted by systemd here, but no such device exists in the container), KMS output,
# and the timing of a real board. --keep-unit everywhere: nspawn runs in the caller's own
# cgroup, since CI machines have no systemd of their own to create a scope on (without it
# nspawn fails with "Failed to open system bus"); where /run is not a tmpfs nspawn complains
# that it will not remove /run/systemd/nspawn/propagate/root, which is harmless.
# usage: tests/boot.sh BUILD_DIR
set -eu
build=$(cd "${1:-build}" && pwd)
cache=${LAMPRIG_BOOT_CACHE:-/var/cache/lamprig-boot}
fails=0
passes=0
ok() { echo "  ok    $*"; passes=$((passes + 1)); }
fail() { echo "  FAIL  $*"; fails=$((fails + 1)); }

[ "$(id -u)" -eq 0 ] || { echo "boot: needs root (systemd-nspawn)"; exit 1; }
for t in systemd-nspawn debootstrap nsenter; do
    command -v "$t" >/dev/null || { echo "boot: $t is missing (make deps installs it)"; exit 1; }
done
deb=$(ls -t "$build"/lamprig_*.deb 2>/dev/null | head -n 1)
[ -n "$deb" ] || { echo "boot: no $build/lamprig_*.deb (make deb)"; exit 1; }
echo "== boot: $(basename "$deb") under systemd-nspawn --boot"

# ---- the base root, made once ----
mirror=$(sed -n 's/^URIs: *\(http[^ ]*debian\)$/\1/p' /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n 1)
[ -n "$mirror" ] || mirror=$(sed -n 's/^deb  *\(http[^ ]*\)  *bookworm .*/\1/p' /etc/apt/sources.list 2>/dev/null | head -n 1)
[ -n "$mirror" ] || mirror=http://deb.debian.org/debian
if [ ! -f "$cache/base/.complete" ]; then
    echo "boot: debootstrap bookworm from $mirror into $cache/base (once; a few minutes) ..." >&2
    rm -rf "$cache/base.tmp"
    mkdir -p "$cache"
    t0=$(date +%s)
    debootstrap --variant=minbase --include=systemd,systemd-sysv,dbus bookworm \
        "$cache/base.tmp" "$mirror" >"$cache/debootstrap.log" 2>&1 ||
        { tail -n 20 "$cache/debootstrap.log"; echo "boot: debootstrap failed"; exit 1; }
    touch "$cache/base.tmp/.complete"
    mv "$cache/base.tmp" "$cache/base"
    echo "boot: base root made in $(( $(date +%s) - t0 )) s" >&2
fi

T=$(mktemp -d /var/tmp/lamprig-boot.XXXXXX)
R=$T/root
nspawn_pid=""
cleanup() {
    [ -n "$nspawn_pid" ] && kill "$nspawn_pid" 2>/dev/null && wait "$nspawn_pid" 2>/dev/null
    rm -rf "$T"
}
trap cleanup EXIT
cp -a "$cache/base" "$R"

# ---- the package, installed by apt inside the root ----
# (nspawn mounts a fresh tmpfs on the container's /tmp)
cp "$deb" "$R/var/tmp/lamprig.deb"
t0=$(date +%s)
if systemd-nspawn -q --register=no --keep-unit -D "$R" --pipe sh -c \
    'apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends /var/tmp/lamprig.deb' \
    >"$T/apt.log" 2>&1; then
    ok "apt installs the package and its Depends in a bare Debian 12 root ($(( $(date +%s) - t0 )) s)"
else
    tail -n 30 "$T/apt.log"
    fail "apt install of the package"
    exit 1
fi
# The package leaves the service to the admin, as Debian does for a daemon that drives a
# projector: enable it for the boot.
systemd-nspawn -q --register=no --keep-unit -D "$R" --pipe systemctl enable lamprig.service >"$T/enable.log" 2>&1 &&
    ok "systemctl enable lamprig" || { cat "$T/enable.log"; fail "systemctl enable lamprig"; }

# ---- boot ----
systemd-nspawn -q --register=no --keep-unit -D "$R" --boot >"$T/console.log" 2>&1 </dev/null &
nspawn_pid=$!
leader=""
i=0
while [ $i -lt 100 ] && [ -z "$leader" ]; do
    leader=$(pgrep -P "$nspawn_pid" | head -n 1 || true)
    sleep 0.2
    i=$((i + 1))
done
[ -n "$leader" ] || { cat "$T/console.log"; echo "boot: the container did not start"; exit 1; }
# The first child seen may be a short-lived helper of nspawn's, gone once the container's
# init runs (then every nsenter failed with "cannot open /proc/PID/ns/ipc"): look again.
inside() {
    kill -0 "$leader" 2>/dev/null || leader=$(pgrep -P "$nspawn_pid" | head -n 1 || true)
    nsenter -t "$leader" -m -u -i -n -p -- "$@"
}
state=""
i=0
while [ $i -lt 120 ]; do
    state=$(inside systemctl is-system-running 2>/dev/null || true)
    case $state in running | degraded) break ;; esac
    sleep 0.5
    i=$((i + 1))
done
ok "booted: system $state"
[ "$state" = degraded ] && inside systemctl --failed --no-legend --plain | sed 's/^/        failed unit (not ours): /'

prop() { inside systemctl show -p "$1" --value lamprig.service; }
frames() { prop StatusText | sed -n 's/.* \([0-9][0-9]*\) frames,.*/\1/p'; }
# The rig refreshes its STATUS= line with the watchdog's ping (every WatchdogSec/2): wait up
# to 40 s for the frame count to pass $1; prints the count seen last.
frames_after() {
    j=0
    n=$(frames)
    while [ $j -lt 80 ] && { [ -z "$n" ] || [ "$n" -le "$1" ]; }; do
        sleep 0.5
        j=$((j + 1))
        n=$(frames)
    done
    echo "$n"
}
i=0
while [ $i -lt 120 ] && [ "$(prop ActiveState)" != active ]; do sleep 0.5; i=$((i + 1)); done
if [ "$(prop ActiveState)" = active ]; then
    ok "lamprig.service active (Type=notify: the rig said READY=1) under User=$(prop User)"
else
    inside journalctl -u lamprig --no-pager | tail -n 30
    fail "lamprig.service is $(prop ActiveState) ($(prop Result))"
fi
pid0=$(prop MainPID)

# ---- it renders ----
f0=$(frames)
t0=$(date +%s)
f1=$(frames_after "${f0:-0}")
if [ -n "$f0" ] && [ -n "$f1" ] && [ "$f1" -gt "$f0" ]; then
    ok "renders: $f0 -> $f1 frames in $(( $(date +%s) - t0 )) s ($(prop StatusText))"
else
    inside journalctl -u lamprig --no-pager | tail -n 30
    fail "no frames: '$f0' -> '$f1' ($(prop StatusText))"
fi

# ---- the page, under the unit's sandbox (RestrictAddressFamilies, the system-call filter) ----
# The container shares the host's network, so the service listens on 127.0.0.1:8080 there;
# the container's bash speaks the request (a minbase root has no curl).
i=0
page=""
while [ $i -lt 40 ]; do
    page=$(inside bash -c 'exec 3<>/dev/tcp/127.0.0.1/8080 &&
        printf "GET /api/status HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n" >&3 && cat <&3' 2>/dev/null || true)
    case $page in *" 200 "*'"version"'*) break ;; esac
    sleep 0.5
    i=$((i + 1))
done
case $page in
*" 200 "*'"version"'*) ok "serves GET /api/status on 127.0.0.1:8080 under the unit's sandbox" ;;
*) inside journalctl -u lamprig --no-pager | grep -i http | tail -n 5
   fail "no /api/status on 127.0.0.1:8080 ('$(echo "$page" | head -n 1)')" ;;
esac

# ---- reload ----
if inside systemctl reload lamprig.service; then
    i=0
    while [ $i -lt 60 ]; do
        case $(prop StatusText) in *" 1 reloads"*) break ;; esac
        sleep 0.5
        i=$((i + 1))
    done
    status=$(prop StatusText)
    case $status in
    *" 1 reloads (0 failed)"*) ok "systemctl reload: reloaded in place ($status)" ;;
    *) fail "systemctl reload: not counted ($status)" ;;
    esac
else
    fail "systemctl reload failed"
fi
[ "$(prop MainPID)" = "$pid0" ] && ok "same main PID $pid0 after the reload" ||
    fail "main PID changed: $pid0 -> $(prop MainPID)"
f2=$(frames)
f3=$(frames_after "${f2:-0}")
[ -n "$f2" ] && [ -n "$f3" ] && [ "$f3" -gt "$f2" ] && ok "renders after the reload: $f2 -> $f3 frames" ||
    fail "no frames after the reload: '$f2' -> '$f3'"
[ "$(prop NRestarts)" = 0 ] && ok "never restarted (watchdog WatchdogSec=$(prop WatchdogUSec))" ||
    fail "restarted $(prop NRestarts) times"
inside test -s /var/lib/lamprig/stats.json && ok "stats written to /var/lib/lamprig/stats.json (StateDirectory)" ||
    fail "no /var/lib/lamprig/stats.json"

# ---- the sandbox's score, on the booted system ----
score=$(inside systemd-analyze security --no-pager lamprig.service 2>/dev/null |
    sed -n 's/.*Overall exposure level for lamprig.service: \([0-9.]*\).*/\1/p')
if [ -n "$score" ] && awk -v s="$score" 'BEGIN { exit !(s <= 2.5) }'; then
    ok "systemd-analyze security lamprig.service: $score (at most 2.5)"
else
    fail "systemd-analyze security: '$score'"
fi
if inside journalctl -u lamprig --no-pager -o cat | grep -E -i 'denied|operation not permitted|seccomp' >"$T/denied.txt"; then
    sed 's/^/        /' "$T/denied.txt" | head -n 10
    fail "the journal shows the sandbox refusing the rig something"
else
    ok "no permission or seccomp refusal in the journal"
fi

# ---- stop ----
inside systemctl stop lamprig.service
[ "$(prop Result)" = success ] && [ "$(prop ActiveState)" = inactive ] &&
    ok "systemctl stop: ended cleanly (Result=success)" ||
    fail "stop: $(prop ActiveState) $(prop Result)"
inside journalctl -u lamprig --no-pager -o cat >"$T/journal.txt" 2>&1 || true
echo "   the service's journal, last lines:"
tail -n 8 "$T/journal.txt" | sed 's/^/        /'
inside systemctl poweroff >/dev/null 2>&1 || true
i=0
while [ $i -lt 100 ] && kill -0 "$nspawn_pid" 2>/dev/null; do sleep 0.2; i=$((i + 1)); done

echo "boot: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
