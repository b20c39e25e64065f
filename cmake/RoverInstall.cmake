# Deployment: `cmake --install BUILD --prefix PREFIX` installs
#   bin/                 roverd, mapd, roverd-sim and the host tools (those built here)
#   lib/systemd/system/  rover-roudi, rover-roverd, rover-mapd .service
#   lib/sysusers.d/      rover.conf (the `rover` user and group)
#   etc/rover/           board.yaml, roudi.toml; with PREFIX /usr: /etc/rover/
# On a board: `cmake --install build/release --prefix /usr`, which matches the
# units' /usr/bin/... and /etc/rover/... paths (firmware/README.md).
#
# Included at the end of the top-level CMakeLists.txt, so `if(TARGET ...)`
# sees every executable of the tree, whichever folder defines it.
include(GNUInstallDirs)

set(ROVER_INSTALL_SYSTEMD_UNITDIR "lib/systemd/system" CACHE STRING
  "systemd system unit folder (relative: below the install prefix)")
set(ROVER_INSTALL_SYSUSERSDIR "lib/sysusers.d" CACHE STRING
  "systemd-sysusers folder (relative: below the install prefix)")

# Firmware processes first, then the host tools. A name that is no target in
# this build (not written yet, or not configured) is skipped.
set(_rover_programs roverd mapd roverd-sim rover-sim rover-log rover-replay rover-eval
  rover-graph rover-calib)
set(_rover_installed_programs "")
foreach(_program IN LISTS _rover_programs)
  if(TARGET ${_program})
    install(TARGETS ${_program} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    list(APPEND _rover_installed_programs ${_program})
  endif()
endforeach()
# For tests/firmware/runtime/board/install_test.sh: which programs to expect.
file(WRITE ${PROJECT_BINARY_DIR}/rover_install_programs.txt "${_rover_installed_programs}\n")

install(FILES
  ${PROJECT_SOURCE_DIR}/firmware/systemd/rover-roudi.service
  ${PROJECT_SOURCE_DIR}/firmware/systemd/rover-roverd.service
  ${PROJECT_SOURCE_DIR}/firmware/systemd/rover-mapd.service
  DESTINATION ${ROVER_INSTALL_SYSTEMD_UNITDIR})
install(FILES ${PROJECT_SOURCE_DIR}/firmware/systemd/rover.sysusers.conf
  DESTINATION ${ROVER_INSTALL_SYSUSERSDIR} RENAME rover.conf)

# The configuration, decided at install time because `--prefix` may differ
# from the configured prefix: GNUInstallDirs' rule that prefix /usr puts the
# configuration in /etc (an absolute CMAKE_INSTALL_SYSCONFDIR wins). An
# existing file that differs (edited on the board) is kept; the new one goes
# next to it as NAME.dist.
install(CODE "
  set(_rover_config_src \"${PROJECT_SOURCE_DIR}/firmware/config\")
  set(_rover_sysconfdir \"${CMAKE_INSTALL_SYSCONFDIR}\")
")
install(CODE [[
  if(IS_ABSOLUTE "${_rover_sysconfdir}")
    set(_rover_etc "${_rover_sysconfdir}/rover")
  elseif(CMAKE_INSTALL_PREFIX MATCHES "^/usr/?$")
    set(_rover_etc "/etc/rover")
  else()
    set(_rover_etc "${CMAKE_INSTALL_PREFIX}/${_rover_sysconfdir}/rover")
  endif()
  set(_rover_etc_dest "$ENV{DESTDIR}${_rover_etc}")  # where the files are now
  foreach(_name board.yaml roudi.toml)
    set(_src "${_rover_config_src}/${_name}")
    set(_rename "${_name}")
    if(EXISTS "${_rover_etc_dest}/${_name}")
      file(SHA256 "${_src}" _new)
      file(SHA256 "${_rover_etc_dest}/${_name}" _old)
      if(NOT _new STREQUAL _old)
        message(STATUS "Keeping the edited ${_rover_etc_dest}/${_name}; the new one is ${_name}.dist")
        set(_rename "${_name}.dist")
      endif()
    endif()
    # Copied by hand: file(INSTALL) with an absolute destination prepends
    # DESTDIR differently across CMake versions.
    file(MAKE_DIRECTORY "${_rover_etc_dest}")
    file(COPY_FILE "${_src}" "${_rover_etc_dest}/${_rename}")
    message(STATUS "Installing: ${_rover_etc_dest}/${_rename}")
  endforeach()
]])
