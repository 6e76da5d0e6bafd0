#!/usr/bin/env bash
# The benchmark campaign and the Monte Carlo fields in their short forms:
# bench1 and bench4 through campaign.py --quick, and through monte_carlo.py
# four random fields that once failed (seeds 64, 131 and 257: the inner
# network's pitch limit cycle; 225: a receding-horizon stall in front of a
# tall cylinder). Both courses and every field must succeed (finish gate,
# no limit exceeded by more than 2 %), both courses must stay outside R_s
# of the real obstacles, bench1 must go over its 140 ft wall and bench4
# round its 60 ft cube (their flown tracks), and the reports and figures
# must be written.
# (`monte_carlo.py --quick` flies four other random fields the same way;
# it is not run here, for time: the fields above are random fields too.)
source "$(dirname "$0")/common.sh"
status=0
/usr/bin/python3 "$REPO/bench/campaign.py" --bin "$BIN" --quick --out "$WORK/campaign" \
  > "$WORK/campaign.txt" 2>&1 || status=$?
cat "$WORK/campaign.txt"
/usr/bin/python3 "$REPO/bench/monte_carlo.py" --bin "$BIN" --seeds 64,131,225,257 \
  --out "$WORK/once_failed" > "$WORK/once_failed.txt" 2>&1 || status=$?
cat "$WORK/once_failed.txt"
/usr/bin/python3 - "$WORK" <<'PY' || fail "the campaign or the random fields did not come out as required"
import csv, json, os, sys
work = sys.argv[1]
ok = True

def need(cond, what):
    global ok
    if not cond:
        print("missing or wrong: " + what)
        ok = False

def nonempty(path):
    return os.path.isfile(path) and os.path.getsize(path) > 0

camp = os.path.join(work, "campaign")
need(nonempty(os.path.join(camp, "report.md")), "campaign/report.md")
need(os.path.isfile(os.path.join(camp, "results.json")), "campaign/results.json")
if ok:
    res = json.load(open(os.path.join(camp, "results.json")))
    courses = {c["course"]: c for c in res["courses"]}
    for name in ("bench1", "bench4"):
        c = courses.get(name)
        need(c is not None, "%s in campaign/results.json" % name)
        if c is None:
            continue
        print("%s: success %s, least clearance %s (R_s %s) %s" % (
            name, c["success"], c.get("min_clearance"), c.get("clearance_required"), c.get("display_unit")))
        need(c["success"], "%s succeeded (%s)" % (name, "; ".join(c.get("failures") or [])))
        need(c.get("min_clearance") is not None and c["min_clearance"] >= c["clearance_required"],
             "%s least clearance >= R_s" % name)
        need(nonempty(os.path.join(camp, "fig-%s.png" % name)), "campaign/fig-%s.png" % name)
    # The way each course is flown: bench1 over the wall, bench4 round the cube.
    ft = 0.3048
    for name, over in (("bench1", True), ("bench4", False)):
        track = os.path.join(camp, name, "nav_state.csv")
        need(nonempty(track), "campaign/%s/nav_state.csv" % name)
        if not nonempty(track):
            continue
        rows = [{k.split(" [")[0]: v for k, v in r.items()}  # "down [m]" -> "down"
                for r in csv.DictReader(open(track))]
        top = max(-float(r["down"]) for r in rows)
        wide = max(abs(float(r["east"])) for r in rows)
        print("%s: highest %.1f m, widest %.1f m" % (name, top, wide))
        if over:
            need(top >= (140 + 20) * ft - 0.5 and wide < 20 * ft, "bench1 climbed over the 140 ft wall")
        else:
            need(wide >= (30 + 20) * ft - 0.5 and top < (120 + 20) * ft,
                 "bench4 went round the 60 ft cube")
mc = os.path.join(work, "once_failed")
for name in ("report.md", "results.json", "clearance.png", "time_ratio.png"):
    need(nonempty(os.path.join(mc, name)), "once_failed/" + name)
once = os.path.join(mc, "results.json")
need(os.path.isfile(once), "once_failed/results.json")
if os.path.isfile(once):
    res = json.load(open(once))
    for r in res["results"]:
        print("field %d (once failed): success %s %s" % (r["seed"], r["success"], "; ".join(r["failures"])))
    need(sorted(r["seed"] for r in res["results"]) == [64, 131, 225, 257] and res["successes"] == 4,
         "fields 64, 131, 225 and 257 succeeded")
sys.exit(0 if ok else 1)
PY
[[ $status == 0 ]] || fail "campaign.py or monte_carlo.py exit code $status"
pass "bench1 over its wall and bench4 round its cube succeeded outside R_s, the four once-failed random fields succeeded, reports and figures written"
