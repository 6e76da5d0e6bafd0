#!/usr/bin/env bash
# Start lcm-spy with the project's LCM types so messages are decoded.
#
# Debian's /usr/bin/lcm-spy passes -Xincgc, which Java 9+ rejects ("Unrecognized
# VM option"), so on Java 17 it dies before opening a window.  This script
# runs the same lcm.spy.Spy class directly, without that flag, and adds the
# project's type jar (build/lcmtypes/ofn_lcmtypes.jar) to the classpath;
# lcm-spy discovers message types by scanning the classpath.
set -euo pipefail

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=deploy/version.sh
source "$REPO_ROOT/deploy/version.sh"
LCM_JAR=/usr/share/java/lcm.jar
JCHART_JAR=/usr/share/java/jchart2d.jar
TYPES_JAR="${OFN_LCMTYPES_JAR:-$REPO_ROOT/build/lcmtypes/ofn_lcmtypes.jar}"
LCM_URL="${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}"

usage() {
    cat <<EOF
usage: deploy/spy.sh [--lcm-url URL]

Opens lcm-spy on the flight-software LCM bus with the ofn_* message types.

  --lcm-url URL   LCM URL to listen on
                  (default: \$LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0)
  -h, --help      show this help
  --version       show the version

Exit codes: lcm-spy's; 2 for bad arguments; 1 when something it needs is
missing.

Needs a display (DISPLAY set; over ssh use 'ssh -X'), Java
(apt-get install default-jre) and the type jar from 'make build'
(override its path with OFN_LCMTYPES_JAR).  Extra jars can be added through
CLASSPATH.
EOF
}

die() {  # something lcm-spy needs is missing: exit code 1
    echo "spy.sh: error: $*" >&2
    exit 1
}

die_usage() {  # bad arguments: one line, exit code 2
    echo "spy.sh: error: $* (see --help)" >&2
    exit 2
}

while [ $# -gt 0 ]; do
    case "$1" in
        --lcm-url)
            [ $# -ge 2 ] || die_usage "--lcm-url needs a URL"
            LCM_URL="$2"
            shift 2
            ;;
        --lcm-url=*)
            LCM_URL="${1#--lcm-url=}"
            shift
            ;;
        -h|--help)
            usage
            exit 0
            ;;
        --version)
            echo "spy.sh $(project_version "$REPO_ROOT")"
            exit 0
            ;;
        *)
            die_usage "unknown argument '$1'"
            ;;
    esac
done

command -v java >/dev/null 2>&1 || die "java not found: apt-get install default-jre"
[ -f "$LCM_JAR" ] || die "$LCM_JAR not found: apt-get install liblcm-java"
[ -f "$JCHART_JAR" ] || die "$JCHART_JAR not found: apt-get install libjchart2d-java"
[ -n "$LCM_URL" ] || die_usage "--lcm-url is empty"
[ -f "$TYPES_JAR" ] || die "LCM type jar $TYPES_JAR not found: run make build"
if [ -z "${DISPLAY:-}" ]; then
    die "no DISPLAY set: lcm-spy is a GUI; run it in a desktop session or over 'ssh -X'"
fi

CP="$LCM_JAR:$JCHART_JAR:$TYPES_JAR${CLASSPATH:+:$CLASSPATH}"
echo "spy.sh: lcm-spy on $LCM_URL with types from $TYPES_JAR"
# IPv4 stack: LCM's UDP multicast does not work over Java's default IPv6 sockets.
exec java -Djava.net.preferIPv4Stack=true -Xmx256m -Xms64m -ea \
    -cp "$CP" lcm.spy.Spy --lcm-url="$LCM_URL"
