#!/usr/bin/env bash
# Lint every RTL module with every parameter set it is used with (both configurations, both
# multiplier targets; the list comes from tb/rtlparams.py, i.e. from the model's formats):
#   verilator --lint-only -Wall   (no waivers; the ECP5 target uses tb/sim/MULT18X18D.v)
#   iverilog -g2005               (compile/elaborate as Verilog-2005)
# Usage: scripts/lint_rtl.sh [-j N] [-s K/M]   Exit status 1 if any job reports anything.
#   -s K/M: only every M-th job from job K (0 <= K < M), so that M runs can share the list
#           (make test runs two shards side by side).
set -u -o pipefail
cd "$(dirname "$0")/.."
JOBS=2
SHARD=0
SHARDS=1
while [ $# -gt 0 ]; do
  case "$1" in
    -j) JOBS="$2"; shift 2 ;;
    -s) SHARD="${2%/*}"; SHARDS="${2#*/}"; shift 2 ;;
    *) echo "lint_rtl.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ "$SHARD" =~ ^[0-9]+$ && "$SHARDS" =~ ^[0-9]+$ && "$SHARDS" -ge 1 && "$SHARD" -lt "$SHARDS" ]] ||
  { echo "lint_rtl.sh: -s K/M: need integers with 0 <= K < M, got '$SHARD/$SHARDS'" >&2; exit 2; }
[[ "$JOBS" =~ ^[1-9][0-9]*$ ]] || { echo "lint_rtl.sh: -j N: need a positive integer, got '$JOBS'" >&2; exit 2; }
PY="${PYTHON:-.venv/bin/python}"
[ -x "$PY" ] || PY=python3
command -v verilator >/dev/null || { echo "lint_rtl.sh: verilator not found" >&2; exit 2; }
command -v iverilog >/dev/null || { echo "lint_rtl.sh: iverilog not found" >&2; exit 2; }

OUT=build/lint/shard$SHARD-of-$SHARDS
rm -rf "$OUT"; mkdir -p "$OUT"
export OUT
"$PY" tb/rtlparams.py lint-jobs > "$OUT/jobs.txt" || exit 2

lint_one() {   # $1 = job number, reads the job line from jobs.txt
  local n="$1" line top files params
  line=$(sed -n "${n}p" "$OUT/jobs.txt")
  IFS=$'\t' read -r top files params <<< "$line"
  local vargs=() iargs=() kv
  for kv in $params; do
    vargs+=("-G$kv")
    iargs+=("-P$top.$kv")
  done
  local log="$OUT/job$n.log"
  {
    echo "== $top $params"
    # shellcheck disable=SC2086
    verilator --lint-only -Wall -Irtl --top-module "$top" "${vargs[@]}" $files 2>&1
    local rv=$?
    # shellcheck disable=SC2086
    iverilog -g2005 -Wall -Irtl -s "$top" "${iargs[@]}" -o /dev/null $files 2>&1
    local ri=$?
    echo "rc verilator=$rv iverilog=$ri"
  } > "$log" 2>&1
}
export -f lint_one

TOTAL=$(wc -l < "$OUT/jobs.txt")
MINE=$(seq 1 "$TOTAL" | awk -v k="$SHARD" -v m="$SHARDS" '(($1 - 1) % m) == k')
N=$(echo "$MINE" | grep -c .)
echo "$MINE" | xargs -P "$JOBS" -I{} bash -c 'lint_one {}'

fail=0
for n in $MINE; do
  log="$OUT/job$n.log"
  # a clean job logs exactly its header and the return codes
  if [ "$(grep -c . "$log")" -ne 2 ] || ! grep -q "rc verilator=0 iverilog=0" "$log"; then
    cat "$log"
    fail=1
  fi
done
if [ "$fail" -eq 0 ]; then
  echo "lint_rtl.sh: $N jobs clean (verilator --lint-only -Wall, iverilog -g2005; shard $SHARD of $SHARDS, $TOTAL jobs in all)"
fi
exit "$fail"
