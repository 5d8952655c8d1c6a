#!/bin/sh
# The C and C++ sources follow .clang-format: clang-format changes nothing in any tracked file.
cd "$1" || exit 1
files=$(git ls-files '*.c' '*.h' '*.cpp') || exit 1
[ -n "$files" ] || { echo "test_format: no sources found in $1"; exit 1; }
# shellcheck disable=SC2086
if clang-format --style=file --dry-run --Werror $files; then
  echo "test_format: $(echo "$files" | wc -l) files follow .clang-format"
else
  echo "test_format: files above differ from .clang-format (run clang-format -i on them)"
  exit 1
fi
