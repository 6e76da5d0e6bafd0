#!/usr/bin/env bash
# The whole stack over a bad link, in the lockstep runner: bench3 with 10 %
# of the datagrams between hosts lost (about half the scans, being seven
# datagrams long) and every message between hosts 50 +- 20 ms late (so that
# some overtake others). The flight must cross the finish gate within
# every rule of the report, and a faulty run must repeat to the bit like a
# clean one.
source "$(dirname "$0")/common.sh"
fly() {  # seed, output name
  "$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench3.yaml" --config-dir "$REPO/config" \
    --process-table "$REPO/deploy/processes.yaml" --link-loss 0.1 --link-delay 0.05 \
    --link-jitter 0.02 --link-seed "$1" --out "$WORK/$2" --quiet > "$WORK/$2.txt" 2>&1 ||
    { cat "$WORK/$2.txt"; fail "seed $1: the flight failed"; }
  grep -E "^link faults|outcome|max speed|least clearance" "$WORK/$2.txt"
  grep -q "outcome *: success" "$WORK/$2.txt" || fail "seed $1: not a success"
  lost=$(sed -n 's/^link faults .*: \([0-9]*\) of \([0-9]*\) messages lost.*/\1/p' "$WORK/$2.txt")
  [[ -n "$lost" && "$lost" -gt 500 ]] || fail "seed $1: the link lost only '${lost}' messages"
}
fly 1 a
fly 1 b
fly 2 c
for f in nav_state control_status ref_traj; do
  cmp "$WORK/a/$f.csv" "$WORK/b/$f.csv" || fail "$f differs between two runs with the same seed"
done
cmp -s "$WORK/a/nav_state.csv" "$WORK/c/nav_state.csv" && fail "another seed gave the same flight"
# At 30 % one scan in twelve arrives: the map is starved of scans, and the
# vehicle must stop and hover rather than fly on it (this seed came within
# 0.64 R_s of the wall's top when it flew on).
"$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench3.yaml" --config-dir "$REPO/config" \
  --process-table "$REPO/deploy/processes.yaml" --link-loss 0.3 --link-seed 2 --max-time 60 \
  --out "$WORK/d" --quiet > "$WORK/d.txt" 2>&1 || { cat "$WORK/d.txt"; fail "30 %: a failure"; }
grep -E "^link faults|outcome|least clearance" "$WORK/d.txt"
grep -q "outcome *: safe_stop" "$WORK/d.txt" || fail "30 %: not a safe stop"
grep -q "map starved of scans" "$WORK/d.txt" || fail "30 %: the optimiser never found the map starved"
pass "bench3 over a link losing 10 % of its datagrams, 50 +- 20 ms late: success on two seeds, repeatable; at 30 % a safe stop"
