# ctest bench_solvers_sweep_model_smoke (bench/solvers.cmake): runs the solver benchmark's sweep
# model on a tiny drape (24^2, planned for 2 and 3 threads, 5 frames; --thread-counts 1 has no
# row) in DIR and checks out/bench/solvers_sweep_model.csv: one row per slot count with positive
# work and span, the span at most the work, and a speed-up between 1 and the slot count (the
# replayed slots never run faster than one alone). Arguments: -DBIN=solvers_bench -DDIR=scratch.
include(${CMAKE_CURRENT_LIST_DIR}/bench_csv.cmake)
set(BENCH_ARGS --sweep-model --thread-res 24 --thread-counts 1,2,3 --frames 5)
bench_csv(out/bench/solvers_sweep_model.csv 2 resolution slots work_ms span_ms sweep_speedup)
set(expected 2 3)
foreach(k 1 2)
  bench_csv_row(${k})
  math(EXPR j "${k} - 1")
  list(GET expected ${j} want)
  if(NOT v_resolution EQUAL 24 OR NOT v_slots EQUAL want OR NOT v_work_ms GREATER 0
     OR NOT v_span_ms GREATER 0 OR v_span_ms GREATER v_work_ms OR v_sweep_speedup LESS 1
     OR v_sweep_speedup GREATER v_slots)
    message(FATAL_ERROR "${csv} row ${k}: '${row}' (want 24^2, ${want} slots, work and span > 0, "
                        "span <= work, 1 <= speed-up <= slots)")
  endif()
endforeach()
message(STATUS "sweep model: ${lines}")
