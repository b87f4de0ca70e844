#!/bin/sh
# Installs the Debian 12 packages lamprig builds, tests and runs with, when any is missing.
# Idempotent and silent when everything is present (`make deps` calls it before every build).
set -eu

# opencv-doc ships OpenCV's sample chessboard photos and OpenCV's own calibration of them
# (examples/data/left*.jpg, left_intrinsics.yml): tests/calib/test_calib_camera.c checks against them.
# libsystemd-dev: sd_notify from the rig loop. lintian and systemd (systemd-analyze verify)
# check `make deb`'s package and unit in tests/install.sh; dpkg-dev comes with build-essential.
PKGS="build-essential pkg-config
libgpiod-dev libhidapi-dev libusb-1.0-0-dev libmodbus-dev
libegl-dev libgles-dev libgbm-dev libdrm-dev libegl-mesa0 libgl1-mesa-dri libgbm1
libopencv-dev libopencv-contrib-dev
opencv-doc
libpng-dev libcairo2-dev liblcms2-dev libcmocka-dev
libsystemd-dev
lintian systemd"

missing=""
for p in $PKGS; do
    # dpkg-query prints "install ok installed" only for a fully installed package.
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    [ "$status" = "install ok installed" ] || missing="$missing $p"
done
[ -z "$missing" ] && exit 0

echo "lamprig deps: installing$missing" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null 2>&1 || { echo "lamprig deps: need root or sudo to install$missing" >&2; exit 1; }
    SUDO=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq >&2
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing >&2
