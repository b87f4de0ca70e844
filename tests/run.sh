#!/bin/sh
# Runs each test binary (one per area) and prints one summary line. Exit status 1 when any
# binary fails. Sanitizer options: leaks in system GL drivers are suppressed (tests/lsan.supp),
# never those in our code: test_leak_control re-runs itself under exactly these settings and
# checks that a child opening EGL passes and the same child leaking 512 bytes of ours fails.
# Suppressing by library name needs the driver's name on the stack: every test binary pins the
# libraries EGL loads (tests/support/gl.c, at eglInitialize), since Mesa unloads its driver at
# eglTerminate and a leak in it was then reported at a random library. Fast unwinding stays:
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
here=$(dirname "$0")
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0:intercept_tls_get_addr=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export CMOCKA_MESSAGE_OUTPUT=stdout
# The tests' caches (the transrad F/S cache, render/transrad/cache.c) go to a folder of this run,
# so that a user's ~/.cache never feeds a test and a test run never fills it.
XDG_CACHE_HOME=$(mktemp -d "${TMPDIR:-/tmp}/lamprig-test-cache.XXXXXX") || exit 1
export XDG_CACHE_HOME
trap 'rm -rf "$XDG_CACHE_HOME"' EXIT
# Each binary's output is also kept in a log of this run, so that a failure's own lines are
# printed again just above the summary: CI shows only the end of a long run.
logs=$(mktemp -d "${TMPDIR:-/tmp}/lamprig-test-logs.XXXXXX") || exit 1
trap 'rm -rf "$XDG_CACHE_HOME" "$logs"' EXIT
failed=""
n=0
for t in "$@"; do
    n=$((n + 1))
    name=$(basename "$t")
    echo "== $name"
    { "$t" 2>&1; echo $? >"$logs/$name.rc"; } | tee "$logs/$name.log"
    if [ "$(cat "$logs/$name.rc")" != 0 ]; then
        failed="$failed $name"
    fi
done
if [ -n "$failed" ]; then
    for f in $failed; do
        echo "== $f failed (exit $(cat "$logs/$f.rc")); its last 40 lines:"
        tail -n 40 "$logs/$f.log"
    done
    echo "tests: $n binaries, FAILED:$failed"
    exit 1
fi
echo "tests: $n binaries, all passed"
