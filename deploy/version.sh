# The project's version for the deploy scripts' --version: the one in the
# top-level CMakeLists.txt (project(... VERSION x.y.z)), as the programs and
# the Python entry points print it. Sourced, not run.

project_version() {  # project_version REPO
  sed -n 's/^[[:space:]]*project[[:space:]]*(.*VERSION[[:space:]]\{1,\}\([0-9][0-9A-Za-z.+-]*\).*/\1/p' \
    "$1/CMakeLists.txt" 2>/dev/null | head -n 1 | grep . || echo unknown
}
