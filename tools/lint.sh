#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The project's conventions, checked mechanically (`tools/run.sh lint` calls this after a build):
#   format   every tracked C++ file equals its clang-format (.clang-format) form;
#   spdx     every source file (C++, shell, Python, CMake) carries the SPDX licence line;
#   tidy     clang-tidy (.clang-tidy: naming with the mathematical-notation whitelist, a few bug-prone checks) on
#            every compiled source of the build's compile_commands.json, `--jobs` at a time.
# usage: tools/lint.sh [--build DIR] [--jobs N] [--only format|spdx|tidy] [--since COMMIT | --files-from FILE]
#   --since COMMIT     tidy only what changed since COMMIT: each changed .cpp, and for a changed .hpp the .cpp of
#                      the same name and its test (tests/<layer>/<name>_test.cpp). ctest's lint.tidy_changed uses
#                      the commit in tools/lint_base.txt, the last whole-tree clean run, so CI catches new findings
#                      without the whole tree's cost (~30 min on 2 cores).
#   --files-from FILE  tidy only the .cpp files listed in FILE (one path per line, relative to the repository)
# Exits 1 when any check finds a violation, listing each; 2 on a usage error; 77 (skipped) outside a git checkout.
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=build
jobs=2
only=""
files_from=""
since=""
while (($#)); do
  case "$1" in
    --build) build_dir=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    --files-from) files_from=$2; shift 2 ;;
    --since) since=$2; shift 2 ;;
    *) echo "tools/lint.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "tools/lint.sh: SKIPPED: not a git checkout (the checks list the tracked files with git)"
  exit 77
fi
wants() { [[ -z "$only" || "$only" == "$1" ]]; }
failed=0

if wants format; then
  mapfile -t cxx < <(git ls-files '*.cpp' '*.hpp')
  # --dry-run --Werror names each file that differs ("FILE:LINE:COL: error: code should be clang-formatted").
  mapfile -t unformatted < <(printf '%s\n' "${cxx[@]}" |
    xargs -r -P "$jobs" -n 16 clang-format --dry-run --Werror 2>&1 |
    sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' | sort -u)
  if ((${#unformatted[@]})); then
    printf 'lint format: %s differs from clang-format (run clang-format -i on it)\n' "${unformatted[@]}"
    failed=1
  fi
  echo "lint format: ${#cxx[@]} C++ files, ${#unformatted[@]} not formatted"
fi

if wants spdx; then
  mapfile -t sources < <(git ls-files '*.cpp' '*.hpp' '*.hpp.in' '*.sh' '*.py' '*CMakeLists.txt' '*.cmake' .ci/run)
  missing=()
  for f in "${sources[@]}"; do
    head -3 "$f" | grep -q 'SPDX-License-Identifier: GPL-3.0-or-later' || missing+=("$f")
  done
  if ((${#missing[@]})); then
    printf 'lint spdx: %s has no "SPDX-License-Identifier: GPL-3.0-or-later" in its first lines\n' "${missing[@]}"
    failed=1
  fi
  echo "lint spdx: ${#sources[@]} source files, ${#missing[@]} without the licence line"
fi

if wants tidy; then
  database="$build_dir/compile_commands.json"
  if [[ ! -f "$database" ]]; then
    echo "lint tidy: $database not found: configure and build first (tools/run.sh build)" >&2
    exit 2
  fi
  if [[ -n "$since" ]]; then
    if ! git cat-file -e "$since^{commit}" 2>/dev/null; then
      echo "lint tidy: SKIPPED: commit $since is not in this checkout's history (a shallow clone?)"
      exit "$failed"
    fi
    files_from=$(mktemp)
    git diff --name-only --diff-filter=d "$since" -- '*.cpp' '*.hpp' | while read -r f; do
      case "$f" in
        *.cpp) echo "$f" ;;
        *.hpp)
          stem=${f%.hpp}
          echo "$stem.cpp"
          echo "tests/$(dirname "$f")/$(basename "$stem")_test.cpp" ;;
      esac
    done | sort -u >"$files_from"
  fi
  if [[ -n "$files_from" ]]; then
    mapfile -t units < <(grep -E '\.cpp$' "$files_from" | while read -r f; do [[ -f "$f" ]] && echo "$f"; done)
  else
    # Every compiled source of the repository (generated files and fuzz-only targets are not in the database).
    mapfile -t units < <(git ls-files '*.cpp')
  fi
  log=$(mktemp)
  # The build precompiles system headers (ULTRATRACK_PRECOMPILE_HEADERS): GCC's precompiled files are not clang's,
  # so clang-tidy reads a copy of the database without them (every source includes what it uses).
  tidy_db=$(mktemp -d)
  trap 'rm -rf "$log" "$tidy_db"' EXIT
  python3 - "$database" "$tidy_db/compile_commands.json" <<'PY'
import json, re, sys
entries = json.load(open(sys.argv[1]))
for e in entries:
    if "command" in e:
        e["command"] = re.sub(r" -Winvalid-pch| -include \S*cmake_pch\.hxx", "", e["command"])
json.dump(entries, open(sys.argv[2], "w"), indent=0)
PY
  if ((${#units[@]})); then
    # A file the build does not compile (fuzz targets without ULTRATRACK_FUZZ, the Python bindings without
    # pybind11) is left out: clang-tidy would guess its flags.
    printf '%s\n' "${units[@]}" |
      python3 -c 'import json,os,sys
db={os.path.realpath(e["file"]) for e in json.load(open(sys.argv[1]))}
for line in sys.stdin:
    f=line.strip()
    if os.path.realpath(f) in db: print(f)' "$database" |
      xargs -r -P "$jobs" -n 4 clang-tidy -p "$tidy_db" --quiet >"$log" 2>/dev/null || true
  fi
  violations=$(grep -cE ': (warning|error): ' "$log" || true)
  if ((violations)); then
    grep -E ': (warning|error): ' "$log" | sort -u
    failed=1
  fi
  echo "lint tidy: ${#units[@]} sources, $violations findings"
fi

exit "$failed"
