#!/usr/bin/env bash
# Replay: a recorded flight played back with lcm-logplayer drives a service
# that follows the replayed SIM_CLOCK (the flight monitor sees the arrival),
# and a recording of the replay gives the same flight report.
source "$(dirname "$0")/common.sh"
scenario="$REPO/sim/scenarios/open.yaml"
"$BIN/ofn_sim_runner" --scenario "$scenario" --config-dir "$REPO/config" --out "$WORK/orig" --quiet \
  > /dev/null || fail "lockstep flight failed"
lcm-logger --lcm-url="udpm://239.255.76.67:7667?ttl=0" "$WORK/replayed.lcm" > /dev/null 2>&1 &
logger=$!
"$BIN/ofn_flight_monitor" --clock sim --timeout 60 --every 20 > "$WORK/monitor.txt" 2>&1 &
monitor=$!
# Give the logger and the monitor time to subscribe: what they miss of the
# start of the replay would be missing from the comparison.
sleep 1.5
"$REPO/deploy/replay.sh" "$WORK/orig/flight.lcm" --speed 4 > "$WORK/replay.txt" 2>&1 ||
  { cat "$WORK/replay.txt"; fail "replay failed"; }
wait $monitor || { cat "$WORK/monitor.txt"; fail "monitor did not see the arrival in the replay"; }
kill -INT $logger; wait $logger || true
"$BIN/ofn_flight_report" --log "$WORK/replayed.lcm" --scenario "$scenario" --out "$WORK/again" \
  > "$WORK/again.txt" || fail "report of the replay failed"
orig=$(grep "gate-to-gate" "$WORK/orig/summary.txt")
again=$(grep "gate-to-gate" "$WORK/again.txt")
[[ "$orig" == "$again" ]] || fail "replayed flight differs: '$orig' vs '$again'"
pass "replayed flight drove the monitor and reproduced: $again"
