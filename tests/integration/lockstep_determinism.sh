#!/usr/bin/env bash
# The lockstep runner is deterministic: two runs of the same scenario give
# identical navigation, control, actuator and planning streams, and the
# flight arrives. bench4: every service is busy (mapping, global route,
# RH optimisation round the cube).
source "$(dirname "$0")/common.sh"
for run in a b; do
  "$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench4.yaml" --config-dir "$REPO/config" \
    --out "$WORK/$run" --quiet > "$WORK/$run.txt" || { cat "$WORK/$run.txt"; fail "run $run did not arrive"; }
done
# Heartbeats carry wall-clock load figures and the pid; everything the
# flight is made of must match to the bit, and so must what the heartbeats
# count of each input (inputs.csv).
for f in nav_state control_status actuator_cmd waypoints global_path ref_traj inputs; do
  cmp "$WORK/a/$f.csv" "$WORK/b/$f.csv" || fail "$f differs between the two runs"
done
# The logs byte for byte, heartbeats aside (and SOLVER_STATS but for its
# trailer: it holds a solve's wall time): every message's sequence trailer
# too, whose publisher ids lockstep derives, never draws.
/usr/bin/python3 - "$WORK/a/flight.lcm" "$WORK/b/flight.lcm" <<'PY' || fail "the logs differ"
import struct, sys
def events(path):
    data, i, out = open(path, "rb").read(), 0, []
    while i + 28 <= len(data):
        _, _, stamp, channel_length, data_length = struct.unpack(">IqqII", data[i:i + 28])
        channel = data[i + 28:i + 28 + channel_length]
        payload = data[i + 28 + channel_length:i + 28 + channel_length + data_length]
        i += 28 + channel_length + data_length
        if channel == b"SOLVER_STATS":
            payload = payload[-20:]
        if not channel.startswith(b"HEARTBEAT_"):
            out.append((stamp, channel, payload))
    return out
a, b = events(sys.argv[1]), events(sys.argv[2])
numbered = sum(1 for _, _, p in a if p.endswith(b"OFS1"))
print("%d messages, heartbeats aside, %d of them numbered" % (len(a), numbered))
for n, (x, y) in enumerate(zip(a, b)):
    if x != y:
        print("message %d differs first: %s at %d us" % (n, x[1].decode(), x[0]))
        break
sys.exit(0 if a == b and len(a) > 1000 and numbered == len(a) else 1)
PY
# Solver reports match except for the wall time each solve took.
cmp <(cut -d, -f1-3,5- "$WORK/a/solver_stats.csv") <(cut -d, -f1-3,5- "$WORK/b/solver_stats.csv") ||
  fail "solver reports differ between the two runs"
n=$(wc -l < "$WORK/a/nav_state.csv")
[[ $n -gt 1000 ]] || fail "only $n navigation samples"
grep -q "reached the last waypoint" "$WORK/a.txt" || fail "summary does not report arrival"
pass "two lockstep runs identical ($n navigation samples)"
