#!/bin/sh
# Packs lamprig-bench's shared libraries (the Debian 12 glibc and loader included) into
# .gpu/lib (9 MB), for a GPU machine whose system is another distribution (the figures in this
# folder came from an Ubuntu 24.04 image with NVIDIA's EGL). Run from the repository root after
# `make`. Not lamprig itself: through the calibration shim it links OpenCV, 280 MB of
# libraries, over what one call to the lent machine carries (64 MB). BASE=path/to/an/older/lamprig-bench also copies that build to
# .gpu/base/ (run.sh times it beside ours); CACHE=1 copies $XDG_CACHE_HOME/lamprig (or
# ~/.cache/lamprig) to .gpu/cache. Then send .gpu/, build/bin/lamprig-bench and
# build/reference-cache there
# (.gpu is ignored by git: carry it) and run `bash tools/bench/gpu-h200/run.sh`.
set -eu
mkdir -p .gpu/lib
for l in $(ldd build/bin/lamprig-bench | awk '/=>/ {print $3} /ld-linux/ {print $1}'); do
    cp -L "$l" .gpu/lib/
done
echo "packed $(ls .gpu/lib | wc -l) libraries into .gpu/lib ($(du -sh .gpu/lib | cut -f1))"
if [ -n "${BASE:-}" ]; then
    mkdir -p .gpu/base && cp "$BASE" .gpu/base/lamprig-bench
    for l in $(ldd "$BASE" | awk '/=>/ {print $3}'); do cp -L "$l" .gpu/lib/; done
fi
if [ "${CACHE:-0}" = 1 ]; then
    src=${XDG_CACHE_HOME:-$HOME/.cache}/lamprig
    mkdir -p .gpu/cache && cp -r "$src" .gpu/cache/
    echo "copied $(du -sh .gpu/cache | cut -f1) of cache"
fi
