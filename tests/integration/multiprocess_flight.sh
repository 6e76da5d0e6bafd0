#!/usr/bin/env bash
# The bench3 flight through the real processes on udpm:// reaches the last
# waypoint, every service sends heartbeats, and the LIDAR scans of the wall
# reach the mapper's obstacle database. (No avoidance yet: the vehicle flies
# through the virtual wall.)
source "$(dirname "$0")/common.sh"
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/bench3.yaml" \
  --bin "$BIN" --rtf 4 --log-dir "$WORK/run" --timeout 120 --no-pin > "$WORK/launch.txt" 2>&1 ||
  { tail -40 "$WORK/launch.txt"; fail "launcher exit code $?"; }
log=$(cat "$WORK/run/latest_log")
"$BIN/ofn_flight_report" --log "$log" --scenario "$REPO/sim/scenarios/bench3.yaml" \
  --out "$WORK/report" > "$WORK/report.txt" || fail "report failed"
cat "$WORK/report.txt"
grep -q "reached the last waypoint, crossed the finish gate" "$WORK/report.txt" ||
  fail "the flight did not complete"
grep -Eq "obstacle database : [1-9][0-9]* cuboids" "$WORK/report.txt" ||
  fail "no cuboid of the wall reached the obstacle database"
for service in vehicle_sim controller mission_uplink flight_monitor obstacle_injector \
  sensor_interface mapper; do
  n=$(grep -c ",$service," "$WORK/report/heartbeats.csv" || true)
  [[ $n -ge 3 ]] || fail "$service sent $n heartbeats"
done
pass "multi-process flight arrived; every service sent heartbeats; the wall was mapped"
