# Fuzz targets for the dress form's inputs: measurement JSON, fabric presets JSON, mesh files.
drape_add_fuzzer(fuzz_measurements_json SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_measurements_json.cpp LIBS drape_sim)
drape_add_fuzzer(fuzz_fabric_json SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_fabric_json.cpp LIBS drape_sim)
drape_add_fuzzer(fuzz_mesh SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_mesh.cpp LIBS drape_sim)
