#!/usr/bin/env bash
# Replay a recorded flight (an lcm-logger file) onto the LCM bus.
#
# Wraps lcm-logplayer from LCM 1.3.1, whose options are -s/--speed,
# -e/--regexp, -l/--lcm-url and -v/--verbose.  It has no loop option, so
# --loop is implemented here by playing the file again after each pass.
set -euo pipefail

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=deploy/version.sh
source "$REPO_ROOT/deploy/version.sh"
LCM_URL="${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}"
SPEED=1.0
LOOP=0
CHANNELS=""
VERBOSE=0
LOGFILE=""
RERUN=""

usage() {
    cat <<EOF
usage: deploy/replay.sh LOGFILE [--speed X] [--lcm-url URL] [--loop]
                        [--channels REGEX] [--rerun SCENARIO] [--verbose]

Publishes the messages of a recorded flight on LCM with their original timing.

  LOGFILE           .lcm file written by deploy/launch.py or deploy/fly.sh, or
                    'latest' for the most recent flight: the newest of
                    results/latest_log (deploy/launch.py) and
                    results/*/latest_log (deploy/fly.sh, make run)
  --speed X         playback speed multiplier (default: 1.0; 2 = twice as fast)
  --lcm-url URL     LCM URL to publish on
                    (default: \$LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0)
  --loop            play the file again each time it ends (Ctrl-C to stop);
                    message timestamps jump back at every new pass
                    (default: play it once)
  --channels REGEX  replay only channels matching this GLib regular expression
                    (default: all channels)
  --rerun SCENARIO  run sensor_interface, mapper, global_planner and
                    rh_optimizer again on the recording (deploy/launch.py
                    --only ..., with SCENARIO, the scenario of that flight)
                    and replay only their inputs and what a watcher needs
                    (NAV_STATE, SIM_CLOCK, LIDAR_RAW, MISSION,
                    VIRTUAL_OBSTACLES, CONTROL_STATUS): the map, route and
                    plans on the bus are then theirs (default: no services)
  -v, --verbose     print every replayed message
  -h, --help        show this help
  --version         show the version

Exit codes: lcm-logplayer's; 2 for bad arguments or an unusable LOGFILE;
1 when lcm-logplayer is missing or fails during --loop.

Re-running onboard software on a recorded flight: start the services under
test alongside the replay, e.g. in a second terminal

  deploy/launch.py --only mapper,global_planner --no-record --timeout 0 \\
      --scenario sim/scenarios/bench3.yaml      (the scenario of that flight)
  deploy/replay.sh latest --channels '<their input channels>'

Restrict --channels to the services' inputs so the recorded outputs of the
old run do not mix with the new ones.  Watch the bus with deploy/spy.sh.
EOF
}

die() {  # the replay cannot run: exit code 1
    echo "replay.sh: error: $*" >&2
    exit 1
}

die_usage() {  # bad arguments or input: one line, exit code 2
    echo "replay.sh: error: $* (see --help)" >&2
    exit 2
}

need_value() {
    [ "$2" -ge 2 ] || die_usage "$1 needs a value"
}

while [ $# -gt 0 ]; do
    case "$1" in
        --speed)      need_value "$1" $#; SPEED="$2"; shift 2 ;;
        --speed=*)    SPEED="${1#*=}"; shift ;;
        --lcm-url)    need_value "$1" $#; LCM_URL="$2"; shift 2 ;;
        --lcm-url=*)  LCM_URL="${1#*=}"; shift ;;
        --channels)   need_value "$1" $#; CHANNELS="$2"; shift 2 ;;
        --channels=*) CHANNELS="${1#*=}"; shift ;;
        --rerun)      need_value "$1" $#; RERUN="$2"; shift 2 ;;
        --rerun=*)    RERUN="${1#*=}"; shift ;;
        --loop)       LOOP=1; shift ;;
        --verbose|-v) VERBOSE=1; shift ;;
        -h|--help)    usage; exit 0 ;;
        --version)    echo "replay.sh $(project_version "$REPO_ROOT")"; exit 0 ;;
        -*)           die_usage "unknown option '$1'" ;;
        *)
            [ -z "$LOGFILE" ] || die_usage "only one LOGFILE allowed (got '$LOGFILE' and '$1')"
            LOGFILE="$1"; shift ;;
    esac
done

[ -n "$LOGFILE" ] || die_usage "missing LOGFILE"
if [ -n "$RERUN" ]; then
    [ -z "$CHANNELS" ] || die_usage "--rerun chooses the channels itself; leave out --channels"
    [ "$LOOP" -eq 0 ] || die_usage "--rerun plays the log once; leave out --loop"
    [ -f "$RERUN" ] || die_usage "scenario '$RERUN' not found"
fi

if [ "$LOGFILE" = latest ]; then
    # deploy/launch.py writes <log dir>/latest_log, results/latest_log by
    # default; deploy/fly.sh (make run) gives each flight its own folder,
    # results/run-*/latest_log.  The newest of them is the latest flight.
    LATEST=""
    for candidate in "$REPO_ROOT/results/latest_log" "$REPO_ROOT"/results/*/latest_log; do
        [ -f "$candidate" ] || continue
        if [ -z "$LATEST" ] || [ "$candidate" -nt "$LATEST" ]; then
            LATEST="$candidate"
        fi
    done
    [ -n "$LATEST" ] || die_usage "no flight recorded yet: neither results/latest_log nor results/*/latest_log exists (fly one with make run)"
    LOGFILE="$(head -n 1 "$LATEST")"
    [ -n "$LOGFILE" ] || die_usage "$LATEST is empty"
    echo "replay.sh: latest flight, from $LATEST"
fi
[ -e "$LOGFILE" ] || die_usage "log file '$LOGFILE' not found"
[ -f "$LOGFILE" ] || die_usage "'$LOGFILE' is not a regular file"
[ -r "$LOGFILE" ] || die_usage "log file '$LOGFILE' is not readable"
[ -s "$LOGFILE" ] || die_usage "log file '$LOGFILE' is empty (nothing was recorded)"

# A positive decimal number; lcm-logplayer would otherwise misbehave quietly.
[[ "$SPEED" =~ ^([0-9]+\.?[0-9]*|\.[0-9]+)$ ]] && awk -v s="$SPEED" 'BEGIN { exit !(s > 0) }' \
    || die_usage "--speed must be a positive number, got '$SPEED'"

command -v lcm-logplayer >/dev/null 2>&1 || die "lcm-logplayer not found: apt-get install liblcm-bin"

PLAYER=(lcm-logplayer "--speed=$SPEED" "--lcm-url=$LCM_URL")
[ -z "$CHANNELS" ] || PLAYER+=("--regexp=$CHANNELS")
[ "$VERBOSE" -eq 0 ] || PLAYER+=(--verbose)
PLAYER+=("$LOGFILE")

if [ -n "$RERUN" ]; then
    # The planners' inputs, and what a watcher (the live viewer) draws
    # besides their outputs; the recorded outputs stay out.
    PLAYER=(lcm-logplayer "--speed=$SPEED" "--lcm-url=$LCM_URL"
            "--regexp=^(NAV_STATE|SIM_CLOCK|LIDAR_RAW|MISSION|VIRTUAL_OBSTACLES|CONTROL_STATUS)\$")
    [ "$VERBOSE" -eq 0 ] || PLAYER+=(--verbose)
    PLAYER+=("$LOGFILE")
    # The launcher in a process group of its own: a Ctrl-C reaches the
    # player, and this script then stops the services once.
    set -m
    /usr/bin/python3 "$REPO_ROOT/deploy/launch.py" --scenario "$RERUN" --lcm-url "$LCM_URL" \
        --only sensor_interface,mapper,global_planner,rh_optimizer --no-record --timeout 0 &
    SERVICES=$!
    set +m
    trap 'kill -INT "$SERVICES" 2> /dev/null; wait "$SERVICES"; exit 130' INT TERM
    # The services follow the replayed SIM_CLOCK; this is the time they get
    # to start and subscribe (what they miss of the start is the first scans).
    sleep 2
    kill -0 "$SERVICES" 2> /dev/null || die "the services did not start (see the launcher's message above)"
    echo "replay.sh: replaying the inputs of $LOGFILE at ${SPEED}x on $LCM_URL into sensor_interface, mapper, global_planner, rh_optimizer"
    status=0
    "${PLAYER[@]}" || status=$?
    kill -INT "$SERVICES" 2> /dev/null || true
    wait "$SERVICES" || true
    exit "$status"
fi

echo "replay.sh: replaying $LOGFILE at ${SPEED}x on $LCM_URL${CHANNELS:+ (channels /$CHANNELS/)}"
if [ "$LOOP" -eq 0 ]; then
    exec "${PLAYER[@]}"
fi

# Ctrl-C ends the loop rather than only the current pass.
trap 'echo "replay.sh: stopped"; exit 130' INT TERM
pass=1
while true; do
    echo "replay.sh: pass $pass"
    "${PLAYER[@]}" || die "lcm-logplayer failed with code $? on pass $pass"
    pass=$((pass + 1))
done
