#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The two commands of the README, and a plain build:
#   tools/run.sh demo   install missing Debian packages, build (Release, 2 jobs), run `ultratrack demo`
#   tools/run.sh test   the same build, then the whole test suite through ctest
#   tools/run.sh build  only the build
#   tools/run.sh lint   the same build, then tools/lint.sh on the whole tree (clang-format, SPDX lines, clang-tidy)
#   tools/run.sh sanitize  the test suite built with AddressSanitizer + UndefinedBehaviorSanitizer (build-sanitize,
#                       RelWithDebInfo, no benchmarks or Python module) and run through ctest: any report fails a test
#   tools/run.sh fuzz [SECONDS [TARGET...]]  the libFuzzer targets (clang, build-fuzz), each (or those named) run
#                       SECONDS (default 600) from the committed corpora by tests/fuzz/run.sh; exit 1 on any finding
# Idempotent: a second run installs nothing and rebuilds only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake make ninja-build pkg-config libeigen3-dev libfftw3-dev libgeographiclib-dev libcli11-dev
          libtomlplusplus-dev libfmt-dev libgtest-dev libgmock-dev libbenchmark-dev)
# The test suite also runs RTKLIB (convbin, rnx2rtkp) on our RINEX output as an independent reader.
# python3: ctest docs.file_map checks docs/architecture.md's module tables against the code; pybind11-dev,
# python3-dev, python3-numpy and python3-matplotlib: the Python package (python/) and its report; python3-pytest and
# chromium (headless: the report pages must render without a console error): its tests (python.module).
# clang-format and clang-tidy: the conventions (tools/lint.sh; ctest lint.*).
[[ "${1:-build}" == test || "${1:-build}" == lint || "${1:-build}" == sanitize ]] && packages+=(clang-format clang-tidy)
# clang and libclang-rt-dev: libFuzzer and its sanitizer runtimes (tools/run.sh fuzz).
[[ "${1:-build}" == fuzz ]] && packages+=(clang libclang-rt-dev)
# munge slurmctld slurmd slurm-client: ctest campaign.slurm_local runs campaigns on a real single-node Slurm
# (tools/slurm-local.sh; about 11 s to install, 4 MB; not the slurm-wlm metapackage, whose recommends pull 31 plugins).
[[ "${1:-build}" == test || "${1:-build}" == sanitize ]] &&
  packages+=(rtklib python3 pybind11-dev python3-dev python3-numpy python3-matplotlib python3-pytest chromium
             munge slurmctld slurmd slurm-client)
# Each phase prints its wall time (CI keeps the log: the slow phase is then known, not guessed).
phase_start=$SECONDS
phase_done() { echo "tools/run.sh: $1 took $((SECONDS - phase_start)) s"; phase_start=$SECONDS; }

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "tools/run.sh: installing ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
  phase_done "installing ${#missing[@]} packages"
fi

build_dir=${ULTRATRACK_BUILD_DIR:-build}
jobs=${ULTRATRACK_JOBS:-2}
build_options=(-DCMAKE_BUILD_TYPE=Release)
case "${1:-build}" in
  # Sanitized: -O2 with debug lines, so a report names the line; a UB report aborts (-fno-sanitize-recover).
  sanitize) build_dir=${ULTRATRACK_BUILD_DIR:-build-sanitize}
            build_options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DULTRATRACK_SANITIZE=ON -DULTRATRACK_BUILD_BENCHMARKS=OFF) ;;
  fuzz) build_dir=${ULTRATRACK_BUILD_DIR:-build-fuzz}
        build_options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang
                       -DULTRATRACK_FUZZ=ON -DULTRATRACK_BUILD_TESTS=OFF -DULTRATRACK_BUILD_BENCHMARKS=OFF) ;;
esac
# A new build folder uses Ninja: a layer's sources compile while the layers below still do (make waits for each
# library), which keeps both cores busy in a cold build. An existing folder keeps the generator it was made with.
generator=()
[[ -f "$build_dir/CMakeCache.txt" ]] || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" "${build_options[@]}" >/dev/null
if [[ "${1:-build}" == fuzz ]]; then  # the fuzz targets and what they link, not the program's other parts
  fuzz_targets=()
  for f in tests/fuzz/fuzz_*.cpp; do fuzz_targets+=("$(basename "$f" .cpp)"); done
  cmake --build "$build_dir" -j"$jobs" --target "${fuzz_targets[@]}"
else
  cmake --build "$build_dir" -j"$jobs"
fi
phase_done "the build"

case "${1:-build}" in
  demo) shift; exec "$build_dir/tools/ultratrack" demo "$@" ;;
  test|sanitize) status=0; ctest --test-dir "$build_dir" --output-on-failure -j"$jobs" || status=$?
        phase_done "ctest"; exit "$status" ;;
  fuzz) ULTRATRACK_FUZZ_BUILD=$build_dir exec tests/fuzz/run.sh "${2:-600}" "${@:3}" ;;
  lint) exec tools/lint.sh --build "$build_dir" --jobs "$jobs" ;;
  build) ;;
  *) echo "usage: tools/run.sh demo|test|build|lint|sanitize|fuzz [SECONDS [TARGET...]]" >&2; exit 2 ;;
esac
