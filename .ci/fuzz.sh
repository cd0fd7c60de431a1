#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/*.cmake) with clang and runs each one briefly on its seed corpus.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${DRAPE_FUZZ_SECONDS:-30}"
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DDRAPE_FUZZ=ON -DDRAPE_BUILD_RENDER=OFF -DDRAPE_BUILD_XR=OFF -DDRAPE_BUILD_BENCH=OFF \
  -DDRAPE_ASAN=OFF >/dev/null
targets=$(cd build-fuzz && ninja -t targets all | sed -n 's/^\(fuzz_[a-z0-9_]*\): .*/\1/p' | sort -u)
[ -n "$targets" ] || { echo "no fuzz targets"; exit 1; }
cmake --build build-fuzz -j "${DRAPE_JOBS:-2}" --target $targets
for t in $targets; do
  corpus="fuzz/corpus/${t#fuzz_}"
  mkdir -p "build-fuzz/corpus/$t"
  echo "-- $t for ${secs}s"
  ./build-fuzz/bin/$t -max_total_time="$secs" -timeout=30 -rss_limit_mb=2048 -print_final_stats=0 \
    "build-fuzz/corpus/$t" $( [ -d "$corpus" ] && echo "$corpus" ) 2>&1 | tail -n 3
done
