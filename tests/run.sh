#!/bin/sh
# Runs each test binary (one per area) and prints one summary line. Exit status 1 when any
# binary fails. Sanitizer options: leaks in system GL drivers are suppressed (tests/lsan.supp),
# never those in our code.
here=$(dirname "$0")
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}"
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export CMOCKA_MESSAGE_OUTPUT=stdout
failed=""
n=0
for t in "$@"; do
    n=$((n + 1))
    echo "== $(basename "$t")"
    if ! "$t"; then
        failed="$failed $(basename "$t")"
    fi
done
if [ -n "$failed" ]; then
    echo "tests: $n binaries, FAILED:$failed"
    exit 1
fi
echo "tests: $n binaries, all passed"
