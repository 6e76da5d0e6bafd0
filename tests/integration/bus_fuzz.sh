#!/usr/bin/env bash
# The bus fuzz's short version (bench/bus_fuzz.py; the full 10^6 messages
# are `make fuzz`): the open course flown by every service at four times
# real time, once without the fuzz and once while 20,000 fuzz messages go
# to every channel at 4,000 a second (every kind: cut short, wrong
# fingerprints, sizes up to 2^31, NaN and Inf in every float, stamps far
# from now, random bytes, oversized). Nothing crashes, hangs or restarts,
# every service is heard after the flood with its pid and has counted
# rejections, and none holds more than 16 MB beyond what it holds in the
# flight without the fuzz.
if [[ -z "${OFN_IN_NETNS:-}" ]] && ! unshare -n true 2> /dev/null &&
  ! unshare -rn true 2> /dev/null; then
  echo "SKIP: cannot create a private network namespace here (needs root or user namespaces)"
  exit 77
fi
source "$(dirname "$0")/common.sh"
status=0
/usr/bin/python3 "$REPO/bench/bus_fuzz.py" --bin "$BIN" --messages 20000 --rate 4000 \
  --scenario "$REPO/sim/scenarios/open.yaml" --rtf 4 --out "$WORK/fuzz" \
  > "$WORK/fuzz.txt" 2>&1 || status=$?
grep -v "^  fuzz: sent " "$WORK/fuzz.txt" | tail -40
[[ $status == 0 ]] || fail "bench/bus_fuzz.py exit code $status"
/usr/bin/python3 - "$WORK/fuzz/results.json" <<'PY' || fail "the fuzz's results do not hold"
import json, sys
r = json.load(open(sys.argv[1]))
fuzz = r["fuzz"]
kinds = ("truncated", "wrong_fingerprint", "size_field", "string_length", "non_finite",
         "extreme_number", "stamp", "random_bytes", "noise", "oversized")
missing = [k for k in kinds if fuzz["by_kind"].get(k, 0) == 0]
deaf = [s for s, e in fuzz["services"].items()
        if not e["alive"] or e["rejected_after"] <= e["rejected_before"]]
print("sent %d messages, %d kinds; crashes %d, restarts %d; flight %s"
      % (fuzz["messages"], len(fuzz["by_kind"]), r["crashes"], r["restarts"],
         r["flight"]["outcome"]))
ok = (fuzz["messages"] == 20000 and not missing and not deaf and r["crashes"] == 0
      and r["restarts"] == 0 and not r["failures"] and len(fuzz["services"]) >= 9)
if missing:
    print("kinds never sent:", missing)
if deaf:
    print("dead or counting nothing:", deaf)
sys.exit(0 if ok else 1)
PY
pass "20,000 fuzz messages on every channel: no crash, no restart, rejections counted, memory bounded"
