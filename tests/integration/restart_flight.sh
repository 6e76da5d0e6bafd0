#!/usr/bin/env bash
# Killing the controller mid-flight: the launcher restarts it, the restarted
# controller picks up the mission where the vehicle is, and the flight
# still completes. Then killing vehicle_sim: the restarted simulator
# resumes the same flight from its checkpoint (no jump back to the start).
source "$(dirname "$0")/common.sh"
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/open.yaml" \
  --bin "$BIN" --rtf 4 --out "$WORK/run" --timeout 150 --no-pin > "$WORK/launch.txt" 2>&1 &
launcher=$!
# Wait until the vehicle is well into the flight (about 20 s of flight time).
sleep 6
# Only this launcher's controller: tests run side by side share the process
# table (the network namespace is private, the PID namespace is not).
pkill -KILL -P $launcher -f "$BIN/ofn_controller" || fail "no controller process to kill"
echo "killed the controller"
sleep 4
pkill -KILL -P $launcher -f "$BIN/ofn_vehicle_sim" || fail "no vehicle_sim process to kill"
echo "killed vehicle_sim"
wait $launcher || { tail -40 "$WORK/launch.txt"; fail "launcher exit code $?"; }
grep -qi "controller exited" "$WORK/launch.txt" || fail "launcher did not notice the controller exit"
grep -qi "restarting" "$WORK/launch.txt" || fail "launcher did not restart the controller"
log=$(cat "$WORK/run/latest_log")
# Exit 1 is the report's verdict of failure; this test asks for completion.
"$BIN/ofn_flight_report" --log "$log" --scenario "$REPO/sim/scenarios/open.yaml" \
  --out "$WORK/report" > "$WORK/report.txt" || [[ $? == 1 ]] || fail "report failed"
cat "$WORK/report.txt"
grep -q "reached the last waypoint, crossed the finish gate" "$WORK/report.txt" ||
  fail "the flight did not complete after the restart"
grep -q "resumed from the checkpoint" "$WORK/launch.txt" ||
  fail "the restarted vehicle_sim did not resume from its checkpoint"
if grep -q "reference jump (" "$WORK/report.txt"; then
  fail "the reference jumped across the restarts"
fi
pass "controller and vehicle_sim restarted by the launcher; the flight went on and completed"
