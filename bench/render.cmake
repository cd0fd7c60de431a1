# render_bench: frame time per eye at 1024^2 with a 128^2 cloth (lavapipe here); needs the
# renderer library, so it is only built with DRAPE_BUILD_RENDER.
if(TARGET render_bench)
  if(TARGET drape_render)
    target_link_libraries(render_bench PRIVATE drape_render drape_scene_file)
  else()
    set_target_properties(render_bench PROPERTIES EXCLUDE_FROM_ALL ON)
  endif()
endif()
