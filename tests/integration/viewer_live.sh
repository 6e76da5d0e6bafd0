#!/usr/bin/env bash
# The live viewer on real traffic: a lockstep flight round bench4's cube is
# played back with deploy/replay.sh into ofn_viewer on the test's private
# bus; the snapshot over HTTP shows the vehicle moved along the course with
# the map, the route and the plans, the event stream carries snapshots, and
# headless Chromium shows the page with its readouts filled and the trail
# drawn (a screenshot before the replay has none), the stream live; and
# deploy/watch.sh's viewer shows a replay in a namespace of its own.
source "$(dirname "$0")/common.sh"
command -v chromium > /dev/null || fail "chromium is missing: run 'make test-deps' (the Makefile installs it)"
/usr/bin/python3 -c "import PIL" 2> /dev/null || fail "Pillow is missing: run 'make test-deps'"

"$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench4.yaml" --config-dir "$REPO/config" \
  --out "$WORK/flight" --quiet > "$WORK/flight.txt" 2>&1 ||
  { cat "$WORK/flight.txt"; fail "lockstep flight failed"; }

"$BIN/ofn_viewer" --port 0 --url-file "$WORK/url" > "$WORK/viewer.log" 2>&1 &
viewer=$!
trap 'kill $viewer 2> /dev/null || true; rm -rf "$WORK"' EXIT
for _ in $(seq 200); do
  [[ -s "$WORK/url" ]] && break
  kill -0 $viewer 2> /dev/null || { cat "$WORK/viewer.log"; fail "the viewer did not start"; }
  sleep 0.1
done
[[ -s "$WORK/url" ]] || { cat "$WORK/viewer.log"; fail "the viewer wrote no URL"; }
url=$(head -n 1 "$WORK/url")

# The page before any traffic: its screenshot is the baseline.
mkdir "$WORK/before" "$WORK/after"
/usr/bin/python3 "$REPO/tests/integration/viewer_page.py" "$url" "$WORK/before" 1 ||
  fail "headless chromium did not show the page before the replay"

"$REPO/deploy/replay.sh" "$WORK/flight/flight.lcm" --speed 8 > "$WORK/replay.txt" 2>&1 ||
  { cat "$WORK/replay.txt"; fail "replay failed"; }

# The snapshot over HTTP once the viewer has taken in the whole log (its
# count of navigation messages no longer grows), then the first event of
# the stream.
/usr/bin/python3 - "$url" "$WORK" <<'PY' || { tail -n 20 "$WORK/viewer.log"; fail "the snapshot does not show the flight"; }
import json, sys, time, urllib.request
url, work = sys.argv[1], sys.argv[2]
def snapshot():
    with urllib.request.urlopen(url + "api/snapshot", timeout=10) as r:
        return json.load(r)
def navs(s):
    return s["counters"]["accepted"].get("NAV_STATE", 0)
s = snapshot()
for _ in range(100):
    time.sleep(0.3)
    again = snapshot()
    if navs(again) == navs(s) and navs(s) > 0:
        break
    s = again
json.dump(s, open(work + "/snapshot.json", "w"))
problems = []
v = s["vehicle"]
if v is None:
    sys.exit("no vehicle in the snapshot")
start, end = s["trail"][0], v["position"]
flown = end[0] - start[0]
print("vehicle from north %.1f to %.1f m, trail %d points, %.0f m; mode %s; solver %s; "
      "%d cuboids; clearance %.1f m"
      % (start[0], end[0], len(s["trail"]), s["trail_length"], s["control"]["mode"],
         s["solver"]["status"], len(s["cuboids"]), v["clearance"]))
if flown < 100:
    problems.append("the vehicle moved only %.1f m north" % flown)
if s["trail_length"] < 100:
    problems.append("trail only %.1f m long" % s["trail_length"])
if s["control"]["mode"] not in ("HOLD", "WAYPOINT", "TRAJECTORY", "NAV_STALE", "DONE", "SAFE_STOP"):
    problems.append("control mode %r" % s["control"]["mode"])
for layer in ("global_path", "ref_traj", "mission", "obstacles", "solver"):
    if s[layer] is None:
        problems.append("no %s in the snapshot" % layer)
if not s["cuboids"]:
    problems.append("no mapped cuboids")
if not (v["clearance"] > 0):
    problems.append("no true clearance")
if s["counters"]["rejected_total"] != 0:
    problems.append("rejected inputs of a clean flight: %s" % s["counters"]["rejected"])
# The stream: its first event is a whole snapshot of the same flight.
with urllib.request.urlopen(url + "api/stream", timeout=10) as r:
    line = r.readline().decode()
    while not line.startswith("data: "):
        line = r.readline().decode()
event = json.loads(line[len("data: "):])
if event["vehicle"] is None or event["trail_length"] < 100:
    problems.append("the stream's snapshot does not show the flight")
if problems:
    sys.exit("; ".join(problems))
PY

# The page in a real browser, once it has drawn three snapshots from the
# stream: its elements, the readouts filled with numbers, the trail drawn.
/usr/bin/python3 "$REPO/tests/integration/viewer_page.py" "$url" "$WORK/after" 3 ||
  fail "headless chromium did not show the page after the replay"
/usr/bin/python3 - "$WORK" <<'PY' || fail "the page does not show the flight"
import json, re, sys
from PIL import Image
work = sys.argv[1]
page = json.load(open(work + "/after/page.json"))
problems = []
for element in ("top-view", "profile-view", "readouts"):
    if element not in page["ids"]:
        problems.append("no #%s" % element)
if page["text"]["connection"] != "live":
    problems.append("the stream is not live: %r" % page["text"]["connection"])
number = r"-?\d+(\.\d+)?"
expect = {"ro-speed": r"^%s ft/s$" % number, "ro-altitude": r"^%s ft$" % number,
          "ro-clearance": r"^%s ft \((obstacle|ground)\)$" % number,
          "ro-mode": r"^(HOLD|WAYPOINT|TRAJECTORY|NAV_STALE|DONE|SAFE_STOP)",
          "ro-solver": r"^[A-Z_]+ \(\d+ it\)$", "ro-trail": r"^\d+ points, \d+ ft$",
          "ro-map": r"^[1-9]\d* cuboids", "ro-route": r"^[A-Z_]+, \d+ points$"}
for element, pattern in expect.items():
    text = page["text"].get(element, "")
    print("%-12s %s" % (element, text))
    if not re.search(pattern, text):
        problems.append("#%s reads %r" % (element, text))

def trail_pixels(path):
    # The trail's colour (#1f5fbf), give or take the anti-aliasing.
    image = Image.open(path).convert("RGB")
    return sum(1 for (r, g, b) in image.getdata()
               if abs(r - 0x1f) < 24 and abs(g - 0x5f) < 24 and abs(b - 0xbf) < 24)
before, after = trail_pixels(work + "/before/page.png"), trail_pixels(work + "/after/page.png")
print("trail-coloured pixels: %d before the replay, %d after" % (before, after))
if after < before + 300:
    problems.append("the screenshot shows no trail (%d pixels, %d before)" % (after, before))
if problems:
    sys.exit("; ".join(problems))
PY

# deploy/watch.sh: the same log in a namespace of its own, with a viewer
# that serves here and listens there. Its page shows the vehicle; none of
# that traffic reaches this namespace's bus (the first viewer's count of
# navigation messages stays as it was).
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$REPO/deploy/watch.sh" --port "$port" --bin "$BIN" --log "$WORK/watch_viewer.log" -- \
  "$REPO/deploy/replay.sh" "$WORK/flight/flight.lcm" --speed 8 > "$WORK/watch.txt" 2>&1 &
watch=$!
/usr/bin/python3 - "$url" "http://127.0.0.1:$port/" <<'PY' || { cat "$WORK/watch.txt"; kill $watch; fail "deploy/watch.sh's viewer did not show the flight"; }
import json, sys, time, urllib.request
def snapshot(url):
    with urllib.request.urlopen(url + "api/snapshot", timeout=10) as r:
        return json.load(r)
def navs(s):
    return s["counters"]["accepted"].get("NAV_STATE", 0)
here_before = navs(snapshot(sys.argv[1]))
seen = None
for _ in range(600):
    try:
        s = snapshot(sys.argv[2])
    except OSError:
        time.sleep(0.1)  # not serving yet
        continue
    if s["vehicle"] is not None and s["trail_length"] > 20:
        seen = s
        break
    time.sleep(0.1)
if seen is None:
    sys.exit("no vehicle on the watched bus")
here_after = navs(snapshot(sys.argv[1]))
print("watched bus: vehicle at north %.1f m, trail %.0f m; this namespace's bus: %d -> %d NAV_STATE"
      % (seen["vehicle"]["position"][0], seen["trail_length"], here_before, here_after))
if here_after != here_before:
    sys.exit("the watched replay reached this namespace's bus")
PY
wait $watch || { cat "$WORK/watch.txt"; fail "deploy/watch.sh exited with code $?"; }
grep -q "no private network namespace" "$WORK/watch.txt" && { cat "$WORK/watch.txt"; fail "watch.sh did not make a namespace"; }
pass "the viewer showed the replayed flight in the browser, and beside a namespace of its own"
