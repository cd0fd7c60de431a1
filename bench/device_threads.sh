#!/usr/bin/env bash
# The solver's thread rows on another machine (a many-core one), from a copy of the benchmark and
# the shared libraries it loads, so that nothing needs to be built or installed there.
#
#   bench/device_threads.sh pack DIR [BASELINE_BIN]
#       here: DIR/solvers_bench (stripped, from build/bin), and BASELINE_BIN stripped as
#       DIR/solvers_bench_base when given (an earlier build to compare with), the libraries both
#       load, the dynamic loader included, in DIR/lib.tgz.
#   bench/device_threads.sh run DIR OUT [--base-res "128 256"] [--base-threads "1 2 4 8 16"]
#                                       [--two-cores] [-- solvers_bench flags]
#       there: the thread rows (solvers_bench --threads-only --threads-default-only, 1/2/4/8/16
#       threads at 128^2 and 256^2 unless the flags after -- say otherwise) run in a scratch
#       directory; OUT/solvers_threads.csv, OUT/threads.log, OUT/machine.txt (cores, CPU model).
#       With a baseline: its probe (--probe form RES xpbd 10 1 --no-polish --no-ref --frames 270)
#       at --base-res x --base-threads (--base-res "" skips it), OUT/baseline.log. --two-cores:
#       also 128^2 on two threads pinned to two cores (taskset), both builds, OUT/two_cores.log.
#       --split: this build's probe at --base-res x --base-threads, each frame's wall time
#       split into the element sweeps and the rest of the step, and into the step's parts
#       (OUT/split.log; the thread rows print the parts too), and the sweep
#       model (solvers_bench --sweep-model: the sweep's plan timed on one thread, replayed on
#       8 and 16; OUT/solvers_sweep_model.csv).
set -euo pipefail
mode="${1:-}"
case "$mode" in
  pack)
    dir="$2"
    base="${3:-}"
    mkdir -p "$dir"
    bins=(build/bin/solvers_bench)
    [ -n "$base" ] && bins+=("$base")
    strip -o "$dir/solvers_bench" build/bin/solvers_bench
    [ -n "$base" ] && strip -o "$dir/solvers_bench_base" "$base"
    rm -rf "$dir/lib" && mkdir -p "$dir/lib"
    for b in "${bins[@]}"; do
      ldd "$b" | awk '/=>/ {print $3} /ld-linux/ {print $1}' | while read -r f; do
        [ -f "$f" ] && cp -L "$f" "$dir/lib/"
      done
    done
    tar czf "$dir/lib.tgz" -C "$dir" lib && rm -rf "$dir/lib"
    cp "$0" "$dir/device_threads.sh"
    du -sh "$dir"
    ;;
  run)
    dir="$(cd "$2" && pwd)"
    out="$3"
    shift 3
    base_res="128 256" base_threads="1 2 4 8 16" two_cores="" split=""
    while [ $# -gt 0 ]; do
      case "$1" in
        --base-res) base_res="$2"; shift 2 ;;
        --base-threads) base_threads="$2"; shift 2 ;;
        --two-cores) two_cores=1; shift ;;
        --split) split=1; shift ;;
        --) shift; break ;;
        *) echo "device_threads.sh: unknown option '$1' (solvers_bench flags go after --)" >&2; exit 2 ;;
      esac
    done
    mkdir -p "$out"
    out="$(cd "$out" && pwd)"
    work="$(mktemp -d)"
    tar xzf "$dir/lib.tgz" -C "$work"
    loader="$work/lib/ld-linux-x86-64.so.2"
    run_bin() { "$loader" --library-path "$work/lib" "$@"; }
    {
      echo "cores: $(nproc)"
      grep -m1 'model name' /proc/cpuinfo || true
      grep -m1 '^flags' /proc/cpuinfo | tr ' ' '\n' | grep -E '^avx(2|512f)$' | tr '\n' ' ' || true
      echo
    } > "$out/machine.txt"
    cat "$out/machine.txt"
    cd "$work"
    run_bin "$dir/solvers_bench" --threads-only --threads-default-only "$@" 2>&1 | tee "$out/threads.log"
    cp out/bench/solvers_threads.csv "$out/"
    # probe_rows NAME BIN PATTERN: BIN's probe at --base-res x --base-threads, the lines that
    # match PATTERN.
    probe_rows() {
      for res in $base_res; do
        for t in $base_threads; do
          echo "== $1 $res^2, $t threads"
          run_bin "$2" --probe form "$res" xpbd 10 1 --no-polish --no-ref --frames 270 \
            --threads "$t" 2>&1 | grep -E "$3"
        done
      done
    }
    if [ -x "$dir/solvers_bench_base" ] && [ -n "$base_res" ]; then
      probe_rows baseline "$dir/solvers_bench_base" '^form .* wall' 2>&1 | tee "$out/baseline.log"
    fi
    if [ -n "$split" ]; then
      probe_rows split "$dir/solvers_bench" '^form .* wall|element sweeps|step parts' 2>&1 |
        tee "$out/split.log"
      run_bin "$dir/solvers_bench" --sweep-model --thread-res 128,256 --thread-counts 8,16 \
        2>&1 | tee -a "$out/split.log"
      cp out/bench/solvers_sweep_model.csv "$out/"
    fi
    # Two cores of the machine (taskset), 128^2 on two threads, this build and the baseline.
    if command -v taskset >/dev/null && [ -n "$two_cores" ]; then
      for b in solvers_bench solvers_bench_base; do
        [ -x "$dir/$b" ] || continue
        echo "== $b, cores 0-1, 128^2, 2 threads"
        taskset -c 0,1 "$loader" --library-path "$work/lib" "$dir/$b" --probe form 128 xpbd 10 1 \
          --no-polish --no-ref --frames 270 --threads 2 2>&1 | grep -E '^form .* wall'
      done 2>&1 | tee "$out/two_cores.log"
    fi
    ;;
  *)
    sed -n '2,/^set -euo/p' "$0" | sed '$d'
    exit 2
    ;;
esac
