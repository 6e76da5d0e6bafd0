#!/usr/bin/env bash
# Loss is visible: bench3 in the lockstep runner with 10 % of the datagrams
# between hosts lost (deploy/processes.yaml's split, the runner's
# --link-loss). Every service's heartbeats count, per input channel, the
# gaps in its publishers' sequence numbers. The inputs that cross from one
# host to another must show loss, at about the rate the link lost; those
# within a host, where nothing is lost, none and no copies; no message is
# unsequenced. Who publishes a channel is read from the log itself: the
# node whose heartbeat carries the same publisher id.
source "$(dirname "$0")/common.sh"
# The outcome is not what is judged here (exit 1 is a failed flight);
# bad input or a crash is.
code=0
"$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench3.yaml" --config-dir "$REPO/config" \
  --process-table "$REPO/deploy/processes.yaml" --link-loss 0.1 --link-seed 1 \
  --out "$WORK/lossy" --quiet > "$WORK/lossy.txt" 2>&1 || code=$?
[[ $code -le 1 && -s "$WORK/lossy/summary.json" ]] || { cat "$WORK/lossy.txt"; fail "the runner failed (exit $code)"; }
grep -E "^link faults|^  outcome|^  messages lost" "$WORK/lossy.txt"
grep -q "^  messages lost     : [1-9]" "$WORK/lossy.txt" || fail "the report shows no lost messages"
/usr/bin/python3 - "$WORK/lossy/flight.lcm" "$WORK/lossy/summary.json" "$REPO/deploy/processes.yaml" <<'PY' ||
import json, struct, sys
import yaml

log_path, summary_path, table_path = sys.argv[1:4]
host = {p["name"]: p["host"] for p in yaml.safe_load(open(table_path))["processes"]}

# The log: sync, event number, timestamp, channel length, data length.
data, i = open(log_path, "rb").read(), 0
service_of_id, ids_of_channel, unsequenced = {}, {}, 0
while i + 28 <= len(data):
    _, _, _, channel_length, data_length = struct.unpack(">IqqII", data[i:i + 28])
    channel = data[i + 28:i + 28 + channel_length].decode()
    payload = data[i + 28 + channel_length:i + 28 + channel_length + data_length]
    i += 28 + channel_length + data_length
    if payload[-4:] != b"OFS1":  # the sequence trailer: id, sequence, magic
        unsequenced += 1
        continue
    publisher = payload[-20:-12]
    if channel.startswith("HEARTBEAT_"):
        service_of_id[publisher] = channel[len("HEARTBEAT_"):].lower()
    else:
        ids_of_channel.setdefault(channel, set()).add(publisher)
failures = []
if unsequenced:
    failures.append("%d messages in the log without a sequence trailer" % unsequenced)
publisher_of = {}
for channel, ids in ids_of_channel.items():
    names = {service_of_id.get(p, "?") for p in ids}
    if len(names) != 1 or "?" in names:
        failures.append("%s: publishers %s" % (channel, sorted(names)))
    publisher_of[channel] = sorted(names)[0]

crossing = within = 0
for row in json.load(open(summary_path))["inputs"]:
    channel, service = row["channel"], row["service"]
    if row["received"] == 0 or channel not in publisher_of:
        continue
    source = publisher_of[channel]
    sent = row["received"] - row["duplicated"] - row["unsequenced"] + row["lost"]
    link = "%s -> %s" % (host[source], host[service])
    print("  %-16s %-18s from %-17s %-19s %5d of %6d lost, %d duplicated, %d unsequenced"
          % (service, channel, source, link, row["lost"], sent, row["duplicated"],
             row["unsequenced"]))
    if row["unsequenced"]:
        failures.append("%s %s: %d unsequenced" % (service, channel, row["unsequenced"]))
    if host[source] != host[service]:
        if sent >= 30:
            crossing += 1
            if row["lost"] == 0:
                failures.append("%s %s crosses %s but shows no loss" % (service, channel, link))
            # One datagram each: lost about as often as the link loses one.
            if channel == "NAV_STATE" and not 0.07 <= row["lost"] / sent <= 0.13:
                failures.append("%s NAV_STATE: %.3f lost, not about 0.1" % (service, row["lost"] / sent))
    else:
        within += 1
        if row["lost"] or row["duplicated"]:
            failures.append("%s %s stays on %s but shows %d lost, %d duplicated"
                            % (service, channel, host[service], row["lost"], row["duplicated"]))
if crossing < 8 or within < 8:
    failures.append("only %d crossing and %d same-host inputs judged" % (crossing, within))
for f in failures:
    print("FAIL:", f)
print("%d inputs across hosts, %d within one" % (crossing, within))
sys.exit(1 if failures else 0)
PY
  fail "the heartbeats' loss does not match the lossy links"
pass "bench3 at 10 % datagram loss between hosts: loss on every crossing input, none within a host"
