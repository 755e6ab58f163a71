#!/usr/bin/env bash
# End-to-end check of ci/perf-gate: the unchanged build against itself passes
# (exit 0), and the same build with the test-only knob HAIRBENCH_BENCH_PLANTED_SLOWDOWN=0.3
# (30% more work in every timed step, harness/bench/step_bench.cpp) is caught (exit 1).
#
#   tests/perf_gate_e2e.sh BUILD_DIR
#
# Noise: the gate counts instructions (callgrind) of the cheapest step benchmark (method 1
# on idle at 500 strands: method 1 is the scenario's reference, so no second model steps
# alongside) instead of timing it. The planted work is a fixed number of extra steps, so
# both counts are the same on every run, whatever else loads the machine: a timed gate
# on a 2-core machine shared with other jobs can see +12% between two identical builds.
set -uo pipefail
bin=${1:?usage: perf_gate_e2e.sh BUILD_DIR}
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
command -v valgrind >/dev/null || { echo "SKIPPED: needs valgrind (ci/bootstrap installs it)"; exit 77; }
gate=("$root/ci/perf-gate" --baseline-bin "$bin" --candidate-bin "$bin" --no-accuracy --no-speed
      --bench-instructions --filter 'BM_step/han_m1/idle/strands:500/')

"${gate[@]}" --out "$out/self" > "$out/self.md"
rc=$?
cat "$out/self.md"
if [ $rc -ne 0 ]; then
  echo "FAIL: the unchanged build against itself: exit $rc (expected 0)"
  exit 1
fi

"${gate[@]}" --out "$out/planted" --candidate-env HAIRBENCH_BENCH_PLANTED_SLOWDOWN=0.3 > "$out/planted.md"
rc=$?
cat "$out/planted.md"
if [ $rc -ne 1 ]; then
  echo "FAIL: the planted 30% slowdown: exit $rc (expected 1, a regression)"
  exit 1
fi
grep -q 'BM_step/han_m1/idle/strands:500.*REGRESSION' "$out/planted.md" \
  || { echo "FAIL: the summary does not name the slowed benchmark as a regression"; exit 1; }
echo "PASS: self-comparison passes, planted 30% slowdown caught"
