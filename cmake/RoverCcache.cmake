# Compiler cache for every preset. One cache in the user's cache folder
# (~/.cache/ccache, or $CCACHE_DIR) serves every clone on the machine: paths are
# made relative to the source root and the working folder is left out of the
# hash, so a fresh clone in another folder hits what an earlier one compiled.
# Off with -DROVER_CCACHE=OFF; absent ccache only costs speed.
option(ROVER_CCACHE "Compile through ccache when it is installed" ON)
if(ROVER_CCACHE)
  find_program(ROVER_CCACHE_PROGRAM ccache)
  if(ROVER_CCACHE_PROGRAM)
    # Four presets (dev, asan, tsan, release) of ~1,000 objects each; the
    # default 5 GB would evict the sanitizer builds between CI runs.
    set(_launcher ${CMAKE_COMMAND} -E env
      "CCACHE_BASEDIR=${PROJECT_SOURCE_DIR}" CCACHE_NOHASHDIR=true
      CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
      CCACHE_MAXSIZE=25G ${ROVER_CCACHE_PROGRAM})
    set(CMAKE_C_COMPILER_LAUNCHER ${_launcher})
    set(CMAKE_CXX_COMPILER_LAUNCHER ${_launcher})
    message(STATUS "ccache: ${ROVER_CCACHE_PROGRAM} (base dir ${PROJECT_SOURCE_DIR})")
  else()
    message(STATUS "ccache: not found, compiling without a cache")
  endif()
endif()
