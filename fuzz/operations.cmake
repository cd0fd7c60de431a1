# Session files (sim/session_log.cpp): the loader must reject any input with an error, never crash.
drape_add_fuzzer(fuzz_session_log SOURCES fuzz/fuzz_session_log.cpp LIBS drape_sim)
