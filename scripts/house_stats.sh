#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The house's numbers (issue 37): lines per folder, files over 400 lines,
# functions over 80 lines (universal-ctags' end lines), public headers,
# installed libraries and README lines. Run from anywhere; reads the
# repository this script is in. Needs universal-ctags (apt-get install
# universal-ctags).
set -euo pipefail
cd "$(dirname "$0")/.."
sources() { git ls-files -- "$@" | grep -E '\.(cpp|cc|hpp|h)$' || true; }

echo "## Lines per folder (C++ sources and headers)"
for dir in src include rt tests examples; do
  files=$(sources "$dir")
  lines=0
  [ -n "$files" ] && lines=$(cat $files | wc -l)
  printf '%-10s %7d lines in %4d files\n' "$dir" "$lines" "$(printf '%s\n' $files | grep -c . || true)"
done

echo "## Files over 400 lines (src, include, rt)"
for f in $(sources src include rt); do
  n=$(wc -l <"$f")
  if [ "$n" -gt 400 ]; then printf '%5d %s\n' "$n" "$f"; fi
done | sort -rn

echo "## Functions over 80 lines (src, include, rt)"
ctags -x --_xformat='%{end} %{line} %{input} %{scope}::%{name}' --kinds-C++=f --fields=+e \
    $(sources src include rt) 2>/dev/null |
  awk '$1 != "-" && $1 - $2 + 1 > 80 {printf "%5d %s:%d %s\n", $1 - $2 + 1, $3, $2, $4}' | sort -rn

echo "## Public headers"
echo "$(git ls-files include | grep -c '\.hpp$') under include/, $(git ls-files rt/sources rt/sinks rt/module | grep -c '\.hpp$') under rt/{sources,sinks,module}/"

echo "## Installed libraries (exported as graspfill::<name>)"
{
  # INTERNAL modules (the CLI's and the tests' tools) are neither exported nor installed.
  grep -rhE '^graspfill_module\(\w+' src rt --include=CMakeLists.txt | grep -v INTERNAL |
    sed -E 's/^graspfill_module\((\w+).*/\1/'
  grep -rhoE 'graspfill_export\(graspfill\w* \w+\)' src rt lcmtypes --include=CMakeLists.txt |
    sed -E 's/.* (\w+)\)/\1/'
} | sort | tr '\n' ' '
echo

echo "## README lines"
wc -l <README.md
