#!/bin/sh
# The installed lamprig, checked from the package `make deb` built (make test-install; make
# test runs it last): lintian finds no error; the package extracted into a scratch root has
# every file where the unit, the rig config and the binary look for them; systemd-analyze
# accepts the unit; the udev rules parse and grant each supported device to group lamprig;
# the installed binary, outside the source tree and unprivileged, finds its data beside
# itself (every tracked data file under configs/), plans the shipped rig's scene as the source
# tree does, renders the default scene and runs the shipped rig config.
#
# Needs no systemd running and changes nothing on the host: the package is never installed
# (dpkg-deb -x into a temporary root) and no user is created (as root, the binary runs as
# uid/gid 65534 through setpriv; otherwise as the calling user).
# usage: tests/install.sh BUILD_DIR
set -eu
build=$(cd "${1:-build}" && pwd)
src=$(cd "$(dirname "$0")/.." && pwd)
fails=0
passes=0
ok() { echo "  ok    $*"; passes=$((passes + 1)); }
fail() { echo "  FAIL  $*"; fails=$((fails + 1)); }
check() { # check DESCRIPTION COMMAND...
    d=$1
    shift
    if "$@"; then ok "$d"; else fail "$d"; fi
}

deb=$(ls -t "$build"/lamprig_*.deb 2>/dev/null | head -n 1)
[ -n "$deb" ] || { echo "install: no $build/lamprig_*.deb (make deb)"; exit 1; }
echo "== install: $(basename "$deb")"
T=$(mktemp -d /tmp/lamprig-install.XXXXXX)
trap 'rm -rf "$T"' EXIT
chmod 0755 "$T"
R=$T/root

# ---- the package ----
if command -v lintian >/dev/null; then
    lintian --fail-on error --tag-display-limit 0 "$deb" >"$T/lintian.txt" 2>&1 &&
        ok "lintian: no errors ($(grep -c '^W:' "$T/lintian.txt" || true) warnings)" ||
        { cat "$T/lintian.txt"; fail "lintian: errors"; }
else
    fail "lintian not installed (make deps)"
fi
dpkg-deb -x "$deb" "$R"
dpkg-deb -e "$deb" "$T/DEBIAN"
depends=$(dpkg-deb -f "$deb" Depends)
for lib in libsystemd0 libegl1 libgles2 libgpiod2 libhidapi-libusb0 libmodbus5 libmicrohttpd12 libmosquitto1 libegl-mesa0 adduser; do
    case "$depends" in *"$lib"*) ;; *) fail "Depends lacks $lib: $depends" ;; esac
done
ok "Depends names the linked libraries (dpkg-shlibdeps) and the GL drivers"
check "conffiles are the files under /etc" \
    test "$(cat "$T/DEBIAN/conffiles")" = "$(cd "$R" && find etc -type f | sed 's|^|/|' | sort)"
check "postinst creates the user lamprig" grep -q 'adduser --system --group' "$T/DEBIAN/postinst"

# ---- every file where the unit and the rig config expect it ----
unit=$R/lib/systemd/system/lamprig.service
check "unit installed" test -f "$unit"
val() { sed -n "s/^$1=//p" "$unit" | head -n 1; }
exe=$(val ExecStart | cut -d' ' -f1)
cfg=$(val ExecStart | sed -n 's/.*--config \([^ ]*\).*/\1/p')
check "ExecStart binary $exe is in the package, executable" test -x "$R$exe"
check "ExecStart config $cfg is in the package" test -f "$R$cfg"
check "Type=notify with a WatchdogSec" sh -c "grep -qx 'Type=notify' '$unit' && grep -q '^WatchdogSec=[1-9]' '$unit'"
check "Restart=on-failure, User=lamprig" sh -c "grep -qx 'Restart=on-failure' '$unit' && grep -qx 'User=lamprig' '$unit'"
check "WorkingDirectory is the StateDirectory" \
    test "$(val WorkingDirectory)" = "/var/lib/$(val StateDirectory)"
# The rig config's absolute paths (scene, controls, sim script, stats) inside the root.
for p in $(grep -o '"/[^"]*"' "$R$cfg" | tr -d '"'); do
    case "$p" in
    /var/lib/*) check "rig.json state path $p is under the StateDirectory" \
        test "${p#/var/lib/$(val StateDirectory)/}" != "$p" ;;
    *) check "rig.json path $p is in the package" test -f "$R$p" ;;
    esac
done
data=$R${exe%/bin/*}/share/lamprig
for f in configs/materials/candle_wax.json configs/scenes/candle.json configs/bench/front.csv \
    shaders/mesh.vert shaders/lib/optics.glsl; do
    check "data $f beside the binary" test -f "$data/$f"
done
if git -C "$src" rev-parse --git-dir >/dev/null 2>&1; then
    check "every tracked data file under configs/ installed (less bench references, READMEs)" \
        test "$(git -C "$src" ls-files configs | grep -v -e '^configs/bench/references/' -e '\.md$' | sort)" = \
        "$(cd "$data" && find configs -type f | sort)"
fi
check "every shader of the source tree installed" \
    test "$(cd "$src/render/shaders" && find . -type f | sort)" = "$(cd "$data/shaders" && find . -type f | sort)"
check "udev rules installed" test -f "$R/lib/udev/rules.d/60-lamprig.rules"
check "sysusers.d entry" grep -q '^u lamprig ' "$R/usr/lib/sysusers.d/lamprig.conf"
check "man page" test -f "$R/usr/share/man/man1/lamprig.1.gz"
# Discovery: the Avahi service file announces _lamprig._tcp on the port of the shipped
# config's "http.listen" (shipped, not linked into /etc/avahi/services: loopback by default).
check "Avahi service file: _lamprig._tcp on the rig config's HTTP port" python3 -c '
import json, sys, xml.etree.ElementTree as ET
svc = {s.findtext("type"): s.findtext("port") for s in ET.parse(sys.argv[1]).getroot().iter("service")}
port = json.load(open(sys.argv[2]))["http"]["listen"].rsplit(":", 1)[1]
sys.exit(0 if svc.get("_lamprig._tcp") == port and svc.get("_http._tcp") == port else 1)
' "$data/avahi/lamprig.service" "$R$cfg"
check "RestrictAddressFamilies: exactly unix, IPv4, IPv6 (Modbus TCP, HTTP), netlink" \
    grep -qx 'RestrictAddressFamilies=AF_UNIX AF_INET AF_INET6 AF_NETLINK' "$unit"

# ---- systemd-analyze verify ----
if command -v systemd-analyze >/dev/null; then
    # The unit as installed, with its binary and config paths pointed into the scratch root
    # (the host has no /usr/bin/lamprig); the man page is in the package, not on the host.
    mkdir "$T/unit"
    sed -e "s|^ExecStart=$exe|ExecStart=$R$exe|" -e "s| --config $cfg| --config $R$cfg|" \
        "$unit" >"$T/unit/lamprig.service"
    if systemd-analyze verify --man=no "$T/unit/lamprig.service" >"$T/verify.txt" 2>&1 &&
        [ ! -s "$T/verify.txt" ]; then
        ok "systemd-analyze verify: no complaint"
    else
        cat "$T/verify.txt"
        fail "systemd-analyze verify"
    fi
    # The hardening, scored as systemd scores it (offline: no manager runs here). 7.3 MEDIUM
    # before it; the bound leaves room for a new directive's weight, not for a lost one.
    score=$(systemd-analyze security --offline=yes --no-pager "$T/unit/lamprig.service" 2>/dev/null |
        sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p')
    if [ -n "$score" ] && awk -v s="$score" 'BEGIN { exit !(s <= 2.5) }'; then
        ok "systemd-analyze security: exposure $score (at most 2.5)"
    else
        systemd-analyze security --offline=yes --no-pager "$T/unit/lamprig.service" 2>&1 | grep -F '✗' | head -n 20
        fail "systemd-analyze security: exposure '$score' over 2.5"
    fi
    check "DevicePolicy=closed with DeviceAllow= for drm, gpiochip, hidraw, usb_device, serial" sh -c \
        "grep -qx 'DevicePolicy=closed' '$unit' && for c in drm gpiochip hidraw usb_device ttyUSB ttyACM; do grep -qx \"DeviceAllow=char-\$c rw\" '$unit' || exit 1; done"
else
    fail "systemd-analyze not installed (make deps installs systemd)"
fi

# ---- udev rules ----
rules=$R/lib/udev/rules.d/60-lamprig.rules
if command -v udevadm >/dev/null && udevadm verify --help >/dev/null 2>&1; then
    check "udevadm verify" udevadm verify --resolve-names=never "$rules"
fi
# A parser of udev's rule syntax (udev(7)): KEY[{attr}] OP "value" pairs joined by commas,
# known keys and operators, GOTO targets defined; then what the rules must grant.
if awk -f "$src/tests/udev_rules.awk" "$rules" >"$T/udev.txt" 2>&1; then
    ok "udev rules parse ($(cat "$T/udev.txt"))"
else
    cat "$T/udev.txt"
    fail "udev rules parse"
fi
for id in 077d:0410 0b33:0020 0b33:0030 0b33:0010; do
    v=${id%:*} p=${id#*:}
    for sub in usb hidraw; do
        check "udev: $sub $id to group lamprig" grep -Eq \
            "^SUBSYSTEM==\"$sub\".*\{idVendor\}==\"$v\", ATTRS?\{idProduct\}==\"$p\".*GROUP=\"lamprig\"" "$rules"
    done
done
check "udev: gpiochip to group lamprig" grep -Eq '^SUBSYSTEM=="gpio", KERNEL=="gpiochip.*GROUP="lamprig"' "$rules"

# ---- the installed binary, outside the source tree, unprivileged ----
mkdir "$T/cwd" "$T/out"
chmod 0777 "$T/out"
# As root: uid/gid 65534 (nobody), no groups; the source tree under /root is then unreadable
# too, so nothing can come from it.
user=""
[ "$(id -u)" -eq 0 ] && user="setpriv --reuid=65534 --regid=65534 --clear-groups --"
run_installed() {
    # shellcheck disable=SC2086
    (cd "$T/cwd" && env -u LAMPRIG_CONFIGS -u LAMPRIG_SHADERS HOME="$T/out" \
        XDG_CACHE_HOME="$T/out/cache" $user "$@")
}
run_installed "$R$exe" help >"$T/help.txt" 2>&1 || true
check "installed binary finds the installed configs" \
    grep -qx "  configs  $(cd "$data" && pwd -P)/configs" "$T/help.txt"
check "installed binary finds the installed shaders" \
    grep -qx "  shaders  $(cd "$data" && pwd -P)/configs/../shaders" "$T/help.txt"
if run_installed "$R$exe" render --scene "$data/configs/scenes/candle.json" --frames 1 \
    --width 64 --height 48 --no-plan --set render.map_size=32 --set render.gbuffer_size=32 \
    --out "$T/out/candle.png" >"$T/render.txt" 2>&1; then
    # PNG IHDR: width and height, big-endian, at bytes 16..23.
    wh=$(od -An -tu1 -j16 -N8 "$T/out/candle.png" | tr -s ' ' | sed 's/^ //')
    check "installed binary renders candle.json as uid $(run_installed id -u): 64x48 PNG" \
        test "$wh" = "0 0 0 64 0 0 0 48"
else
    cat "$T/render.txt"
    fail "installed binary renders candle.json"
fi
# The planner's tables (front.csv, models.csv) come from beside the installed binary: its plan
# of the shipped rig's scene equals the source tree's, as shipped and with another preset (a
# material change re-plans with the change costs of models.csv).
sed 's/"candle_wax"/"marble"/' "$data/configs/scenes/candle.json" >"$T/out/candle_marble.json"
for scene in "$data/configs/scenes/candle.json" "$T/out/candle_marble.json"; do
    run_installed "$R$exe" plan --scene "$scene" --json >"$T/out/plan_installed.json" \
        2>"$T/out/plan_installed.err" || true
    (cd "$src" && env -u LAMPRIG_CONFIGS "$build/bin/lamprig" plan --scene "$scene" --json) \
        >"$T/plan_source.json" 2>/dev/null || true
    if [ -s "$T/plan_source.json" ] && cmp -s "$T/out/plan_installed.json" "$T/plan_source.json"; then
        ok "installed plan of $(basename "$scene") equals the source tree's"
    else
        cat "$T/out/plan_installed.err"
        diff "$T/out/plan_installed.json" "$T/plan_source.json" | cut -c1-300 | head -n 5
        fail "installed plan of $(basename "$scene") differs from the source tree's"
    fi
done
# The shipped rig config, its /usr paths pointed into the root, stats into a scratch dir, its
# HTTP endpoint on a port of the test plan (8080 may be anyone's on a build machine).
sed -e "s|\"/usr/|\"$R/usr/|g" -e "s|\"/var/lib/lamprig/|\"$T/out/|g" \
    -e 's|"127.0.0.1:8080"|"127.0.0.1:18087"|' "$R$cfg" >"$T/out/rig.json"
run_installed "$R$exe" run --config "$T/out/rig.json" --duration 3 >"$T/run.txt" 2>&1 &
rig=$!
# The page and the status while it runs (the endpoint starts after the first frame).
for _ in $(seq 1 300); do
    curl -s -m 2 -o "$T/page.html" http://127.0.0.1:18087/ 2>/dev/null && break
    sleep 0.1
done
curl -s -m 2 -o "$T/status.json" http://127.0.0.1:18087/api/status 2>/dev/null || true
if wait "$rig" && grep -q '"frames"' "$T/out/stats.json"; then
    ok "installed binary runs the shipped rig config (sim devices, headless) and writes stats"
else
    cat "$T/run.txt"
    fail "installed binary runs the shipped rig config"
fi
check "installed rig serves its page on the config's 127.0.0.1 port" grep -q '<title>lamprig</title>' "$T/page.html"
check "installed rig serves /api/status with its version" \
    grep -q "\"version\": \"$(cat "$src/VERSION")\"" "$T/status.json"

# The suite's closing line: test binaries (tests/run.sh) and these checks together.
echo "install: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
