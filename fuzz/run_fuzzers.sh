#!/usr/bin/env bash
# Runs every libFuzzer program of a fuzz build for SECONDS each, from seeds of the project's own
# files (the same the regression test runs: tests/fuzz/fuzz_regression_test.cpp) plus the kept
# inputs of fuzz/regressions/, and prints a table (executions/s, coverage, findings); writes
# BUILD/fuzz_report.json. Exit status 1 if any target found a crash, a hang or a leak; its input
# is in BUILD/artifacts/<target>/ (copy it into fuzz/regressions/<target>/ once fixed).
#   fuzz/run_fuzzers.sh BUILD SECONDS   (EGRESS_FUZZ_TARGETS="a b": only those;
#                                        EGRESS_FUZZ_REPORT: the report's path)
set -euo pipefail
build=$1
seconds=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

seed_files() {
  case "$1" in
    bt_script) find "$root/fuzz/seeds/bt_script" -type f ;;
    bt_xml) find "$root/behavior/trees" -name '*.xml' ;;
    scenario_yaml) find "$root/worlds/scenarios" -name '*.yaml' ;;
    sdf_world) find "$root/worlds" -name '*.sdf' ;;
    urdf) find "$root/hsr_interface/models" -name '*.urdf' ;;
    map_server | navd_requests) find "$root/fuzz/seeds/$1" -type f ;;
  esac
  find "$root/fuzz/regressions/$1" -type f
}

targets=(${EGRESS_FUZZ_TARGETS:-bt_script bt_xml scenario_yaml sdf_world urdf map_server navd_requests})
failed=0
rows=()
json="["
for name in "${targets[@]}"; do
  program="$build/fuzz/egress_fuzz_$name"
  [ -x "$program" ] || { echo "missing $program" >&2; exit 1; }
  corpus="$build/corpus/$name"
  artifacts="$build/artifacts/$name"
  mkdir -p "$corpus" "$artifacts"
  while read -r f; do cp -n "$f" "$corpus/seed_$(basename "$f")" 2>/dev/null || true; done < <(seed_files "$name")
  log="$build/fuzz_$name.log"
  printf '[fuzz] %-14s %s s ... ' "$name" "$seconds"
  status=0
  ASAN_OPTIONS=detect_leaks=1 "$program" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=262144 -print_final_stats=1 -artifact_prefix="$artifacts/" \
    "$corpus" >"$log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  findings=$(find "$artifacts" -type f | wc -l)
  verdict=clean
  if [ "$status" -ne 0 ] || [ "$findings" -gt 0 ]; then verdict="FOUND ($findings input(s), exit $status)"; failed=1; fi
  echo "$verdict"
  rows+=("$(printf '%-14s %10s %9s %8s  %s' "$name" "${runs:-?}" "${speed:-?}" "${cov:-?}" "$verdict")")
  json+="$( [ "$json" = "[" ] || echo ,){\"target\":\"$name\",\"seconds\":$seconds,\"runs\":${runs:-0},\"exec_per_s\":${speed:-0},\"coverage\":${cov:-0},\"findings\":$findings,\"exit\":$status}"
done
json+="]"
report=${EGRESS_FUZZ_REPORT:-$build/fuzz_report.json}
echo "$json" >"$report"
echo
printf '%-14s %10s %9s %8s  %s\n' target runs exec/s cov result
for row in "${rows[@]}"; do echo "$row"; done
echo "report: $report; logs: $build/fuzz_<target>.log"
exit $failed
