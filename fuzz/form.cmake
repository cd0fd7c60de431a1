# Fuzz targets for the dress form's inputs: measurement JSON, fabric presets JSON, mesh files.
drape_add_fuzzer(fuzz_measurements_json SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_measurements_json.cpp LIBS drape_sim)
drape_add_fuzzer(fuzz_fabric_json SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_fabric_json.cpp LIBS drape_sim)
# One mesh target per format the product reads (fuzz/fuzz_mesh.cpp; seeds in
# fuzz/corpus/mesh_<format>/), so that each format's executions are counted on their own.
foreach(format obj ply stl glb)
  drape_add_fuzzer(fuzz_mesh_${format} SOURCES ${CMAKE_SOURCE_DIR}/fuzz/fuzz_mesh.cpp LIBS drape_sim)
  target_compile_definitions(fuzz_mesh_${format} PRIVATE DRAPE_FUZZ_MESH_FORMAT="${format}")
endforeach()
