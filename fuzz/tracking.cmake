# Fuzz the UDP skeleton packet parser; seeds in fuzz/corpus/udp_packet/. The parser source is
# compiled into the target so it gets coverage instrumentation.
drape_add_fuzzer(fuzz_udp_packet SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_udp_packet.cpp
                 ${CMAKE_SOURCE_DIR}/tracking/udp_source.cpp LIBS Eigen3::Eigen)
