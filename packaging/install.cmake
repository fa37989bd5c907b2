# Install rules of the airseg product: the programs, the systemd unit, the configuration file
# (/etc/airseg/airseg.yaml, a conffile in the Debian package), manual pages and example plans.
# Pulled in at the end of the top-level directory (see systemd/CMakeLists.txt); including it a
# second time is harmless.
include_guard(GLOBAL)
include(GNUInstallDirs)

# The systemd unit directory: /lib/systemd/system for a /usr install on Debian 12.
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(_airseg_unit_dir_default /lib/systemd/system)
else()
  set(_airseg_unit_dir_default ${CMAKE_INSTALL_PREFIX}/lib/systemd/system)
endif()
set(AIRSEG_SYSTEMD_UNIT_DIR ${_airseg_unit_dir_default} CACHE PATH "Where the systemd unit is installed")

# Finds the executable target whose file is called OUTPUT (its OUTPUT_NAME, or its name),
# whatever directory defines it, so the rules do not depend on how each area names its targets.
function(_airseg_find_executable output dir result)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(t IN LISTS targets)
    get_target_property(type ${t} TYPE)
    if(type STREQUAL "EXECUTABLE")
      get_target_property(name ${t} OUTPUT_NAME)
      if(NOT name)
        set(name ${t})
      endif()
      if(name STREQUAL output)
        set(${result} ${t} PARENT_SCOPE)
        return()
      endif()
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub IN LISTS subdirs)
    _airseg_find_executable(${output} ${sub} found)
    if(found)
      set(${result} ${found} PARENT_SCOPE)
      return()
    endif()
  endforeach()
  set(${result} "" PARENT_SCOPE)
endfunction()

set(_airseg_not_installed "")
set(_airseg_man_dir ${CMAKE_CURRENT_LIST_DIR}/man)
# program | destination | manual page (section file) or -
set(_airseg_programs
    "airsegd|${CMAKE_INSTALL_SBINDIR}|airsegd.8"
    "airsegctl|${CMAKE_INSTALL_BINDIR}|airsegctl.1"
    "airseg-ground|${CMAKE_INSTALL_BINDIR}|airseg-ground.1"
    "airseg-apmsim|${CMAKE_INSTALL_BINDIR}|airseg-apmsim.1"
    "airseg-linksim|${CMAKE_INSTALL_BINDIR}|airseg-linksim.1"
    "airseg-mavdump|${CMAKE_INSTALL_BINDIR}|airseg-mavdump.1")
foreach(entry IN LISTS _airseg_programs)
  string(REPLACE "|" ";" entry "${entry}")
  list(GET entry 0 program)
  list(GET entry 1 destination)
  list(GET entry 2 manpage)
  _airseg_find_executable(${program} ${PROJECT_SOURCE_DIR} target)
  if(NOT target)
    list(APPEND _airseg_not_installed ${program})
    continue()
  endif()
  install(TARGETS ${target} RUNTIME DESTINATION ${destination})
  if(NOT manpage STREQUAL "-")
    string(REGEX REPLACE ".*\\.([0-9])$" "\\1" section ${manpage})
    install(FILES ${_airseg_man_dir}/${manpage} DESTINATION ${CMAKE_INSTALL_MANDIR}/man${section})
  endif()
endforeach()

if(_airseg_not_installed)
  message(STATUS "Not in this build, so not installed: ${_airseg_not_installed}")
endif()

install(FILES ${PROJECT_SOURCE_DIR}/systemd/airsegd.service ${PROJECT_SOURCE_DIR}/systemd/airseg-ground.service
        DESTINATION ${AIRSEG_SYSTEMD_UNIT_DIR})

if(EXISTS ${PROJECT_SOURCE_DIR}/config/airseg.yaml)
  install(FILES ${PROJECT_SOURCE_DIR}/config/airseg.yaml DESTINATION ${CMAKE_INSTALL_FULL_SYSCONFDIR}/airseg)
endif()
if(IS_DIRECTORY ${PROJECT_SOURCE_DIR}/config/plans)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/plans/
          DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples/plans
          FILES_MATCHING PATTERN "*.yaml")
endif()
