#!/bin/bash
# Runs the bench's render and sweep sections on an NVIDIA GPU through its EGL, with the
# libraries packed by pack.sh (our loader and glibc; NVIDIA's EGL vendor library from the
# machine). OUT: where the tables go (default /tmp/lamprig-gpu).
cd "$(dirname "$0")/../../.." || exit 1
OUT=${OUT:-/tmp/lamprig-gpu}; mkdir -p "$OUT"
nvidia-smi -L
NVJ=$(ls /usr/local/nvidia/share/glvnd/egl_vendor.d/*nvidia*.json \
         /usr/share/glvnd/egl_vendor.d/*nvidia*.json 2>/dev/null | head -1)
NVEGL=$(find / -xdev -name 'libEGL_nvidia.so.0' 2>/dev/null | head -1)
[ -n "$NVJ" ] && [ -n "$NVEGL" ] || { echo "no NVIDIA EGL vendor found" >&2; exit 1; }
export __EGL_VENDOR_LIBRARY_FILENAMES=$NVJ
# device: EGL_EXT_platform_device (render/gl/backend_device.c); surfaceless works too there.
export LAMPRIG_EGL_PLATFORM=${LAMPRIG_EGL_PLATFORM:-device}
L=".gpu/lib/ld-linux-x86-64.so.2 --library-path $PWD/.gpu/lib:$(dirname "$NVEGL")"
B=build/bin/lamprig-bench
LRB_RENDER_PARTS=timing timeout 100 $L $B render > "$OUT/render_timing.md"
timeout 300 $L $B sweep > "$OUT/sweep.md"
cp build/bench/summary.md build/bench/results.csv build/bench/pareto.png "$OUT/"
timeout 300 $L $B render > "$OUT/render.md"
