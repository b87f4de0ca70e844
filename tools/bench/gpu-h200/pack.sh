#!/bin/sh
# Packs lamprig-bench and its shared libraries (the Debian 12 glibc and loader included) into
# .gpu/, for a GPU machine whose system is another distribution (the figures in this folder
# came from an Ubuntu 24.04 image with NVIDIA's EGL). Run from the repository root after
# `make`; then copy .gpu/, build/bin/lamprig-bench and build/reference-cache there and run
# `bash tools/bench/gpu-h200/run.sh`.
set -eu
mkdir -p .gpu/lib
for l in $(ldd build/bin/lamprig-bench | awk '/=>/ {print $3} /ld-linux/ {print $1}' | sort -u); do
    cp -L "$l" .gpu/lib/
done
echo "packed $(ls .gpu/lib | wc -l) libraries into .gpu/lib"
