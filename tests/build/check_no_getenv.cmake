# The libraries read no environment variable: options and arguments are their only inputs
# (the executables turn flags into them). Fails when a library source calls getenv,
# secure_getenv, setenv, unsetenv, putenv or clearenv, naming the file and the line.
#   cmake -DSOURCE_DIR=<repo> -P tests/build/check_no_getenv.cmake
# Checked: the libraries, sim/, render/, tracking/, xr_app/app/, xr_app/paths.* and
# xr_app/scene_file.*. Not checked:
#  - xr_app/mock_runtime/: a runtime loaded by the OpenXR loader has no caller to take options
#    from; the environment (DRAPE_MOCK_*) is its only channel, like XR_RUNTIME_JSON is the
#    loader's.
#  - executables: bench/, tests/, fuzz/, xr_app/cmd_*.cpp and xr_app/main.cpp may read the
#    environment and pass what they read on as options (so may the executable's launch side of
#    the OpenXR app, xr_app/xr_launch.*, where the xr_app conversion puts it: it sets the
#    loader's XR_RUNTIME_JSON and the mock runtime's DRAPE_MOCK_*).
cmake_minimum_required(VERSION 3.25)
set(patterns "")
foreach(dir sim render tracking xr_app/app)
  foreach(ext c cc cpp h hpp inl)
    list(APPEND patterns "${SOURCE_DIR}/${dir}/*.${ext}")
  endforeach()
endforeach()
foreach(stem xr_app/paths xr_app/scene_file)
  list(APPEND patterns "${SOURCE_DIR}/${stem}.cpp" "${SOURCE_DIR}/${stem}.hpp")
endforeach()
file(GLOB_RECURSE files ${patterns})
list(SORT files)
set(violations "")
list(LENGTH files count)
foreach(file ${files})
  file(STRINGS "${file}" lines REGEX "(getenv|setenv|putenv|clearenv)[ \t]*\\(")
  file(RELATIVE_PATH rel "${SOURCE_DIR}" "${file}")
  foreach(line ${lines})
    string(STRIP "${line}" line)
    string(APPEND violations "  ${rel}: ${line}\n")
  endforeach()
endforeach()
if(count EQUAL 0)
  message(FATAL_ERROR "check_no_getenv: no library sources under ${SOURCE_DIR}")
elseif(violations)
  message(FATAL_ERROR "check_no_getenv: library sources use the environment (take an option "
                      "from the caller instead):\n${violations}")
endif()
message(STATUS "check_no_getenv: ${count} library sources, none uses the environment")
