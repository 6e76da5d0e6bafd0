#!/usr/bin/env bash
# `make test`'s ctest run, in two lanes side by side. The integration tests
# run as always (ctest -j 4 in half-cores; those marked RUN_SERIAL alone). The
# unit tests run at the same time at the lowest CPU priority (nice 19),
# so they take only the CPU the integration tests leave idle: the real-time
# multi-process flights use about one core of two for minutes, and a unit
# test beside them at normal priority would starve them (which is why they
# run alone). The unit tests keep no wall-clock deadlines, so running slowly
# does not change what they check. docs/TESTING.md has the figures.
#
# Usage: tests/run_tests.sh BUILD_DIR. Exit code 0 when both lanes pass,
# 1 when a test fails, 2 on a bad command line or an unlabelled test. The
# unit lane's whole output is in BUILD_DIR/Testing/unit_lane.log; its
# failures are printed.
set -uo pipefail
if [[ $# -ne 1 || ! -d $1 ]]; then
  echo "usage: tests/run_tests.sh BUILD_DIR (a configured and built folder)" >&2
  exit 2
fi
cd "$1" || exit 2
mkdir -p Testing
unit_log=Testing/unit_lane.log
ctest_args=(--output-on-failure --timeout 600)
# The lanes are chosen by label: a test with neither label would run in
# neither, so it is an error here rather than a test silently left out.
unlabelled=$(ctest -N -LE '^(unit|integration)$' | sed -n 's/^ *Test *#[0-9]*: //p')
if [[ -n $unlabelled ]]; then
  echo "tests: these tests have neither the unit nor the integration label" \
    "(tests/CMakeLists.txt), so neither lane would run them:" >&2
  echo "$unlabelled" >&2
  exit 2
fi
echo "tests: the unit tests run beside the integration tests at nice 19 (log: $1/$unit_log)"
# Nice alone is not enough: with the kernel's autogroups (Debian's default)
# CPU is shared fairly between sessions whatever their nice values, and the
# launcher starts each service in a session of its own; a niced unit lane
# took half the CPU from the flights (lockstep_link_faults 37 s -> 55 s).
# So the lane gets a session of its own whose autogroup is set to nice 19
# (a process may lower its own group's priority; without autogroups the
# file is absent and nice 19 does it).
setsid bash -c 'echo 19 > /proc/self/autogroup 2> /dev/null; exec nice -n 19 ctest "$@"' \
  unit_lane -L unit -j 2 "${ctest_args[@]}" > "$unit_log" 2>&1 &
unit_lane=$!
# Ctrl-C or a kill of this script ends the unit lane (its session) too.
trap 'kill -- -$unit_lane 2> /dev/null' EXIT
# The integration lane counts half-cores: -j 4 on two cores, each test's
# PROCESSORS its share (tests/CMakeLists.txt), so that a test that mostly
# waits runs beside a busy one rather than holding a slot.
ctest -L integration -j 4 "${ctest_args[@]}"
integration_status=$?
wait $unit_lane
unit_status=$?
trap - EXIT
echo
echo "== unit tests (ran beside at nice 19; all of it in $1/$unit_log):"
if [[ $unit_status -ne 0 ]]; then
  # What failed and why; the passing tests' lines are in the log.
  grep -v -E '^ *Start +[0-9]+: |^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* Passed ' "$unit_log"
else
  grep -E 'tests passed|Total Test time' "$unit_log"
fi
if [[ $integration_status -ne 0 || $unit_status -ne 0 ]]; then
  echo "tests: FAILED (integration lane exit $integration_status, unit lane exit $unit_status)"
  exit 1
fi
echo "tests: all passed (both lanes)"
