# What deploy/fly.sh and deploy/fly_three_hosts.sh share: their options'
# checks and everything after the run (the flight report, the figures, the
# replay hint and the exit code), so that the one-host and the three-host
# flights are judged and reported the same way. Sourced, not run; the
# sourcing script sets `program` (its name, for messages) and `repo`.

die_usage() {  # one line, exit code 2
  echo "$program: error: $* (see --help)" >&2
  exit 2
}

need_value() {  # need_value OPTION NUMBER_OF_ARGS_LEFT
  [[ $2 -ge 2 ]] || die_usage "$1 needs a value"
}

flight_option() {  # flight_option ARGS...: one of the options both scripts take
  # (--scenario, --rtf, --out, --timeout, as "--x V" or "--x=V"); sets them
  # and `taken`, the number of arguments used; anything else is a usage error.
  case "$1" in
    --scenario | --rtf | --out | --timeout) need_value "$1" $#; taken=2; local value=$2 ;;
    --scenario=* | --rtf=* | --out=* | --timeout=*) taken=1; local value=${1#*=} ;;
    *) die_usage "unknown option '$1'" ;;
  esac
  local name=${1%%=*}
  case "$name" in
    --scenario) scenario=$value ;;
    --rtf) rtf=$value ;;
    --out) out=$value ;;
    --timeout) timeout=$value ;;
  esac
}

check_flight_options() {  # check_flight_options SCENARIO RTF TIMEOUT BIN
  local positive='^([0-9]+\.?[0-9]*|\.[0-9]+)$'
  [[ $2 =~ $positive ]] && awk -v x="$2" 'BEGIN { exit !(x > 0) }' ||
    die_usage "--rtf must be a positive number, got '$2'"
  [[ $3 =~ $positive ]] || die_usage "--timeout must be a number of seconds >= 0, got '$3'"
  [[ -n $1 ]] || die_usage "--scenario is empty"
  [[ -f "$1" ]] || { echo "$program: error: scenario file '$1' not found" >&2; exit 2; }
  [[ -x "$4/ofn_flight_report" ]] || { echo "$program: error: not built yet: run 'make build'" >&2; exit 2; }
}

exit_if_no_flight() {  # exit_if_no_flight LAUNCHER_STATUS [CONFIG_ERROR]
  if [[ $1 == 2 || -n ${2:-} ]]; then
    # The launcher rejected its input, or a service its configuration: there
    # was no flight to report on (the launcher said why, above).
    echo "fly: no flight: a configuration or usage error (see the launcher's message above)" >&2
    exit 2
  fi
}

report_flight() {  # report_flight BIN OUT SCENARIO LOG [KEYRING]; sets report_status
  # The report's exit code is the verdict (1: the flight failed); the figure
  # is drawn either way, since a failed flight is the one to look at. With
  # the keyring of an authenticated bus the report reads only what was
  # signed by a role allowed to, as the services did.
  report_status=0
  "$1/ofn_flight_report" --log "$4" --scenario "$3" ${5:+--bus-keys "$5"} \
    --controller-config "$repo/config/controller.yaml" --out "$2" || report_status=$?
  /usr/bin/python3 "$repo/services/tools/plot_flight.py" "$2" >/dev/null &&
    echo "  figures           : $2/flight.png, $2/tracking.png"
  return 0
}

finish_flight() {  # finish_flight OUT LOG LAUNCHER_STATUS: the replay hint, then exits
  # replay.sh's 'latest' is the newest flight in results/ or a folder just below.
  local out_abs replay=$2
  out_abs=$(cd "$1" && pwd)
  [[ $out_abs == "$repo/results" || $(dirname "$out_abs") == "$repo/results" ]] && replay=latest
  echo "  replay            : deploy/replay.sh $replay"
  if [[ $report_status == 1 ]]; then
    echo "fly: the flight failed (see the outcome above)" >&2
    exit 1
  elif [[ $report_status != 0 ]]; then
    echo "fly: the flight report could not be written (exit code $report_status)" >&2
    exit "$report_status"
  fi
  if [[ $3 != 0 ]]; then
    echo "fly: the flight did not complete (launcher exit code $3)" >&2
  fi
  exit "$3"
}
