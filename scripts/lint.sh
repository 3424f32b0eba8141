#!/usr/bin/env bash
# Style and static checks on the project's own code:
#   clang-format --dry-run (the .clang-format style) and clang-tidy (.clang-tidy)
# against build/compile_commands.json. Usage: bash scripts/lint.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
mapfile -t files < <(git ls-files '*.cc' '*.h' | grep -E '^(calib|targets|reconstruct|datasets|apps|tests)/')
echo "clang-format: ${#files[@]} files"
# grep -c exits 1 when it counts 0: not a failure here (set -o pipefail).
clang-format --dry-run "${files[@]}" 2>&1 | { grep -c "warning:" || true; } | xargs -I{} echo "  {} formatting differences (clang-format -i to apply)"
echo "clang-tidy: library sources"
mapfile -t sources < <(printf '%s\n' "${files[@]}" | grep '\.cc$' | grep -v '_test\.cc$')
clang-tidy -p "$build" --quiet "${sources[@]}" 2>/dev/null | grep -E "warning:|error:" || echo "  no findings"
