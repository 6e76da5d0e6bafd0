#!/usr/bin/env bash
# Bad command lines and files get a clear message and exit code 2 (an input
# error, which the launcher never restarts), never a crash; and every
# program in the build follows the command-line convention
# (services/common/include/ofn/common/command_line.hpp): a usage error is one
# line on stderr, --version prints the project version, --help every default.
source "$(dirname "$0")/common.sh"
expect_error() {  # expect_error "pattern" command...
  local pattern=$1; shift
  set +e; "$@" > "$WORK/out.txt" 2>&1; local code=$?; set -e
  [[ $code -eq 2 ]] || { cat "$WORK/out.txt"; fail "'$*' exited $code, not 2"; }
  grep -q -- "$pattern" "$WORK/out.txt" || { cat "$WORK/out.txt"; fail "'$*' did not say '$pattern'"; }
}
expect_error "^ofn_controller: error: .*not expected: --no-such-flag (see --help)$" \
  "$BIN/ofn_controller" --no-such-flag
expect_error "^ofn_flight_monitor: error: --timeout: expected a number >= 0, got '-1'" \
  "$BIN/ofn_flight_monitor" --timeout -1
# The bound in a few digits, not the largest double in full.
expect_error "^ofn_sim_runner: error: --max-time: expected a number > 0, got 'abc' (see --help)$" \
  "$BIN/ofn_sim_runner" --max-time abc
expect_error "^ofn_vehicle_sim: error: --scenario: " "$BIN/ofn_vehicle_sim" --scenario
# --rtf, as launch.py and fly.sh name it; --real-time-factor its other name.
expect_error "^ofn_vehicle_sim: error: --rtf: expected a number in \[0.01, 1000\], got '0'" \
  "$BIN/ofn_vehicle_sim" --scenario "$WORK/none.yaml" --rtf 0
for rtf in --rtf --real-time-factor; do
  expect_error "none.yaml" "$BIN/ofn_vehicle_sim" --scenario "$WORK/none.yaml" $rtf 2
done
"$BIN/ofn_vehicle_sim" --help | grep -q -- "--rtf,--real-time-factor" || fail "ofn_vehicle_sim --help lacks --rtf"
expect_error "scenario is required\|--scenario is required" "$BIN/ofn_mission_uplink"
cat > "$WORK/bad.yaml" <<'YAML'
name: bad
units: ft
start: {position: [0, 0, 100], speed: 5}
waypoints:
  - position: [0, 0]
limits: {max_speed: 10, max_accel: 1.6, max_vertical_speed: 5}
YAML
expect_error "bad.yaml: field 'waypoints\[0\].position'" "$BIN/ofn_sim_runner" --scenario "$WORK/bad.yaml"
sed -i 's/units: ft/units: yards/' "$WORK/bad.yaml"
expect_error "field 'units': expected 'ft' or 'm'" "$BIN/ofn_mission_uplink" --scenario "$WORK/bad.yaml"
printf 'outer_loop:\n  position_gian: [1, 1, 1]\n' > "$WORK/ctl.yaml"
expect_error "ctl.yaml: unknown field 'outer_loop.position_gian'" "$BIN/ofn_controller" --config "$WORK/ctl.yaml"
printf 'rate_hz: fast\n' > "$WORK/ctl.yaml"
expect_error "field 'rate_hz': expected a number" "$BIN/ofn_controller" --config "$WORK/ctl.yaml"
printf 'nominal_airframe:\n  rotor_radius: 0\n' > "$WORK/ctl.yaml"
expect_error "field 'nominal_airframe.rotor_radius'" "$BIN/ofn_controller" --config "$WORK/ctl.yaml"
expect_error "File does not exist" "$BIN/ofn_controller" --config "$WORK/missing.yaml"
printf 'not: [valid' > "$WORK/broken.yaml"
expect_error "broken.yaml: line" "$BIN/ofn_sim_runner" --scenario "$WORK/broken.yaml"
expect_error "no valid NAV_STATE\|cannot read" "$BIN/ofn_flight_report" --log "$WORK/ctl.yaml" --out "$WORK/r"
# The authenticated bus: a keyring that cannot be used is an input error
# naming the file or the role, before the service joins the bus.
"$BIN/ofn_bus_keygen" --policy "$REPO/config/bus_policy.yaml" --out "$WORK/keys" > /dev/null ||
  fail "ofn_bus_keygen could not make a keyring"
expect_error "already holds a keyring" "$BIN/ofn_bus_keygen" --policy "$REPO/config/bus_policy.yaml" \
  --out "$WORK/keys"
expect_error "cannot read publish policy 'config/bus_policy.yaml' (run from the repository root" \
  "$BIN/ofn_bus_keygen" --out "$WORK/other-keys"
expect_error "go together" "$BIN/ofn_controller" --bus-keys "$WORK/keys"
expect_error "role 'gcs' may not publish on HEARTBEAT_CONTROLLER" \
  "$BIN/ofn_controller" --bus-keys "$WORK/keys" --bus-role gcs
expect_error "is not in .*policy.yaml" "$BIN/ofn_mapper" --bus-keys "$WORK/keys" --bus-role ground
chmod 644 "$WORK/keys/onboard2.key"
expect_error "may be read by others" "$BIN/ofn_mapper" --bus-keys "$WORK/keys" --bus-role onboard2
# The viewer's own input errors.
expect_error "holds no index.html" "$BIN/ofn_viewer" --web-root "$WORK"
expect_error "lcm-netns: cannot open '$WORK/no-such-ns'" "$BIN/ofn_viewer" --port 0 --lcm-netns "$WORK/no-such-ns"
expect_error "^ofn_viewer: error: --port: .*70000" "$BIN/ofn_viewer" --port 70000

# Every program of the build, found in it rather than listed here, so that a
# new one cannot be forgotten. A Google Test or Google Benchmark executable
# says so in its --help and has its framework's command line instead.
version=$(sed -n 's/^project(.*VERSION \([0-9.]*\).*/\1/p' "$REPO/CMakeLists.txt")
[[ $version =~ ^[0-9]+\.[0-9]+\.[0-9]+$ ]] || fail "no project version in CMakeLists.txt"
programs=()
for path in "$BIN"/ofn_*; do
  [[ -f $path && -x $path ]] || continue
  help=$(timeout 30 "$path" --help 2>&1 || true)
  if grep -q "Google Test\|--benchmark_" <<< "$help"; then continue; fi
  programs+=("$(basename "$path")")
done
(( ${#programs[@]} > 0 )) || fail "no program found in $BIN"
# The flight's own processes must be among them: a glob gone wrong fails.
for name in $(grep -o '{bin}/ofn_[a-z_]*' "$REPO/deploy/processes.yaml" | sed 's|{bin}/||' | sort -u) \
    ofn_sim_runner ofn_replay ofn_baseline ofn_flight_report ofn_bus_keygen ofn_viewer; do
  [[ " ${programs[*]} " == *" $name "* ]] || fail "$name is not among the programs found: ${programs[*]}"
done
for name in "${programs[@]}"; do
  prog="$BIN/$name"
  # A usage error: exit code 2, one line on stderr naming the problem, nothing on stdout.
  set +e; "$prog" --no-such-option > "$WORK/out.txt" 2> "$WORK/err.txt"; code=$?; set -e
  [[ $code -eq 2 ]] || { cat "$WORK/err.txt"; fail "$name --no-such-option exited $code, not 2"; }
  [[ $(wc -l < "$WORK/err.txt") -eq 1 && ! -s "$WORK/out.txt" ]] ||
    { cat "$WORK/out.txt" "$WORK/err.txt"; fail "$name: a usage error is not one line on stderr"; }
  grep -q "^$name: error: .*--no-such-option.* (see --help)$" "$WORK/err.txt" ||
    { cat "$WORK/err.txt"; fail "$name: the usage error does not name the option"; }
  # --version: exit code 0, "<program> <project version>", maybe the git describe.
  set +e; "$prog" --version > "$WORK/out.txt" 2> "$WORK/err.txt"; code=$?; set -e
  [[ $code -eq 0 && ! -s "$WORK/err.txt" && $(wc -l < "$WORK/out.txt") -eq 1 ]] ||
    { cat "$WORK/out.txt" "$WORK/err.txt"; fail "$name --version exited $code or is not one line"; }
  grep -q "^$name ${version//./\\.}\( (git [^)]*)\)\?$" "$WORK/out.txt" ||
    { cat "$WORK/out.txt"; fail "$name --version does not print version $version"; }
  # --help: exit code 0, and every option shows its default or is required.
  set +e; "$prog" --help > "$WORK/out.txt" 2> "$WORK/err.txt"; code=$?; set -e
  [[ $code -eq 0 && ! -s "$WORK/err.txt" ]] || { cat "$WORK/err.txt"; fail "$name --help exited $code"; }
  grep -q "^Usage: $name " "$WORK/out.txt" || { cat "$WORK/out.txt"; fail "$name --help: no usage line"; }
  grep -q "(default: " "$WORK/out.txt" || { cat "$WORK/out.txt"; fail "$name --help shows no default"; }
  # An option's entry is its line, and the next when the name column is full.
  awk '/^  -/ { if (entry != "") print entry; entry = $0; next }
       /^      / && entry != "" { entry = entry $0; next }
       { if (entry != "") print entry; entry = "" }
       END { if (entry != "") print entry }' "$WORK/out.txt" |
    grep -v -e "^  -h,--help" -e "^  --version" | grep -v -e "(default: " -e "REQUIRED" > "$WORK/bare.txt" || true
  [[ ! -s "$WORK/bare.txt" ]] || { cat "$WORK/bare.txt"; fail "$name --help: options without their default"; }
done
"$BIN/ofn_viewer" --help | grep -A1 -- "--port" | grep -q "(default: 8765)" ||
  fail "ofn_viewer --help does not show the port's default"
pass "bad command lines and files rejected with clear messages; ${#programs[@]} programs follow the convention: ${programs[*]}"
