# Fuzz the UDP skeleton packet parser; seeds in fuzz/corpus/udp_packet/.
# The parser sources are compiled into the targets so they get coverage instrumentation.
find_package(OpenSSL REQUIRED COMPONENTS Crypto)
set(DRAPE_FUZZ_UDP_SOURCES ${CMAKE_SOURCE_DIR}/tracking/udp_source.cpp
                           ${CMAKE_SOURCE_DIR}/tracking/udp_auth.cpp)
drape_add_fuzzer(fuzz_udp_packet SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_udp_packet.cpp
                 ${DRAPE_FUZZ_UDP_SOURCES} LIBS Eigen3::Eigen OpenSSL::Crypto)
# The signed (version 2) packets: the tag check, then the parser; seeds in
# fuzz/corpus/udp_signed/ (signed with the target's fixed key, so they pass the check).
drape_add_fuzzer(fuzz_udp_signed SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_udp_signed.cpp
                 ${DRAPE_FUZZ_UDP_SOURCES} LIBS Eigen3::Eigen OpenSSL::Crypto)
