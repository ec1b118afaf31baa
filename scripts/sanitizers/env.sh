# Sanitizer settings of scripts/test.sh --sanitize; `source scripts/sanitizers/env.sh` before
# running a test of build-asan/ by hand. Sourced by bash from the repository root or elsewhere.
_qsmesh_san_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# detect_leaks: LeakSanitizer at exit (third-party leaks in lsan.supp);
# check_initialization_order / strict_init_order: static-initialization-order bugs;
# detect_stack_use_after_return stays off (it doubles the run time of the meshing tests).
export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1:strict_string_checks=1:detect_odr_violation=2"
export LSAN_OPTIONS="suppressions=${_qsmesh_san_dir}/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=${_qsmesh_san_dir}/ubsan.supp"
unset _qsmesh_san_dir
