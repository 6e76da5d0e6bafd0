#!/usr/bin/env bash
# Random bytes, NaN-filled messages and well-formed forgeries (a clock jump,
# a DONE, a plan at five times the speed limit, a cyclic beyond its range)
# on every channel during a flight: nothing crashes, the rejection counters
# rise, the run is not ended by the forged DONE, the vehicle never flies
# faster than its limit, and the flight completes.
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
grep -q "monitor: DONE not taken" "$WORK/launch.txt" || fail "the forged DONE went unnoticed"
/usr/bin/python3 - "$WORK/report/summary.json" <<'PY' || fail "the vehicle left its speed limit"
import json, sys
s = json.load(open(sys.argv[1]))
print("max speed %.3f m/s, limit %.3f m/s" % (s["max_speed"], s["limits"]["max_speed"]))
sys.exit(0 if s["max_speed"] <= 1.02 * s["limits"]["max_speed"] else 1)
PY
pass "flood rejected and counted; flight completed"
