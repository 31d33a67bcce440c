# Sanitizer runtime options for romo's ASan+UBSan builds (sourced by scripts/ci-sanitize.sh and
# scripts/fuzz.sh; source it yourself before running binaries of such a build by hand).
# Suppressions are only for third-party code; each entry says why.
_romo_san_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:abort_on_error=0:suppressions=$_romo_san_dir/asan.supp}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$_romo_san_dir/lsan.supp:print_suppressions=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1:suppressions=$_romo_san_dir/ubsan.supp}"
unset _romo_san_dir
