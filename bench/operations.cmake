# operations_bench measures latency through the sim thread.
if(TARGET operations_bench AND TARGET drape_sim_thread)
  target_link_libraries(operations_bench PRIVATE drape_sim_thread)
endif()
