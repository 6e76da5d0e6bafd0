# Shared by the integration tests. Each test re-runs itself inside a private
# network namespace (deploy/netns.sh), so its multicast never leaves the
# machine and tests running side by side never hear each other.
# Arguments of every test: BIN_DIR REPO_DIR
set -euo pipefail
BIN=${1:?usage: $0 BIN_DIR REPO_DIR}
REPO=${2:?usage: $0 BIN_DIR REPO_DIR}
if [[ -z "${OFN_IN_NETNS:-}" ]]; then
  export OFN_IN_NETNS=1
  exec "$REPO/deploy/netns.sh" "$0" "$@"
fi
WORK=$(mktemp -d /tmp/ofn-it.XXXXXX)
[[ -n ${OFN_KEEP_WORK:-} ]] || trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
pass() { echo "PASS: $*"; }
# Named network namespaces need root (a user namespace cannot make them):
# without them a test that builds hosts of its own is skipped (exit 77).
skip_without_named_netns() {
  local probe="ofn-it-probe-$$"
  if ! ip netns add "$probe" 2> /dev/null; then
    echo "SKIP: cannot create network namespaces here (needs root)"
    exit 77
  fi
  ip netns del "$probe"
}
