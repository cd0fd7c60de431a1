# ply_bench reads the grid with assimp's own PLY importer too (an Assimp::Importer of its own).
find_package(assimp REQUIRED)
target_link_libraries(ply_bench PRIVATE assimp::assimp)
