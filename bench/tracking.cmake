# Tracking benchmarks (bench/voice_bench.cpp, bench/tracking_bench.cpp) link drape_tracking.
foreach(b voice_bench tracking_bench)
  if(TARGET ${b})
    target_link_libraries(${b} PRIVATE drape_tracking nlohmann_json::nlohmann_json)
  endif()
endforeach()
