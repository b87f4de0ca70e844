#!/usr/bin/env bash
# Runs test binaries (one per area), several at a time, and prints each binary's result and time
# as it ends, then a summary with the slowest binaries. Exit status 1 when any binary fails.
#
#   sh tests/run.sh build/test/test_NAME ...       (or bash; `make test` runs them all)
#   LR_TEST_JOBS=N   binaries at once (default: the number of CPUs plus one, at least 3)
#   pi5:build/test/test_NAME   that binary again under the Raspberry Pi 5's GLES profile
#                    (MESA_GLES_VERSION_OVERRIDE=$LR_PI5_GLES, MESA_EXTENSION_OVERRIDE=
#                    $LR_PI5_EXT, both from the Makefile), shown as test_NAME@pi5
#
# Scheduling: the binaries named in tests/durations.txt start longest first (a fixed list of
# measured CPU times, so a run's makespan is about the longest binary's time plus the rest
# divided by the jobs); binaries not listed start after them. Each binary gets a cache folder
# of its own (XDG_CACHE_HOME) below this run's: no binary sees what another one cached, so a
# result never depends on the order or on which binaries ran beside it, and a user's ~/.cache
# never feeds a test (Mesa's shader cache alone is shared: compiled shaders, not results;
# see launch). Each binary's output goes to a log of this run; a failure's last lines
# are printed again above the summary (CI shows only the end of a long run). While binaries
# run, a line every 60 s names the ones still running, so a long run is never silent.
#
# Sanitizer options: leaks in system GL drivers are suppressed (tests/lsan.supp), never those
# in our code: test_leak_control re-runs itself under exactly these settings and checks that a
# child opening EGL passes and the same child leaking 512 bytes of ours fails. Suppressing by
# library name needs the driver's name on the stack: every test binary pins the libraries EGL
# loads (tests/support/gl.c, at eglInitialize), since Mesa unloads its driver at eglTerminate
# and a leak in it was then reported at a random library. Fast unwinding stays:
# fast_unwind_on_malloc=0 also found the names (deeper frames, in libEGL_mesa) but cost
# +66-74 % CPU time per binary (test_calib_camera, test_gl_context).
# intercept_tls_get_addr=0: GCC 12's runtime (Debian 12) takes a dynamic TLS block that malloc
# placed at 16 bytes past a page boundary for a pre-2.25 glibc block and reads the two words
# before it as that block's start and size (sanitizer_tls_get_addr.cpp; fixed in LLVM 17); the
# leak check's tracer then scans that garbage range and dies: "Tracer caught signal 11 ...
# LeakSanitizer has encountered a fatal error" after every test passed. llvmpipe's threads give
# one such block per GL binary, so about 1 in 256 runs of each failed, and CI failed on a
# fresh clone (test_render_openings). glibc 2.36's blocks are never recognised anyway ("Can't
# guess glibc version", size 0, with verbosity=2), so the flag costs no scanning: the leak
# check is the same, which test_leak_control proves under these settings.
if [ -z "${BASH_VERSION:-}" ]; then exec bash "$0" "$@"; fi
set -u
here=$(dirname "$0")
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0:intercept_tls_get_addr=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export CMOCKA_MESSAGE_OUTPUT=stdout

# One more than the CPUs: the rig's binaries (test_fw_loop, _modbus, _http, test_async) wait on
# their clocks and peers for about half their time (test_fw_loop: 39 s of CPU in 72 s), and a
# third binary fills that. On the 2-core machine the 125 binaries took 732-734 s at 3 against
# 767 s at 2 (each CPU-bound binary is slower, the whole run shorter).
jobs=${LR_TEST_JOBS:-$(( $(nproc 2>/dev/null || echo 2) + 1 ))}
case $jobs in '' | *[!0-9]* | 0) echo "run.sh: LR_TEST_JOBS must be a positive integer" >&2; exit 2 ;; esac
[ "$jobs" -lt 3 ] && [ -z "${LR_TEST_JOBS:-}" ] && jobs=3
# llvmpipe starts one rasteriser thread per CPU in every GL binary: with several binaries at
# once that oversubscribes the CPUs many times over. Share them out instead.
if [ -z "${LP_NUM_THREADS:-}" ]; then
    cpus=$(nproc 2>/dev/null || echo 2)
    lp=$(( (cpus + jobs - 1) / jobs ))
    export LP_NUM_THREADS=$(( lp < 1 ? 1 : lp ))
fi

run_dir=$(mktemp -d "${TMPDIR:-/tmp}/lamprig-test-run.XXXXXX") || exit 1
trap 'rm -rf "$run_dir"' EXIT
mkdir -p "$run_dir/cache" "$run_dir/logs" "$run_dir/mesa_shader_cache"

# Longest first: tests/durations.txt lists "NAME SECONDS" (measured; `sort -k2 -nr`).
declare -A known=()
if [ -f "$here/durations.txt" ]; then
    while read -r name secs _; do
        case $name in '' | '#'*) continue ;; esac
        known[$name]=$secs
    done <"$here/durations.txt"
fi
listed=()
unlisted=()
for t in "$@"; do
    name=$(basename "${t#pi5:}")
    if [ -n "${known[$name]:-}" ]; then listed+=("${known[$name]} $t"); else unlisted+=("$t"); fi
done
queue=()
if [ ${#listed[@]} -gt 0 ]; then
    while read -r _ t; do queue+=("$t"); done < <(printf '%s\n' "${listed[@]}" | sort -k1,1 -gr)
fi
queue+=("${unlisted[@]}")

total=${#queue[@]}
echo "tests: $total binaries, $jobs at a time (LR_TEST_JOBS), llvmpipe threads $LP_NUM_THREADS each"

declare -A pid_name=() started=()
failed=()
times=()
done_n=0
run_start=$EPOCHREALTIME
last_beat=${EPOCHREALTIME%.*}

launch() {
    local t=$1 name pi5=
    name=$(basename "${t#pi5:}")
    if [ "${t#pi5:}" != "$t" ]; then
        pi5=1
        t=${t#pi5:}
        name=$name@pi5
    fi
    mkdir -p "$run_dir/cache/$name"
    # Mesa's shader cache alone is shared by the run's binaries (a link in each cache folder,
    # so a test that points XDG_CACHE_HOME elsewhere still gets its own): it holds llvmpipe's
    # compiled shaders, keyed by their source and the driver, never a result, and compiling
    # the renderer's shaders again in every GL binary was about 2.5 s CPU each.
    [ -n "${MESA_SHADER_CACHE_DIR:-}" ] || ln -s ../../mesa_shader_cache "$run_dir/cache/$name/mesa_shader_cache"
    (
        export XDG_CACHE_HOME="$run_dir/cache/$name"
        # LR_TEST_EXEC: a runner in front of each binary (make test-arm64: qemu-aarch64-static).
        if [ -n "$pi5" ]; then
            export MESA_GLES_VERSION_OVERRIDE="${LR_PI5_GLES:?pi5: entries need LR_PI5_GLES}"
            export MESA_EXTENSION_OVERRIDE="${LR_PI5_EXT:?pi5: entries need LR_PI5_EXT}"
        fi
        ${LR_TEST_EXEC:-} "$t" >"$run_dir/logs/$name.log" 2>&1
        echo $? >"$run_dir/logs/$name.rc"
    ) &
    pid_name[$!]=$name
    started[$name]=$EPOCHREALTIME
}

finish() {
    local pid=$1 name rc secs
    name=${pid_name[$pid]}
    wait "$pid" 2>/dev/null
    rc=$(cat "$run_dir/logs/$name.rc" 2>/dev/null || echo 99)
    secs=$(awk -v a="${started[$name]}" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }')
    done_n=$((done_n + 1))
    times+=("$secs $name")
    if [ "$rc" = 0 ]; then
        printf '[%d/%d] %-34s ok     %7s s\n' "$done_n" "$total" "$name" "$secs"
    else
        printf '[%d/%d] %-34s FAILED %7s s (exit %s)\n' "$done_n" "$total" "$name" "$secs" "$rc"
        failed+=("$name")
    fi
    unset "pid_name[$pid]"
}

i=0
while [ $i -lt "$total" ] || [ ${#pid_name[@]} -gt 0 ]; do
    while [ $i -lt "$total" ] && [ ${#pid_name[@]} -lt "$jobs" ]; do
        launch "${queue[$i]}"
        i=$((i + 1))
    done
    sleep 0.2
    for pid in "${!pid_name[@]}"; do
        kill -0 "$pid" 2>/dev/null || finish "$pid"
    done
    now=${EPOCHREALTIME%.*}
    if [ $((now - last_beat)) -ge 60 ] && [ ${#pid_name[@]} -gt 0 ]; then
        last_beat=$now
        line=""
        for pid in "${!pid_name[@]}"; do
            n=${pid_name[$pid]}
            line="$line $n ($(awk -v a="${started[$n]}" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.0f", b - a }') s)"
        done
        echo "   ... still running:$line"
    fi
done

wall=$(awk -v a="$run_start" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.0f", b - a }')
echo "tests: the slowest binaries (wall seconds, $jobs at a time):"
printf '%s\n' "${times[@]}" | sort -k1,1 -gr | head -n 12 | awk '{ printf "   %7.1f s  %s\n", $1, $2 }'
if [ ${#failed[@]} -gt 0 ]; then
    for f in "${failed[@]}"; do
        echo "== $f failed (exit $(cat "$run_dir/logs/$f.rc" 2>/dev/null)); its last 40 lines:"
        tail -n 40 "$run_dir/logs/$f.log"
    done
    echo "tests: $total binaries in $wall s, FAILED: ${failed[*]}"
    exit 1
fi
echo "tests: $total binaries in $wall s, all passed"
