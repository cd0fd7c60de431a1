# World checkpoints (sim/ops/checkpoint.cpp) and the XPBD solver's state in them
# (sim/solvers/xpbd/xpbd_state.cpp): the readers must reject any input with an error, never crash;
# their sources are compiled into the target so they get coverage instrumentation.
drape_add_fuzzer(fuzz_checkpoint SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_checkpoint.cpp
                 ${CMAKE_SOURCE_DIR}/sim/ops/checkpoint.cpp
                 ${CMAKE_SOURCE_DIR}/sim/solvers/xpbd/xpbd_state.cpp LIBS drape_sim)
