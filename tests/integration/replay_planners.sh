#!/usr/bin/env bash
# Replay into the services: a lockstep flight of bench1 (over the wall:
# mapping, global route and RH avoidance all busy), replayed by ofn_replay
# into fresh sensor_interface, mapper, global_planner and rh_optimizer
# services, reproduces every compared channel to the bit; a log with the
# scans cut out is reported as different; bad input exits 2.
source "$(dirname "$0")/common.sh"
scenario="$REPO/sim/scenarios/bench1.yaml"
# Not arriving within 25 s, the runner exits 1; the log is what counts.
"$BIN/ofn_sim_runner" --scenario "$scenario" --config-dir "$REPO/config" --out "$WORK/orig" \
  --max-time 25 --quiet > "$WORK/orig.txt" 2>&1 || true
[[ -s "$WORK/orig/flight.lcm" ]] || { cat "$WORK/orig.txt"; fail "lockstep flight wrote no log"; }

"$BIN/ofn_replay" --log "$WORK/orig/flight.lcm" --config-dir "$REPO/config" --out "$WORK/replay" \
  --log-level error > "$WORK/replay.txt" 2>&1 || { cat "$WORK/replay.txt"; fail "replay differs (exit $?)"; }
cat "$WORK/replay.txt"
for ch in SCAN_WORLD OBSTACLE_GRID CUBOIDS GLOBAL_PATH NARROW_PASSAGES REF_TRAJ SOLVER_STATS; do
  # recorded == replayed == identical, and not zero: the chain was exercised.
  awk -v ch="$ch" '$1 == ch && $2 > 0 && $2 == $3 && $2 == $4 && $6 == 0 && $7 == 0 { ok = 1 }
                   END { exit !ok }' "$WORK/replay.txt" || fail "$ch not reproduced identically"
done
grep -q "replay reproduces the recording" "$WORK/replay.txt" || fail "no verdict line"

# The replayed log is a flight log like any other. Cut off at 25 s the
# flight's outcome is failure (exit 1); only a report that broke fails here.
"$BIN/ofn_flight_report" --log "$WORK/replay/replayed.lcm" --scenario "$scenario" \
  --out "$WORK/replay/report" > /dev/null || [[ $? == 1 ]] ||
  fail "flight report of the replayed log failed"
cmp "$WORK/orig/ref_traj.csv" "$WORK/replay/report/ref_traj.csv" || fail "REF_TRAJ CSV differs"
cmp "$WORK/orig/global_path.csv" "$WORK/replay/report/global_path.csv" ||
  fail "GLOBAL_PATH CSV differs"

# Bad input: exit 2 with the reason.
set +e
"$BIN/ofn_replay" --log "$WORK/orig/flight.lcm" --services mapper,controller > "$WORK/bad.txt" 2>&1
code=$?
set -e
[[ $code -eq 2 ]] && grep -q "unknown service 'controller'" "$WORK/bad.txt" ||
  { cat "$WORK/bad.txt"; fail "unknown service: exit $code"; }
set +e
"$BIN/ofn_replay" --log "$WORK/missing.lcm" > "$WORK/bad.txt" 2>&1
code=$?
set -e
[[ $code -eq 2 ]] && grep -q "not found" "$WORK/bad.txt" ||
  { cat "$WORK/bad.txt"; fail "missing log: exit $code"; }

# A replay with the wrong mapper settings does not reproduce: exit 1.
mkdir -p "$WORK/other-config"
cp "$REPO"/config/*.yaml "$WORK/other-config/"
sed -i 's/^cuboid_rate_hz: .*/cuboid_rate_hz: 2.0/' "$WORK/other-config/mapper.yaml"
set +e
"$BIN/ofn_replay" --log "$WORK/orig/flight.lcm" --config-dir "$WORK/other-config" \
  --services mapper --log-level error > "$WORK/differs.txt" 2>&1
code=$?
set -e
[[ $code -eq 1 ]] && grep -q "CUBOIDS .*DIFFERS" "$WORK/differs.txt" ||
  { cat "$WORK/differs.txt"; fail "changed mapper settings: exit $code, expected 1"; }
pass "lockstep bench1 flight replayed into mapper and planners identically"
