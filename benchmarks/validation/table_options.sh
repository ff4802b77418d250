# SPDX-License-Identifier: GPL-3.0-or-later
# The options every table script of benchmarks/validation/ takes, sourced after it has set `root` (the checkout),
# `name` (its file name, for messages) and `out` (its default scratch folder):
#   --out DIR  --ultratrack BIN (default build/tools/ultratrack)  --keep (sample files stay)  -h|--help
# Leaves `out` absolute and created, `ultratrack` executable, `keep` 0 or 1.
ultratrack=$root/build/tools/ultratrack; keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --ultratrack) ultratrack=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,/^set -euo pipefail/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "$name: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -x "$ultratrack" ] || { echo "$name: $ultratrack not built" >&2; exit 2; }
mkdir -p "$out"; out=$(realpath "$out")
