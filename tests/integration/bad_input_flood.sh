#!/usr/bin/env bash
# Random bytes and NaN-filled messages on every channel during a flight:
# nothing crashes, the rejection counters rise, and the flight completes.
source "$(dirname "$0")/common.sh"
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/open.yaml" \
  --bin "$BIN" --rtf 4 --log-dir "$WORK/run" --timeout 150 --no-pin --max-restarts 0 \
  > "$WORK/launch.txt" 2>&1 &
launcher=$!
sleep 3
"$BIN/ofn_bus_fuzz" --expect vehicle_sim --expect controller --expect flight_monitor ||
  { kill -INT $launcher; wait $launcher || true; fail "a service died or rejected nothing"; }
wait $launcher || { tail -40 "$WORK/launch.txt"; fail "launcher exit code $? after the flood"; }
if grep -qi "restarting" "$WORK/launch.txt"; then fail "a service had to be restarted"; fi
log=$(cat "$WORK/run/latest_log")
# Exit 1 is the report's verdict of failure; this test asks for completion.
"$BIN/ofn_flight_report" --log "$log" --scenario "$REPO/sim/scenarios/open.yaml" \
  --out "$WORK/report" > "$WORK/report.txt" || [[ $? == 1 ]] || fail "report failed"
grep -q "reached the last waypoint" "$WORK/report.txt" || fail "flight did not complete"
pass "flood rejected and counted; flight completed"
