#!/usr/bin/env bash
# ./drape bench tracking: One-Euro jitter vs lag, Kinect pipeline fps, and per hand source (UDP,
# Kinect depth, trace file) latency, jitter and CPU per frame; on one core.
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
shift || true  # the rest: tracking_bench's flags
cd "$ROOT"
BUILD="${DRAPE_BUILD_DIR:-build}"
mkdir -p out/bench
if command -v taskset > /dev/null; then
  exec taskset -c 0 "$BUILD/bin/tracking_bench" "$@"
fi
exec "$BUILD/bin/tracking_bench" "$@"
