# Session files (sim/ops/session_log.cpp): the loader must reject any input with an error, never crash.
# The parser source is compiled into the target so it gets coverage instrumentation.
drape_add_fuzzer(fuzz_session_log SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_session_log.cpp
                 ${CMAKE_SOURCE_DIR}/sim/ops/session_log.cpp LIBS drape_sim)
