#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs every libFuzzer target of a fuzz build for SECONDS each, starting from the committed seed corpora
# (tests/fuzz/corpus/<target>/, copied: what a run adds stays in the scratch folder). Exit 1 on any finding; the
# reproducer is left in the scratch folder and its path printed (keep it as a regression input in tests/fuzz/regressions/).
#   tests/fuzz/run.sh SECONDS [TARGET...]   fuzz build in $ULTRATRACK_FUZZ_BUILD (default build-fuzz); every target,
#                                          or only those named (e.g. fuzz_csv_inputs)
# The fuzz build (`tools/run.sh fuzz SECONDS [TARGET...]` makes it and runs this):
#   CXX=clang++ cmake -S . -B build-fuzz -DULTRATRACK_FUZZ=ON -DULTRATRACK_BUILD_TESTS=OFF \
#     -DULTRATRACK_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo && cmake --build build-fuzz -j2
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
seconds=${1:?usage: tests/fuzz/run.sh SECONDS [TARGET...]}
shift
build=${ULTRATRACK_FUZZ_BUILD:-$root/build-fuzz}
scratch=$(mktemp -d "${TMPDIR:-/tmp}/ultratrack_fuzz.XXXXXX")
[[ -d $build/fuzz ]] || { echo "run.sh: no fuzz targets in $build/fuzz (see the header for the fuzz build)" >&2; exit 2; }
status=0
targets=("$build"/fuzz/fuzz_*)
if (($#)); then
  targets=()
  for name in "$@"; do
    [[ -x "$build/fuzz/$name" ]] || { echo "run.sh: no target $name in $build/fuzz" >&2; exit 2; }
    targets+=("$build/fuzz/$name")
  done
fi
for target in "${targets[@]}"; do
  name=$(basename "$target")
  work=$scratch/$name
  mkdir -p "$work/corpus" "$work/artifacts"
  cp "$here/corpus/$name"/* "$work/corpus/" 2>/dev/null
  # Every input found so far that crashed once stays a seed, so a fixed bug that returns is found at once.
  cp "$here/regressions/$name"-* "$work/corpus/" 2>/dev/null  # none yet: the folder appears with the first finding
  if "$target" -max_total_time="$seconds" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$work/artifacts/" \
       "$work/corpus" > "$work/log.txt" 2>&1; then
    echo "$name: clean, $(grep -o 'stat::number_of_executed_units: [0-9]*' "$work/log.txt" | cut -d' ' -f2) runs"
  else
    echo "$name: FINDING: $(find "$work/artifacts" -type f -printf '%f\n' | head -1) (log $work/log.txt)"
    status=1
  fi
done
echo "run.sh: scratch in $scratch"
exit $status
