#!/usr/bin/env bash
# `make test`: builds and runs the suite in stages, so that the first results come within seconds
# of the library build instead of after every test binary is compiled. Each stage builds only its
# own binaries, then runs its ctest labels:
#   1. scripts    the floor checks and the TeachMyAgent analysis (nothing to build)
#   2. floors     the rooms below learning (core ... teach): small binaries, quick tests
#   3. learning   dist, learn, learn/meta, train, the CLI; the pytest suite and the robustness
#                 sweep (python), and one run of each benchmark binary (bench)
# A failing test does not stop the later stages; a failing build does (nothing to run). The exit
# status is non-zero if anything failed, and the failed tests of every stage are listed at the end.
# Every registered test must belong to a stage: one that no stage ran is an error.
#
# usage: scripts/test-in-stages.sh BUILD_DIR JOBS [PREFIX...]   (PREFIX: e.g. `nice -n 15`)
set -uo pipefail
build=$1
jobs=$2
shift 2
prefix=("$@")

floors="core model scene sim senses tma sami envs eval teach"
learning="dist learn meta train apps"
# The test binaries of the rooms that have tests (a room without a tests/ folder has no target).
targets_of() {
  local t out=()
  for room in $1; do
    t="${room}_test"
    if ninja -C "$build" -t query "$t" >/dev/null 2>&1; then out+=("$t"); fi
  done
  echo "${out[@]}"
}
labels_of() { echo "^($(echo "$1" | tr ' ' '|'))\$"; }

failed_tests=()
ran=0
status=0
stage() {  # stage NAME LABEL_REGEX TARGETS...
  local name=$1 labels=$2
  shift 2
  local start=$SECONDS
  if [ $# -gt 0 ]; then
    echo "== ${name}: building $*"
    if ! "${prefix[@]}" cmake --build "$build" -j "$jobs" --target "$@"; then
      echo "make test: the ${name} stage's build failed (targets: $*)" >&2
      exit 2
    fi
  fi
  echo "== ${name}: running tests labelled ${labels}"
  local log
  log=$(mktemp)
  (cd "$build" && "${prefix[@]}" ctest --output-on-failure -j "$jobs" -L "$labels") | tee "$log"
  local rc=${PIPESTATUS[0]}
  # "100% tests passed, 0 tests failed out of N" or "97% tests passed, 3 tests failed out of N".
  local n
  n=$(sed -n 's/.* tests failed out of \([0-9]*\).*/\1/p' "$log" | tail -1)
  if [ -z "$n" ]; then
    echo "make test: the ${name} stage ran no test (labels ${labels})" >&2
    status=1
  else
    ran=$((ran + n))
  fi
  if [ "$rc" -ne 0 ]; then
    status=1
    while IFS= read -r line; do failed_tests+=("$line"); done \
      < <(sed -n '/The following tests FAILED:/,$p' "$log" | grep -E '^[[:space:]]+[0-9]+ - ')
  fi
  rm -f "$log"
  echo "== ${name}: $((SECONDS - start)) s"
}

stage scripts '^scripts$'
# shellcheck disable=SC2046  # the target list is meant to split
stage floors "$(labels_of "$floors")" $(targets_of "$floors")
# shellcheck disable=SC2046
stage learning "$(labels_of "$learning python bench")" $(targets_of "$learning") cradle_tests

# Every test registered now that all binaries exist, against what the stages ran.
total=$(cd "$build" && ctest -N | sed -n 's/^Total Tests: \([0-9]*\)/\1/p')
if [ "$total" != "$ran" ]; then
  echo "make test: ctest registers ${total} tests but the stages ran ${ran}: a test without a" \
    "stage's label (see scripts/test-in-stages.sh)" >&2
  status=1
fi
if [ ${#failed_tests[@]} -gt 0 ]; then
  echo "make test: ${#failed_tests[@]} tests failed:"
  printf '%s\n' "${failed_tests[@]}"
fi
[ "$status" -eq 0 ] && echo "make test: all ${ran} tests passed"
exit "$status"
