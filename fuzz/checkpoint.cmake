# World checkpoints (sim/ops/checkpoint.cpp): the reader must reject any input with an error, never
# crash; the reader's source is compiled into the target so it gets coverage instrumentation.
drape_add_fuzzer(fuzz_checkpoint SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_checkpoint.cpp
                 ${CMAKE_SOURCE_DIR}/sim/ops/checkpoint.cpp LIBS drape_sim)
