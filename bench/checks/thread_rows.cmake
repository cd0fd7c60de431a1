# ctest bench_solvers_thread_rows_smoke (bench/solvers.cmake): runs the solver benchmark's thread rows on a tiny drape
# (16^2, 1 and 3 threads, 5 frames) in DIR and checks out/bench/solvers_threads.csv: its header
# names resolution, threads, cores and ms_per_frame, and it holds one row per thread count with
# the machine's core count and a positive time, and the step's sweep and contact parts timed. Arguments: -DBIN=solvers_bench -DDIR=scratch.
include(${CMAKE_CURRENT_LIST_DIR}/bench_csv.cmake)
set(BENCH_ARGS --threads-only --threads-default-only --thread-res 16 --thread-counts 1,3
               --thread-rounds 1 --frames 5)
bench_csv(out/bench/solvers_threads.csv 2 resolution threads cores ms_per_frame part_sweep_ms
          part_contacts_ms)
cmake_host_system_information(RESULT cores QUERY NUMBER_OF_LOGICAL_CORES)
set(expected 1 3)
foreach(k 1 2)
  bench_csv_row(${k})
  math(EXPR j "${k} - 1")
  list(GET expected ${j} want)
  if(NOT v_resolution EQUAL 16 OR NOT v_threads EQUAL want OR NOT v_cores EQUAL cores
     OR NOT v_ms_per_frame GREATER 0 OR NOT v_part_sweep_ms GREATER 0
     OR NOT v_part_contacts_ms GREATER 0)
    message(FATAL_ERROR "${csv} row ${k}: '${row}' (want 16^2, ${want} threads, ${cores} cores, "
                        "ms > 0, the sweep's and the contacts' parts > 0)")
  endif()
endforeach()
message(STATUS "thread rows: ${lines}")
