# Tracking benchmark drivers, linked to drape_tracking only (run by bench/voice.sh and
# bench/tracking.sh; executables voice_bench and tracking_bench in build/bin).
foreach(b voice tracking)
  add_executable(${b}_bench ${CMAKE_CURRENT_SOURCE_DIR}/${b}_driver.cpp)
  target_include_directories(${b}_bench PRIVATE ${CMAKE_SOURCE_DIR})
  target_link_libraries(${b}_bench PRIVATE drape_options drape_tracking nlohmann_json::nlohmann_json
                                           CLI11::CLI11)
endforeach()
# The hand sources in the app's frame loop (latency, jitter, CPU per source).
target_sources(tracking_bench PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tracking_sources.cpp)
