#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/*.cmake) with clang and runs each one for DRAPE_FUZZ_SECONDS
# on the seed corpus kept in the repository (fuzz/corpus/<name>) plus what earlier runs found
# (build-fuzz/corpus/<target>). Prints a table of executions per target and writes it to
# out/fuzz/fuzz.csv; any crash, leak, timeout or out-of-memory fails the script, with the
# fuzzer's report and the input that caused it (build-fuzz/artifacts/).
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${DRAPE_FUZZ_SECONDS:-30}"
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DDRAPE_FUZZ=ON -DDRAPE_BUILD_RENDER=OFF -DDRAPE_BUILD_XR=OFF -DDRAPE_BUILD_BENCH=OFF \
  -DDRAPE_ASAN=OFF >/dev/null
targets=$(cd build-fuzz && ninja -t targets all | sed -n 's/^\(fuzz_[a-z0-9_]*\): .*/\1/p' | sort -u)
[ -n "$targets" ] || { echo "no fuzz targets"; exit 1; }
cmake --build build-fuzz -j "${DRAPE_JOBS:-2}" --target $targets
mkdir -p out/fuzz build-fuzz/logs build-fuzz/artifacts
csv=out/fuzz/fuzz.csv
echo "target,seconds,executions,execs_per_s,corpus_files,result" >"$csv"
failed=0
printf '%-26s %8s %12s %10s %8s  %s\n' target seconds executions exec/s corpus result
for t in $targets; do
  seeds="fuzz/corpus/${t#fuzz_}"
  mkdir -p "build-fuzz/corpus/$t"
  log="build-fuzz/logs/$t.log"
  rc=0
  ./build-fuzz/bin/$t -max_total_time="$secs" -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="build-fuzz/artifacts/$t-" "build-fuzz/corpus/$t" \
    $( [ -d "$seeds" ] && echo "$seeds" ) >"$log" 2>&1 || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  files=$(find "build-fuzz/corpus/$t" -type f | wc -l)
  result=passed
  [ "$rc" -eq 0 ] || { result="FAILED (exit $rc)"; failed=1; }
  printf '%-26s %8s %12s %10s %8s  %s\n' "$t" "$secs" "${execs:-0}" "$(( ${execs:-0} / secs ))" \
    "$files" "$result"
  echo "$t,$secs,${execs:-0},$(( ${execs:-0} / secs )),$files,$result" >>"$csv"
  if [ "$rc" -ne 0 ]; then
    echo "--- $t's report ($log):"
    grep -E "ERROR|SUMMARY|Test unit written|==[0-9]+==" "$log" | head -n 40
  fi
done
exit "$failed"
