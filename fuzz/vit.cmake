# Fuzz target for the Seamly2D / Valentina individual measurements parser (.vit XML).
drape_add_fuzzer(fuzz_vit SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_vit.cpp LIBS drape_sim)
