#!/usr/bin/env bash
# `cmake --install` of the build into a temporary prefix gives an outside
# project what docs/INSTALL.md promises: examples/consumer configures with
# find_package(ofn), builds warning-free and runs (message round trip,
# validator, global planner, B-spline); ofn.pc compiles and links an LCM
# program; examples/python/nav_track.py decodes a lockstep flight's log with
# the installed Python types (no python3-lcm) and agrees with the flight's
# CSV; and the Lua types round-trip a message where lua5.2 and liblcm-lua are
# installed. The build folder is BIN_DIR/..; cmake writes only its
# install_manifest.txt there.
source "$(dirname "$0")/common.sh"
BUILD=$(cd "$BIN/.." && pwd)
PREFIX=$WORK/prefix
[[ -f $BUILD/cmake_install.cmake ]] || fail "$BUILD is not a configured build folder"
unset DESTDIR PYTHONPATH

# 1. Install: copying only.
env -u DESTDIR cmake --install "$BUILD" --prefix "$PREFIX" > "$WORK/install.txt" 2>&1 ||
  { cat "$WORK/install.txt"; fail "cmake --install failed"; }
for f in lib/libofn_common.a lib/libofn_bspline.a lib/libofn_bus_auth.a lib/libofn_world.a lib/libofn_rotorcraft_model.a lib/libofn_vehicle_core.a \
         lib/libofn_controller_core.a lib/libofn_sensor_interface_core.a lib/libofn_map.a lib/libofn_mapper_core.a \
         lib/libofn_global_planner_core.a lib/libofn_rh_optimizer_core.a lib/libofn_time_optimal.a \
         include/ofn/nav_state_t.hpp include/ofn/common/validate.hpp include/ofn/mapper/mapper.hpp include/ofn/map/distance_field.hpp \
         include/ofn/rotorcraft_model/rotorcraft_model.hpp include/ofn/sim/time_optimal.hpp \
         share/ofn/python/ofn/__init__.py share/ofn/python/ofn/nav_state_t.py \
         share/ofn/lua/ofn/init.lua share/ofn/lua/ofn/nav_state_t.lua \
         lib/cmake/ofn/ofnConfig.cmake lib/cmake/ofn/ofnConfigVersion.cmake lib/cmake/ofn/ofnTargets.cmake \
         lib/cmake/ofn/Dependencies.cmake lib/pkgconfig/ofn.pc; do
  [[ -f $PREFIX/$f ]] || fail "not installed: $f"
done
# Every message type in every binding.
for lcm in "$REPO"/lcmtypes/*.lcm; do
  t=$(basename "$lcm" .lcm)
  for f in "include/ofn/$t.hpp" "share/ofn/lcmtypes/$t.lcm" "share/ofn/python/ofn/$t.py" "share/ofn/lua/ofn/$t.lua"; do
    [[ -f $PREFIX/$f ]] || fail "not installed: $f"
  done
done
grep -q "counts and string lengths bounded" "$PREFIX/include/ofn/nav_state_t.hpp" ||
  fail "the installed message headers are not the hardened ones"
if [[ -f $BUILD/lcmtypes/ofn_lcmtypes.jar ]]; then
  [[ -f $PREFIX/share/java/ofn_lcmtypes.jar ]] || fail "the build made the Java types jar but it was not installed"
fi

# 2. An outside CMake project: find_package(ofn), -Wall -Wextra clean, runs.
cmake -S "$REPO/examples/consumer" -B "$WORK/consumer" -DCMAKE_PREFIX_PATH="$PREFIX" \
  > "$WORK/consumer.txt" 2>&1 || { cat "$WORK/consumer.txt"; fail "the consumer did not configure"; }
grep -qx "ofn_DIR:PATH=$PREFIX/lib/cmake/ofn" "$WORK/consumer/CMakeCache.txt" ||
  fail "find_package(ofn) did not take the package from $PREFIX"
cmake --build "$WORK/consumer" > "$WORK/consumer_build.txt" 2>&1 ||
  { cat "$WORK/consumer_build.txt"; fail "the consumer did not build"; }
if grep -q "warning:" "$WORK/consumer_build.txt"; then
  cat "$WORK/consumer_build.txt"; fail "the consumer built with warnings"
fi
"$WORK/consumer/ofn_consumer" > "$WORK/consumer_run.txt" 2>&1 ||
  { cat "$WORK/consumer_run.txt"; fail "the consumer failed"; }
grep -qx "0 failed" "$WORK/consumer_run.txt" || { cat "$WORK/consumer_run.txt"; fail "the consumer printed no verdict"; }

# 3. pkg-config: message headers and LCM, enough to build an LCM program.
export PKG_CONFIG_PATH=$PREFIX/lib/pkgconfig
flags=$(pkg-config --cflags --libs ofn) || fail "pkg-config --cflags --libs ofn failed"
echo "pkg-config --cflags --libs ofn: $flags"
[[ " $flags " == *" -I$PREFIX/"*"include "* && " $flags " == *" -llcm "* ]] ||
  fail "ofn.pc does not give the installed include folder and -llcm"
[[ $(pkg-config --variable=pythondir ofn) -ef $PREFIX/share/ofn/python ]] || fail "ofn.pc: pythondir is wrong"
cat > "$WORK/pc_memq.cpp" <<'EOF'
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include "ofn/nav_state_t.hpp"
struct Receiver {
  int got = 0;
  double north = 0;
  void on_nav(const lcm::ReceiveBuffer*, const std::string&, const ofn::nav_state_t* msg) {
    ++got;
    north = msg->position[0];
  }
};
int main() {
  lcm::LCM bus("memq://");
  if (!bus.good()) return 1;
  Receiver receiver;
  bus.subscribe("NAV_STATE", &Receiver::on_nav, &receiver);
  ofn::nav_state_t msg{};
  msg.frame = "NED";
  msg.position[0] = 12.5;
  bus.publish("NAV_STATE", &msg);
  bus.handle();
  std::printf("received %d, north %.1f\n", receiver.got, receiver.north);
  return receiver.got == 1 && receiver.north == 12.5 ? 0 : 1;
}
EOF
# shellcheck disable=SC2086  # the flags are words
c++ -std=c++17 -Wall -Wextra -o "$WORK/pc_memq" "$WORK/pc_memq.cpp" $flags > "$WORK/pc_build.txt" 2>&1 ||
  { cat "$WORK/pc_build.txt"; fail "a program did not build with ofn.pc's flags"; }
! grep -q "warning:" "$WORK/pc_build.txt" || { cat "$WORK/pc_build.txt"; fail "warnings with ofn.pc's flags"; }
"$WORK/pc_memq" || fail "the pkg-config program did not receive its message"

# 4. Python: a short lockstep flight's log, decoded with the installed types
# by the example, agrees with the nav_state.csv the flight report wrote.
"$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/open.yaml" --config-dir "$REPO/config" \
  --out "$WORK/flight" --max-time 8 --quiet > "$WORK/flight.txt" 2>&1 || true  # 8 s: not arrived, exit 1
[[ -s $WORK/flight/flight.lcm && -s $WORK/flight/nav_state.csv ]] ||
  { cat "$WORK/flight.txt"; fail "the lockstep flight wrote no log"; }
/usr/bin/python3 -c "import lcm" 2>/dev/null && echo "(python3-lcm is installed; the example does not use it)"
PYTHONPATH=$PREFIX/share/ofn/python /usr/bin/python3 "$REPO/examples/python/nav_track.py" \
  "$WORK/flight/flight.lcm" || fail "nav_track.py failed on the flight's log"
PYTHONPATH=$PREFIX/share/ofn/python /usr/bin/python3 "$REPO/examples/python/nav_track.py" --json \
  "$WORK/flight/flight.lcm" > "$WORK/track.json" || fail "nav_track.py --json failed"
/usr/bin/python3 - "$WORK" "$PREFIX/share/ofn/python" "$REPO/examples/python" <<'PY' ||
import csv, json, math, struct, sys
work, types, example = sys.argv[1:4]
track = json.load(open(f"{work}/track.json"))
# Headers carry units ("north [m]"); the bare names are read.
rows = [{k.split(" [")[0]: v for k, v in r.items()}
        for r in csv.DictReader(open(f"{work}/flight/nav_state.csv"))]
def pos(r): return [float(r["north"]), float(r["east"]), float(r["down"])]
top = max(math.sqrt(sum(float(r[k]) ** 2 for k in ("vn", "ve", "vd"))) for r in rows)
close = lambda a, b: all(abs(x - y) <= 1e-6 * max(1.0, abs(y)) for x, y in zip(a, b))
assert track["messages"] == len(rows), (track["messages"], len(rows))
assert close(track["first_position"], pos(rows[0])), (track["first_position"], pos(rows[0]))
assert close(track["last_position"], pos(rows[-1])), (track["last_position"], pos(rows[-1]))
assert close([track["top_speed"]], [top]), (track["top_speed"], top)
assert track["duration_s"] > 7.9 and track["frame"] == "NED", track

# A log written here with the generated types: garbage between two events and
# a last event cut short are skipped, as LCM's reader skips them.
sys.path[:0] = [types, example]
from ofn import nav_state_t
import nav_track
def event(n, msg):
    data = msg.encode()
    return struct.pack(">IqqII", 0xEDA1DA01, n, 1000 * n, 9, len(data)) + b"NAV_STATE" + data
msgs = []
for n, (north, speed) in enumerate([(1.0, 2.0), (2.0, 5.0), (3.0, 1.0)]):
    m = nav_state_t(); m.utime = 10000 * (n + 1); m.frame = "NED"
    m.position = [north, 0.5, -20.0]; m.velocity = [speed, 0.0, 0.0]; m.quaternion = [1.0, 0, 0, 0]
    msgs.append(m)
cut = event(3, msgs[0])
with open(f"{work}/small.lcm", "wb") as f:
    f.write(event(0, msgs[0]) + b"\x00\xed\xa1junk" + event(1, msgs[1]) + event(2, msgs[2]) + cut[:-5])
s = nav_track.summarise(f"{work}/small.lcm", "NAV_STATE", nav_state_t)
assert s["messages"] == 3 and s["first_position"] == [1.0, 0.5, -20.0], s
assert s["last_position"] == [3.0, 0.5, -20.0] and s["top_speed"] == 5.0, s
assert abs(s["duration_s"] - 0.02) < 1e-12, s
print(f"python: {track['messages']} NAV_STATE messages agree with nav_state.csv; the written log reads back")
PY
  fail "nav_track.py's summary does not match the flight or the written log"

# 5. Lua, where its runtime is installed (Debian: lua5.2 liblcm-lua).
if command -v lua5.2 > /dev/null && lua5.2 -e "require('lcm')" 2> /dev/null; then
  LUA_PATH="$PREFIX/share/ofn/lua/?.lua;$PREFIX/share/ofn/lua/?/init.lua;;" lua5.2 -e "
    local ofn = require('ofn')
    local m = ofn.nav_state_t:new()
    m.utime = 42; m.frame = 'NED'; m.position = {1.5, -2.0, -30.0}
    local back = ofn.nav_state_t.decode(m:encode())
    assert(back.utime == 42 and back.frame == 'NED' and back.position[3] == -30.0)
    print('lua: nav_state_t round trip')" || fail "the Lua types do not round-trip a message"
else
  echo "lua: skipped (lua5.2 or liblcm-lua not installed)"
fi
pass "the installed package works from CMake, pkg-config and Python (Lua above)"
