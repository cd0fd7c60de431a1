# Shared build settings: warnings, sanitizers, and a helper to register GoogleTest suites.
add_library(drape_options INTERFACE)
target_compile_options(drape_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wno-missing-field-initializers>)
if(DRAPE_WERROR)
  target_compile_options(drape_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Werror>)
endif()
if(DRAPE_ASAN)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
# The fuzz build: every library with libFuzzer's coverage instrumentation (the targets link the
# fuzzer itself, fuzz/CMakeLists.txt), AddressSanitizer and UBSan, so that a fuzz target is
# guided by what the parser code it calls does, not only by its own source file.
if(DRAPE_FUZZ)
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
if(DRAPE_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()

# drape_add_test(<name> SOURCES a.cpp b.cpp LIBS lib1 lib2 [LABELS l1 l2])
# Builds one GoogleTest executable and registers each TEST with ctest.
# A test whose sources start threads (std::thread/jthread/async, the sim's thread classes, a
# solver or energy run with more than one thread) gets the label "threads" whatever its name, and
# joins the target drape_threads_tests: the TSan build builds that target and runs that label.
set(DRAPE_THREADED_SOURCE_REGEX
  "std::(j?thread|async)|SimThread|FinishThread|ThreadPool|KinectSource|VoiceInput|CheckpointWriter|threads *= *([2-9]|[a-z_(])")
function(drape_add_test name)
  cmake_parse_arguments(T "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  if(NOT "threads" IN_LIST T_LABELS)
    foreach(src ${T_SOURCES})
      get_filename_component(path ${src} ABSOLUTE)
      file(READ ${path} text)
      if(text MATCHES "${DRAPE_THREADED_SOURCE_REGEX}")
        list(APPEND T_LABELS threads)
        break()
      endif()
    endforeach()
  endif()
  if("threads" IN_LIST T_LABELS)
    if(NOT TARGET drape_threads_tests)
      add_custom_target(drape_threads_tests)
    endif()
    add_dependencies(drape_threads_tests ${name})
  endif()
  target_link_libraries(${name} PRIVATE ${T_LIBS} drape_options GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    DRAPE_SOURCE_DIR="${CMAKE_SOURCE_DIR}" DRAPE_BINARY_DIR="${CMAKE_BINARY_DIR}")
  gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST
    WORKING_DIRECTORY ${CMAKE_BINARY_DIR}
    PROPERTIES TIMEOUT 600)
  # Labels are set by a second include file that runs after discovery: gtest_discover_tests
  # flattens a list passed in PROPERTIES, so a second label would be read as a property name.
  if(T_LABELS)
    set(labels_file "${CMAKE_CURRENT_BINARY_DIR}/${name}_labels.cmake")
    file(WRITE "${labels_file}"
      "if(${name}_TESTS)\n  set_tests_properties(\${${name}_TESTS} PROPERTIES LABELS \"${T_LABELS}\")\nendif()\n")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${labels_file}")
  endif()
endfunction()
