#!/bin/sh
# Checks an arm64 lamprig package (make deb-arm64 runs it): every file in /usr/bin is an
# aarch64 ELF, and each library it needs (readelf -d NEEDED) belongs to a package its Depends
# names, so installing the .deb on the board brings every library the binaries load.
# The owner of a soname: the arm64 package dpkg knows (dpkg -S), or one of the OpenCV modules
# unpacked under build/arm64/cv/pkg/ (tools/cross/arm64.mk).
# usage: check-deb.sh build/lamprig_VERSION_arm64.deb
set -eu
deb=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
dpkg-deb -x "$deb" "$tmp/root"
[ "$(dpkg-deb -f "$deb" Architecture)" = arm64 ] || { echo "check-deb: $deb is not Architecture: arm64" >&2; exit 1; }
# Depends as bare package names, one a line.
dpkg-deb -f "$deb" Depends | tr ',|' '\n\n' | sed 's/(.*//; s/:.*//; s/ //g' | sort -u > "$tmp/depends"
fail=0
n=0
for b in "$tmp"/root/usr/bin/*; do
    n=$((n + 1))
    if ! file -b "$b" | grep -q 'ELF 64-bit LSB .*ARM aarch64'; then
        echo "check-deb: $(basename "$b") is not an aarch64 ELF: $(file -b "$b")" >&2
        fail=1
        continue
    fi
    for lib in $(readelf -d "$b" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
        owner=$(dpkg -S "/usr/lib/aarch64-linux-gnu/$lib" "/lib/aarch64-linux-gnu/$lib" 2>/dev/null |
            sed -n 's/:arm64: .*//p' | head -n1)
        if [ -z "$owner" ]; then
            for d in build/arm64/cv/pkg/*; do
                [ -e "$d/usr/lib/aarch64-linux-gnu/$lib" ] && owner=$(basename "$d")
            done
        fi
        if [ -z "$owner" ]; then
            echo "check-deb: $(basename "$b") needs $lib, which no arm64 package provides" >&2
            fail=1
        elif ! grep -qx "$owner" "$tmp/depends"; then
            echo "check-deb: $(basename "$b") needs $lib from $owner, not in Depends" >&2
            fail=1
        fi
    done
done
[ "$n" -gt 0 ] || { echo "check-deb: no binaries in /usr/bin" >&2; exit 1; }
[ "$fail" = 0 ] || exit 1
echo "check-deb: $n aarch64 binaries, every NEEDED library in Depends ($(wc -l < "$tmp/depends") packages)"
