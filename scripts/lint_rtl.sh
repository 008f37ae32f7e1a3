#!/usr/bin/env bash
# Lint every RTL module with every parameter set it is used with (both configurations, both
# multiplier targets; the list comes from tb/rtlparams.py, i.e. from the model's formats):
#   verilator --lint-only -Wall   (no waivers; the ECP5 target uses tb/sim/MULT18X18D.v)
#   iverilog -g2005               (compile/elaborate as Verilog-2005)
# Usage: scripts/lint_rtl.sh [-j N]      Exit status 1 if any job reports anything.
set -u -o pipefail
cd "$(dirname "$0")/.."
JOBS=2
if [ "${1:-}" = "-j" ]; then JOBS="$2"; fi
PY="${PYTHON:-.venv/bin/python}"
[ -x "$PY" ] || PY=python3
command -v verilator >/dev/null || { echo "lint_rtl.sh: verilator not found" >&2; exit 2; }
command -v iverilog >/dev/null || { echo "lint_rtl.sh: iverilog not found" >&2; exit 2; }

OUT=build/lint
rm -rf "$OUT"; mkdir -p "$OUT"
"$PY" tb/rtlparams.py lint-jobs > "$OUT/jobs.txt" || exit 2

lint_one() {   # $1 = job number, reads the job line from jobs.txt
  local n="$1" line top files params
  line=$(sed -n "${n}p" build/lint/jobs.txt)
  IFS=$'\t' read -r top files params <<< "$line"
  local vargs=() iargs=() kv
  for kv in $params; do
    vargs+=("-G$kv")
    iargs+=("-P$top.$kv")
  done
  local log="build/lint/job$n.log"
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

N=$(wc -l < "$OUT/jobs.txt")
seq 1 "$N" | xargs -P "$JOBS" -I{} bash -c 'lint_one {}'

fail=0
for n in $(seq 1 "$N"); do
  log="$OUT/job$n.log"
  # a clean job logs exactly its header and the return codes
  if [ "$(grep -c . "$log")" -ne 2 ] || ! grep -q "rc verilator=0 iverilog=0" "$log"; then
    cat "$log"
    fail=1
  fi
done
if [ "$fail" -eq 0 ]; then
  echo "lint_rtl.sh: $N jobs clean (verilator --lint-only -Wall, iverilog -g2005)"
fi
exit "$fail"
