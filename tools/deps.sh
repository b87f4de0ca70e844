#!/bin/sh
# Installs the Debian 12 packages lamprig builds, tests and runs with, when any is missing.
# Idempotent and silent when everything is present (`make deps` calls it before every build).
set -eu

# opencv-doc ships OpenCV's sample chessboard photos and OpenCV's own calibration of them
# (examples/data/left*.jpg, left_intrinsics.yml): tests/calib/test_calib_camera.c checks against them.
# libsystemd-dev: sd_notify from the rig loop. lintian and systemd (systemd-analyze verify)
# check `make deb`'s package and unit in tests/install.sh; dpkg-dev comes with build-essential.
# libmicrohttpd-dev: the rig's HTTP endpoint (firmware/rig/http.h); curl, chromium,
# chromium-driver and python3: its tests (tests/fw/test_fw_http.c drives the API with curl,
# the page in headless chromium through chromedriver's WebDriver protocol from
# tests/fw/http_browser.py, python3's standard library only).
# systemd-container (systemd-nspawn) and debootstrap boot the package under systemd in
# tests/boot.sh (make test-boot).
# libmosquitto-dev: the rig's MQTT client (firmware/rig/mqtt.c, lamprig mqtt-send); mosquitto:
# the broker test_fw_mqtt starts (its network namespaces and veth pair: iproute2, below);
# clang: `make fuzz` (libFuzzer harnesses in tests/fuzz/).
# liblo-dev: the OSC input (hal/osc.c). The console peers the tests start: liblo-tools
# (oscsend), ola (olad, ola_set_dmx, ola_streaming_client), qlcplus; iproute2 (ip netns, veth)
# for the namespace OLA's E1.31 output needs.
PKGS="build-essential pkg-config
libgpiod-dev libhidapi-dev libusb-1.0-0-dev libmodbus-dev
libegl-dev libgles-dev libgbm-dev libdrm-dev libegl-mesa0 libgl1-mesa-dri libgbm1
libopencv-dev libopencv-contrib-dev
opencv-doc
libpng-dev libcairo2-dev liblcms2-dev libcmocka-dev
libsystemd-dev
libmicrohttpd-dev curl chromium chromium-driver python3
libmosquitto-dev mosquitto clang
lintian systemd
systemd-container debootstrap
liblo-dev liblo-tools ola qlcplus iproute2"

# `tools/deps.sh arm64` (make deb-arm64, make test-arm64 only; a native make never installs
# these): Debian's cross toolchain, the arm64 multiarch -dev packages of PKGS' libraries,
# qemu-user-static (test-arm64 runs the arm64 tests under qemu-aarch64-static) and the arm64
# Mesa drivers the arm64 binaries load. OpenCV: only the modules whose arm64 -dev package can
# sit beside the native libopencv-dev (core, imgproc, flann, photo); the other five are
# unpacked, not installed (tools/cross/arm64.mk says why). Needs `dpkg --add-architecture arm64`.
ARM64_PKGS="crossbuild-essential-arm64 qemu-user-static
libgpiod-dev:arm64 libhidapi-dev:arm64 libusb-1.0-0-dev:arm64 libmodbus-dev:arm64
libegl-dev:arm64 libgles-dev:arm64 libgbm-dev:arm64 libdrm-dev:arm64
libegl-mesa0:arm64 libgl1-mesa-dri:arm64 libgbm1:arm64
libpng-dev:arm64 libcairo2-dev:arm64 liblcms2-dev:arm64 libcmocka-dev:arm64
libsystemd-dev:arm64 liblo7:arm64 libmicrohttpd-dev:arm64 libmosquitto-dev:arm64
libopencv-core-dev:arm64 libopencv-imgproc-dev:arm64 libopencv-flann-dev:arm64 libopencv-photo-dev:arm64"
# liblo-dev is not Multi-Arch: same either: its headers are the native package's (the same on
# both 64-bit little-endian ABIs) and tools/cross/arm64.mk links liblo.so.7 by name.
if [ "${1:-}" = arm64 ]; then
    PKGS=$ARM64_PKGS
    if ! dpkg --print-foreign-architectures | grep -qx arm64; then
        [ "$(id -u)" -eq 0 ] && dpkg --add-architecture arm64 || {
            echo "lamprig deps: run 'dpkg --add-architecture arm64' as root first" >&2; exit 1; }
    fi
fi

native=$(dpkg --print-architecture)
missing=""
for p in $PKGS; do
    # dpkg-query prints "install ok installed" only for a fully installed package. With a
    # foreign architecture added (make deb-arm64) an unqualified name matches every installed
    # architecture: only the native one (or all) counts, so an arm64 copy never stands in
    # for the native package and two copies never read as a missing one.
    case $p in
        *:*) ok=$(dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -cx 'install ok installed' || true) ;;
        *) ok=$(dpkg-query -W -f='${Architecture} ${Status}\n' "$p" 2>/dev/null |
               grep -cE "^($native|all) install ok installed\$" || true) ;;
    esac
    [ "${ok:-0}" -gt 0 ] || missing="$missing $p"
done
[ -z "$missing" ] && exit 0

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    if ! command -v sudo >/dev/null 2>&1; then
        echo "lamprig deps: these Debian packages are missing:$missing" >&2
        echo "lamprig deps: install them as root (no sudo here): su -c 'sh $(cd "$(dirname "$0")" && pwd)/$(basename "$0")'" >&2
        exit 1
    fi
    SUDO=sudo
fi
export DEBIAN_FRONTEND=noninteractive
echo "lamprig deps: missing:$missing" >&2
echo "lamprig deps: apt-get update ..." >&2
$SUDO apt-get update -qq >&2
# What apt will do (the packages with their dependencies, the download), before it does it:
# a fresh Debian 12 gets several hundred packages and some minutes. -s only simulates;
# --print-uris lists what would be fetched with its size.
# shellcheck disable=SC2086
plan=$($SUDO apt-get -s install --no-install-recommends $missing 2>/dev/null | sed -n 's/^\(.*newly installed\).*/\1/p' || true)
# shellcheck disable=SC2086
mb=$($SUDO apt-get --print-uris -qq install --no-install-recommends $missing 2>/dev/null |
    awk '{ s += $3 } END { printf "%.1f", s / 1e6 }')
[ -n "$plan" ] && echo "lamprig deps: $plan, about $mb MB to download" >&2
echo "lamprig deps: installing (apt's progress below) ..." >&2
# -q: one line per package fetched and set up, so a long install shows how far it is.
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends -o Dpkg::Use-Pty=0 $missing >&2
echo "lamprig deps: done" >&2
