#!/usr/bin/env bash
# The bench3 flight through the real processes on udpm:// reaches the last
# waypoint over the wall: every service sends heartbeats, the LIDAR scans of
# the wall reach the mapper's obstacle database, the RH optimiser takes over
# from waypoint guidance, and the vehicle keeps at least 0.8 R_s (the
# benchmarks' failure line) from the real wall.
source "$(dirname "$0")/common.sh"
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/bench3.yaml" \
  --bin "$BIN" --rtf 2 --out "$WORK/run" --timeout 150 --no-pin > "$WORK/launch.txt" 2>&1 ||
  { tail -40 "$WORK/launch.txt"; fail "launcher exit code $?"; }
log=$(cat "$WORK/run/latest_log")
# Exit 1 is the report's verdict of failure; what this test requires is
# checked below.
"$BIN/ofn_flight_report" --log "$log" --scenario "$REPO/sim/scenarios/bench3.yaml" \
  --out "$WORK/report" > "$WORK/report.txt" || [[ $? == 1 ]] || fail "report failed"
cat "$WORK/report.txt"
grep -q "reached the last waypoint, crossed the finish gate" "$WORK/report.txt" ||
  fail "the flight did not complete"
grep -Eq "obstacle database : [1-9][0-9]* cuboids" "$WORK/report.txt" ||
  fail "no cuboid of the wall reached the obstacle database"
grep -Eq "RH optimiser      : [1-9][0-9]* steps" "$WORK/report.txt" ||
  fail "the RH optimiser never took over"
/usr/bin/python3 - "$WORK/report/summary.json" <<'PY' || fail "closer to the wall than 0.8 R_s"
import json, sys
s = json.load(open(sys.argv[1]))
print("least clearance %.2f m, required %.2f m" % (s["min_clearance"], s["clearance_required"]))
sys.exit(0 if s["min_clearance"] >= 0.8 * s["clearance_required"] else 1)
PY
for service in vehicle_sim controller mission_uplink flight_monitor obstacle_injector \
  sensor_interface mapper global_planner rh_optimizer; do
  n=$(grep -c ",$service," "$WORK/report/heartbeats.csv" || true)
  [[ $n -ge 3 ]] || fail "$service sent $n heartbeats"
done
pass "multi-process flight went over the wall; every service sent heartbeats; the wall was mapped"
