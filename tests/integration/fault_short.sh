#!/usr/bin/env bash
# The fault suite's short version: bench3 on the three-host split with 30 %
# of the datagrams dropped on every link between the hosts, the whole
# flight. Most multi-fragment messages (scans, plans) never arrive; the
# vehicle must not fly on blind: no violation of the benchmark rules
# (outcome success, or a safe stop when the link allows no progress).
source "$(dirname "$0")/common.sh"
skip_without_named_netns
command -v nft > /dev/null || fail "nft is missing: run 'make test-deps' (the Makefile installs nftables)"

status=0
/usr/bin/python3 "$REPO/bench/fault_suite.py" --only loss-30 --rtf 2 --timeout 150 \
  --bin "$BIN" --out "$WORK/faults" > "$WORK/suite.txt" 2>&1 || status=$?
cat "$WORK/suite.txt"
cat "$WORK/faults/report.md" 2> /dev/null || fail "no fault report (exit code $status)"
/usr/bin/python3 - "$WORK/faults/results.json" <<'PY' || fail "a rule was broken under 30 % loss"
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert len(rows) == 1, rows
r = rows[0]
print("%s: outcome %s, applied: %s, failures: %s" % (r["name"], r["outcome"], r["applied"], r["failures"]))
sys.exit(0 if r["applied"].startswith("dropping") and r["outcome"] in ("success", "safe_stop") else 1)
PY
pass "30 % loss between the hosts: no rule broken"
