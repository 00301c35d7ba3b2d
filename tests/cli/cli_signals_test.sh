#!/usr/bin/env bash
# End-to-end signals for `dyncull run`: Ctrl-C (SIGINT) finishes the files cleanly and
# says where they are; a fatal signal names the frame and mode it hit.
#   cli_signals_test.sh DYNCULL_BINARY SCENE_FILE WORK_DIR
set -uo pipefail
bin=$1 scene=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
fail() { echo "FAIL: $*"; for f in "$work"/*.log; do echo "--- $f"; cat "$f"; done; exit 1; }

# Waits until the per-frame CSV of a run has at least $2 data rows (the header is line 1).
wait_rows() {
  for _ in $(seq 1 600); do
    [[ -f $1 && $(wc -l <"$1") -gt $2 ]] && return 0
    sleep 0.1
  done
  return 1
}

# 1. SIGINT mid-run: exit status 130, the CSV holds every completed frame, the picture is
#    of the last completed frame, and the run says so.
"$bin" run "$scene" --frames 100000 --size 64x48 --out "$work/int" >"$work/int.log" 2>&1 &
pid=$!
wait_rows "$work/int/frames_full.csv" 3 || { kill -9 $pid; fail "no frames written"; }
kill -INT $pid
wait $pid
rc=$?
[[ $rc -eq 130 ]] || fail "SIGINT: exit status $rc, expected 130"
grep -q "^interrupted after [0-9]* of 100000 frames" "$work/int.log" || fail "SIGINT: no 'interrupted after' line"
grep -q "^stats: $work/int/frames_full.csv" "$work/int.log" || fail "SIGINT: stats path not printed"
grep -q "^picture: $work/int/last_full.png" "$work/int.log" || fail "SIGINT: picture path not printed"
[[ -s $work/int/last_full.png ]] || fail "SIGINT: no picture"
frames=$(sed -n 's/^summary .* frames=\([0-9]*\) .*/\1/p' "$work/int.log")
rows=$(($(wc -l <"$work/int/frames_full.csv") - 1))
[[ -n $frames && $rows -eq $frames ]] || fail "SIGINT: CSV has $rows rows, summary says $frames frames"
# Every row complete: 17 fields.
awk -F, 'NR == 1 { n = NF } NR > 1 && NF != n { exit 1 }' "$work/int/frames_full.csv" || fail "SIGINT: a CSV row is incomplete"

# 2. A fatal signal during a frame: one line naming the frame and the mode, then the
#    default action (exit status 128 + SIGSEGV).
"$bin" run "$scene" --mode simple --frames 100000 --size 64x48 --out "$work/segv" >"$work/segv.log" 2>&1 &
pid=$!
wait_rows "$work/segv/frames_simple.csv" 2 || { kill -9 $pid; fail "no frames written"; }
kill -SEGV $pid
wait $pid
rc=$?
[[ $rc -eq 139 ]] || fail "SIGSEGV: exit status $rc, expected 139"
grep -qE "^dyncull: fatal SIGSEGV during (frame [0-9]+ of mode simple|writing outputs)$" "$work/segv.log" ||
  fail "SIGSEGV: no line naming the frame and mode"
echo "cli signals: all passed"
