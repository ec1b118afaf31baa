#!/usr/bin/env bash
# The style checks CI runs after the normal suite.
#  1. clang-format in check mode over every tracked C/C++ source (.clang-format): any difference
#     fails the run. Fix with `git clang-format` on a change, or `clang-format -i FILE`.
#  2. With --tidy: clang-tidy (.clang-tidy) on the C++ sources the checked-out commit changes
#     against BASE (default: its first parent), using build/compile_commands.json. Its findings
#     are printed, not fatal: Debian's clang-tidy 14 parses with clang 14, which rejects some valid
#     C++20 that GCC builds (a lambda naming a structured binding), and reports those as errors.
#     At most QSMESH_TIDY_MAX files (default 16), so a large merge cannot take CI's hour.
# Usage: scripts/check_style.sh [--tidy [BASE]]
set -euo pipefail
cd "$(dirname "$0")/.."
fmt=$(command -v clang-format-14 || command -v clang-format || true)
if [ -z "$fmt" ]; then
  echo "check_style: clang-format not found (scripts/setup.sh installs clang-format-14)" >&2
  exit 2
fi
mapfile -t sources < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.c')
if ! "$fmt" --dry-run --Werror "${sources[@]}" 2>/tmp/qsmesh_format.$$; then
  grep -E "^[^ ].*: (error|warning):" /tmp/qsmesh_format.$$ | head -40 >&2
  echo "check_style: $(grep -c "error:" /tmp/qsmesh_format.$$) places are not clang-format" \
       "clean (run clang-format -i on the files above)" >&2
  rm -f /tmp/qsmesh_format.$$
  exit 1
fi
rm -f /tmp/qsmesh_format.$$
echo "check_style: clang-format clean (${#sources[@]} files)"

[ "${1:-}" = "--tidy" ] || exit 0
base=${2:-HEAD^}
tidy=$(command -v clang-tidy-14 || command -v clang-tidy || true)
if [ -z "$tidy" ] || [ ! -f build/compile_commands.json ]; then
  echo "check_style: clang-tidy or build/compile_commands.json missing, tidy step skipped" >&2
  exit 2
fi
if ! git rev-parse -q --verify "$base" >/dev/null; then
  echo "check_style: no commit $base to compare with, tidy step skipped"
  exit 0
fi
mapfile -t changed < <(git diff --name-only --diff-filter=AM "$base" HEAD -- '*.cpp' |
                        head -n "${QSMESH_TIDY_MAX:-16}")
if [ ${#changed[@]} -eq 0 ]; then
  echo "check_style: no C++ source changed against $base"
  exit 0
fi
echo "check_style: clang-tidy on ${#changed[@]} changed files"
log=$(mktemp)
# GCC-only flags that clang 14 rejects as unknown (and then skips the file) are stripped from the
# compile commands the tidy step reads: -fcx-fortran-rules (src/linalg/CMakeLists.txt).
db=$(mktemp -d)
sed 's/ -fcx-fortran-rules//g' build/compile_commands.json >"$db/compile_commands.json"
"$tidy" -p "$db" --quiet "${changed[@]}" >"$log" 2>&1 || true
rm -rf "$db"
grep -E "(warning|error): .*\[[a-z-]+(,[a-z.-]+)*\]$" "$log" || true
echo "check_style: clang-tidy findings by check:"
grep -oE "\[[a-z-]+(,[a-z.-]+)*\]$" "$log" | sort | uniq -c | sort -rn || true
rm -f "$log"
