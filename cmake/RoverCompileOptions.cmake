# Warning set shared by every target of the project. (-Wnull-dereference is left
# out: GCC 12 reports false positives inside libstdc++ at -O2.) Targets opt in through
# rover_target_defaults() so third-party code is never compiled with -Werror.
add_library(rover_warnings INTERFACE)
target_compile_options(rover_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
  -Wcast-align -Wunused -Woverloaded-virtual -Wconversion -Wsign-conversion
  -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # -Wno-restrict: GCC 12 at -O3 reports impossible overlaps inside
  # std::string's operator+ (GCC bug 105329), which would break the release preset.
  target_compile_options(rover_warnings INTERFACE
    -Wmisleading-indentation -Wduplicated-cond -Wduplicated-branches -Wlogical-op -Wno-restrict)
endif()
if(ROVER_WARNINGS_AS_ERRORS)
  target_compile_options(rover_warnings INTERFACE -Werror)
endif()

# Compressed debug sections. Debug info is most of the build tree (every test
# links Eigen, OpenCV and Ceres templates); zlib halves it for about 2 % more
# compile time, which keeps the dev, ASan and TSan trees of a CI clone small.
# Applies to every target, third-party included, and is a no-op without -g.
add_compile_options(-gz)
add_link_options(-gz)

# Applies the project defaults to a target: include root, warnings.
function(rover_target_defaults target)
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_link_libraries(${target} PRIVATE rover_warnings)
endfunction()

# Shared reference data (EuRoC excerpt, pose graphs) lives beside the
# checkout; $ROVER_SHARED_DIR overrides where.
if(DEFINED ENV{ROVER_SHARED_DIR})
  set(ROVER_SHARED_DIR "$ENV{ROVER_SHARED_DIR}" CACHE PATH "shared reference data")
else()
  get_filename_component(_shared "${PROJECT_SOURCE_DIR}/../shared" ABSOLUTE)
  set(ROVER_SHARED_DIR "${_shared}" CACHE PATH "shared reference data")
endif()

# rover_add_test(NAME name SOURCES a.cc b.cc LIBS libs... [LABELS l...] [RESOURCE_LOCK r])
# One gtest executable, registered test-by-test with ctest. Labels select the
# sanitizer runs (asan, tsan); RESOURCE_LOCK serialises tests sharing one
# machine-wide resource (e.g. "roudi").
#
# Properties are applied by a script that ctest includes after discovery:
# gtest_discover_tests(PROPERTIES ...) flattens list values, which would keep
# only the first label and the first environment variable.
function(rover_add_test)
  cmake_parse_arguments(ARG "" "NAME;RESOURCE_LOCK" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  rover_target_defaults(${ARG_NAME})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LIBS} GTest::gmock GTest::gtest_main)
  gtest_discover_tests(${ARG_NAME} TEST_LIST ${ARG_NAME}_TESTS DISCOVERY_TIMEOUT 60)
  set(environment "ROVER_SOURCE_DIR=${PROJECT_SOURCE_DIR};ROVER_SHARED_DIR=${ROVER_SHARED_DIR}")
  set(properties "LABELS \"${ARG_LABELS}\" ENVIRONMENT \"${environment}\"")
  if(ARG_RESOURCE_LOCK)
    string(APPEND properties " RESOURCE_LOCK \"${ARG_RESOURCE_LOCK}\"")
  endif()
  set(script "${CMAKE_CURRENT_BINARY_DIR}/${ARG_NAME}_properties.cmake")
  file(WRITE "${script}" "if(${ARG_NAME}_TESTS)\n"
    "  set_tests_properties(\${${ARG_NAME}_TESTS} PROPERTIES ${properties})\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${script}")
  # Remembered per label so tests/CMakeLists.txt can make one target per
  # sanitizer label: the sanitizer presets build only what they run.
  foreach(label IN LISTS ARG_LABELS)
    set_property(GLOBAL APPEND PROPERTY ROVER_TESTS_LABELLED_${label} ${ARG_NAME})
  endforeach()
endfunction()
