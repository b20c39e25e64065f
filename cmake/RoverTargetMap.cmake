# rover_write_target_map(): writes ${CMAKE_BINARY_DIR}/rover_targets.tsv, one
# line per target of the build: `name<TAB>folder`, the folder being the source
# directory that defines the target, relative to the project root ("." for the
# root itself). `cmake --graphviz` gives the link graph but not where a target
# is defined; scripts/check_link_graph.py needs both to check the layering
# (tests/architecture/link_rules.txt).
#
# Alias targets (rover::core) cannot be listed through any property, so the
# ones that some target links by name get a third column naming the real
# target: `rover::core<TAB>core<TAB>rover_core`. That lets the checker resolve
# a graph that shows aliases as nodes of their own.
#
# Call it at the very end of the top-level CMakeLists.txt, when every target
# exists.

# Appends to `out_var` the source directory `dir` and all directories below it
# that add_subdirectory() reached.
function(_rover_collect_dirs dir out_var)
  set(dirs ${${out_var}} "${dir}")
  get_property(subdirs DIRECTORY "${dir}" PROPERTY SUBDIRECTORIES)
  foreach(subdir IN LISTS subdirs)
    _rover_collect_dirs("${subdir}" dirs)
  endforeach()
  set(${out_var} ${dirs} PARENT_SCOPE)
endfunction()

# Appends to `out_var` one `alias<TAB>folder<TAB>real` line for each alias of a
# project target that `target` links, publicly or privately.
function(_rover_collect_aliases target out_var)
  set(lines ${${out_var}})
  get_target_property(type ${target} TYPE)
  set(props INTERFACE_LINK_LIBRARIES)
  if(NOT type STREQUAL "INTERFACE_LIBRARY")
    list(APPEND props LINK_LIBRARIES)
  endif()
  foreach(prop IN LISTS props)
    get_target_property(items ${target} ${prop})
    if(NOT items)
      continue()
    endif()
    # A static library's private links appear as $<LINK_ONLY:name>; other
    # generator expressions cannot be resolved here and are skipped.
    string(REGEX REPLACE "\\$<LINK_ONLY:([^>$]*)>" "\\1" items "${items}")
    foreach(item IN LISTS items)
      if(item MATCHES "\\$<" OR NOT TARGET "${item}")
        continue()
      endif()
      get_target_property(real "${item}" ALIASED_TARGET)
      if(NOT real)
        continue()
      endif()
      get_target_property(imported "${real}" IMPORTED)
      if(NOT imported)
        get_target_property(real_dir "${real}" SOURCE_DIR)
        file(RELATIVE_PATH folder "${PROJECT_SOURCE_DIR}" "${real_dir}")
        if(folder STREQUAL "")
          set(folder ".")
        endif()
        list(APPEND lines "${item}\t${folder}\t${real}")
      endif()
    endforeach()
  endforeach()
  set(${out_var} ${lines} PARENT_SCOPE)
endfunction()

function(rover_write_target_map)
  set(dirs "")
  _rover_collect_dirs("${PROJECT_SOURCE_DIR}" dirs)
  set(lines "")
  set(aliases "")
  foreach(dir IN LISTS dirs)
    file(RELATIVE_PATH folder "${PROJECT_SOURCE_DIR}" "${dir}")
    if(folder STREQUAL "")
      set(folder ".")
    endif()
    get_property(targets DIRECTORY "${dir}" PROPERTY BUILDSYSTEM_TARGETS)
    foreach(target IN LISTS targets)
      list(APPEND lines "${target}\t${folder}")
      _rover_collect_aliases(${target} aliases)
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES aliases)
  list(APPEND lines ${aliases})
  list(JOIN lines "\n" text)
  file(WRITE "${CMAKE_BINARY_DIR}/rover_targets.tsv" "${text}\n")
endfunction()
