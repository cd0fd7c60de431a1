# Solver benchmark: the Bullet soft-body peer (bench/bullet_peer.cpp) is linked into
# solvers_bench and into its standalone driver bullet_peer_bench. Bullet (libbullet-dev) is
# required: `./drape setup` installs it, and the solver benchmark compares against it.
find_path(DRAPE_BULLET_INCLUDE btSoftBody.h PATHS /usr/include/bullet/BulletSoftBody
          NO_DEFAULT_PATH)
find_library(DRAPE_BULLET_SOFT BulletSoftBody)
find_library(DRAPE_BULLET_DYN BulletDynamics)
find_library(DRAPE_BULLET_COLL BulletCollision)
find_library(DRAPE_BULLET_MATH LinearMath)
if(NOT (DRAPE_BULLET_INCLUDE AND DRAPE_BULLET_SOFT AND DRAPE_BULLET_DYN AND DRAPE_BULLET_COLL
        AND DRAPE_BULLET_MATH))
  message(FATAL_ERROR "Bullet soft body not found (Debian package libbullet-dev; `./drape setup` "
                      "installs it), needed by the solver benchmark's peer (bench/bullet_peer.cpp)")
endif()
foreach(tgt solvers_bench bullet_peer_bench)
  if(TARGET ${tgt})
    target_sources(${tgt} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/bullet_peer.cpp)
    # System headers: Bullet's own warnings are not ours (-Werror in CI).
    target_include_directories(${tgt} SYSTEM PRIVATE /usr/include/bullet)
    target_link_libraries(${tgt} PRIVATE ${DRAPE_BULLET_SOFT} ${DRAPE_BULLET_DYN}
                                         ${DRAPE_BULLET_COLL} ${DRAPE_BULLET_MATH})
  endif()
endforeach()
# Smoke check of the peer (ctest, label "bench"): Bullet on an 8x8 sheet at 40 substeps, every
# position finite and the RMS error against the static Newton minimum under 2 mm.
if(TARGET bullet_peer_bench)
  add_test(NAME bench_bullet_peer_smoke
           COMMAND bullet_peer_bench --res 8 --runs 40x1 --check-rms 2
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(bench_bullet_peer_smoke PROPERTIES LABELS "bench")
endif()
# Smoke checks of the thread rows and of the sweep model (ctest, label "bench"): a tiny drape on 1
# and 3 threads writes out/bench/solvers_threads.csv with the columns and rows the many-core
# figures use (bench/checks/thread_rows.cmake); its sweep planned for 2 and 3 threads, timed on
# one and replayed, writes out/bench/solvers_sweep_model.csv with bounded figures
# (bench/checks/sweep_model.cmake).
if(TARGET solvers_bench)
  foreach(check thread_rows sweep_model)
    add_test(NAME bench_solvers_${check}_smoke
             COMMAND ${CMAKE_COMMAND} -DBIN=$<TARGET_FILE:solvers_bench>
                     -DDIR=${CMAKE_BINARY_DIR}/bench_${check} -P
                     ${CMAKE_CURRENT_SOURCE_DIR}/checks/${check}.cmake)
    set_tests_properties(bench_solvers_${check}_smoke PROPERTIES LABELS "bench")
  endforeach()
endif()
