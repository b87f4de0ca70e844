#!/bin/bash
# Runs bench sections on an NVIDIA GPU through its EGL, with the libraries packed by pack.sh
# (our loader and glibc; NVIDIA's EGL vendor library from the machine). Every section's output
# goes to $OUT/log.md (stderr, the progress lines, to $OUT/err.log), then the sweep's
# summary.md, results.csv and pareto.png.
# OUT: where they go (default /tmp/lamprig-gpu). Optional: .gpu/base/lamprig-bench, a build of
# an earlier commit, whose render timing and dimmer sections run beside ours in the same call
# (a before/after on one machine); .gpu/cache, a copy of $XDG_CACHE_HOME/lamprig (the
# translucent-radiosity and receiver-bounce form factors) so that the sweep does not rebuild
# them. LRB_GPU_SWEEP_S: the sweep's time limit (default 200 s; 0 skips it). LRB_GPU_ONLY:
# run only the named sections (e.g. "models").
cd "$(dirname "$0")/../../.." || exit 1
OUT=${OUT:-/tmp/lamprig-gpu}; mkdir -p "$OUT"
LOG=$OUT/log.md ERR=$OUT/err.log
: >"$LOG"; : >"$ERR"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv | tee -a "$LOG"
grep PRETTY_NAME /etc/os-release | tee -a "$LOG"
NVJ=$(ls /usr/local/nvidia/share/glvnd/egl_vendor.d/*nvidia*.json \
         /usr/share/glvnd/egl_vendor.d/*nvidia*.json 2>/dev/null | head -1)
NVEGL=$(find / -xdev -name 'libEGL_nvidia.so.0' 2>/dev/null | head -1)
[ -n "$NVJ" ] && [ -n "$NVEGL" ] || { echo "no NVIDIA EGL vendor found" >&2; exit 1; }
export __EGL_VENDOR_LIBRARY_FILENAMES=$NVJ
# device: EGL_EXT_platform_device (render/gl/backend_device.c); surfaceless works too there.
export LAMPRIG_EGL_PLATFORM=${LAMPRIG_EGL_PLATFORM:-device}
[ -d .gpu/cache ] && export XDG_CACHE_HOME=$PWD/.gpu/cache
L=".gpu/lib/ld-linux-x86-64.so.2 --library-path $PWD/.gpu/lib:$(dirname "$NVEGL")"
B=build/bin/lamprig-bench
BASE=.gpu/base/lamprig-bench

# section NAME LIMIT_S [VAR=VALUE...] PROGRAM ARGS...: one run, its tables into the log.
section() {
    local name=$1 limit=$2; shift 2
    local vars=()
    while [[ $1 == *=* ]]; do vars+=("$1"); shift; done
    echo "== $name ($(date +%T))" | tee -a "$LOG" "$ERR"
    local t0=$SECONDS
    env "${vars[@]}" timeout "$limit" $L "$@" >>"$LOG" 2>>"$ERR"
    echo "rc $? in $((SECONDS - t0)) s" | tee -a "$LOG"
}

# LRB_GPU_ONLY="models ...": only these sections of lamprig-bench (name = its argument),
# 300 s each, then stop.
if [ -n "${LRB_GPU_ONLY:-}" ]; then
    for s in $LRB_GPU_ONLY; do
        section "$s" 300 "$B" "$s"
        cp "build/bench/$s.csv" "$OUT/" 2>/dev/null
    done
    echo "done $(date +%T)" | tee -a "$LOG"
    exit 0
fi

section render_timing 60 LRB_RENDER_PARTS=timing $B render
[ -x $BASE ] && section base_render_timing 60 LRB_RENDER_PARTS=timing $BASE render
section dimmer 60 $B dimmer
[ -x $BASE ] && section base_dimmer 60 $BASE dimmer
section camera_640x480 60 LRB_CAMERA_SIZE=640x480 $B camera
section camera_1280x720 60 LRB_CAMERA_SIZE=1280x720 $B camera
section render_full 90 $B render
if [ "${LRB_GPU_SWEEP_S:-200}" != 0 ]; then
    section sweep "${LRB_GPU_SWEEP_S:-200}" LRB_SWEEP_REF2=cached $B sweep
    cp build/bench/summary.md build/bench/results.csv build/bench/pareto.png "$OUT/" 2>/dev/null
fi
echo "done $(date +%T)" | tee -a "$LOG"
