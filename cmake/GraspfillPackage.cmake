# SPDX-License-Identifier: BSD-3-Clause
# graspfill as a package.
#
# Every product library is exported as graspfill::<name>: installed
# (install(EXPORT), find_package(graspfill)) and, for projects that
# add_subdirectory() graspfill, as an ALIAS of the same name. The CLI's and
# the tests' tool libraries (synth, eval; graspfill_module(... INTERNAL)) and
# the Poisson baseline are neither. graspfill_install_package() at the
# end of the top-level CMakeLists installs the libraries, the public and the
# generated LCM headers, graspfillConfig.cmake with its version file,
# graspfill.pc, the CLI and its data.
include(CMakePackageConfigHelpers)

set(GRASPFILL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/graspfill)
# The CLI's data: <prefix>/share/graspfill/{replay,claws}, found relative to
# the executable (bin/../share/graspfill, rt/cli/data_paths.hpp). The build
# tree mirrors it (bin/ and share/graspfill/ side by side, linked to the
# source tree's replay/ and config/claws/).
set(GRASPFILL_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/graspfill)

# graspfill_export(<target> <name>): <target> becomes graspfill::<name>.
function(graspfill_export target name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "EXECUTABLE")
    add_executable(graspfill::${name} ALIAS ${target})
  else()
    add_library(graspfill::${name} ALIAS ${target})
  endif()
  set_property(GLOBAL APPEND PROPERTY GRASPFILL_EXPORTED_TARGETS ${target})
endfunction()

# The CLI's data beside the build tree's bin/, as it is installed.
function(graspfill_stage_data)
  set(data_dir ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/../share/graspfill)
  file(MAKE_DIRECTORY ${data_dir})
  foreach(pair "replay;replay" "config/claws;claws")
    list(GET pair 0 from)
    list(GET pair 1 to)
    file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${from} ${data_dir}/${to} SYMBOLIC
      RESULT result)
    if(NOT result STREQUAL "0")  # no symbolic links here: a copy
      file(COPY ${PROJECT_SOURCE_DIR}/${from}/ DESTINATION ${data_dir}/${to})
    endif()
  endforeach()
endfunction()

# graspfill.pc: our static libraries in link order, then their dependencies.
# Open3D and Embree by file: Embree ships no .pc, and Open3D's puts -std=c++14
# into the consumer's flags (no public graspfill header includes either).
function(graspfill_write_pkg_config)
  set(libs)
  foreach(name rt_module rt_sources rt_sinks mesh io view pipeline refine repair
               evidence fusion claw core)
    string(APPEND libs " -lgraspfill_${name}")
  endforeach()
  set(GRASPFILL_PC_LIBS "${libs}")
  set(GRASPFILL_PC_REQUIRES "eigen3 lcm nlohmann_json zlib fmt urdfdom assimp")
  if(GRASPFILL_WITH_OPENNI2)
    string(APPEND GRASPFILL_PC_REQUIRES " libopenni2")
  endif()
  file(RELATIVE_PATH GRASPFILL_PC_PREFIX_FROM_PCFILEDIR
    /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
  string(REGEX REPLACE "/$" "" GRASPFILL_PC_PREFIX_FROM_PCFILEDIR
    "${GRASPFILL_PC_PREFIX_FROM_PCFILEDIR}")
  configure_file(${PROJECT_SOURCE_DIR}/cmake/graspfill.pc.in
    ${PROJECT_BINARY_DIR}/graspfill.pc.configured @ONLY)
  file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/graspfill.pc
    INPUT ${PROJECT_BINARY_DIR}/graspfill.pc.configured)
  install(FILES ${PROJECT_BINARY_DIR}/graspfill.pc
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endfunction()

function(graspfill_install_package)
  if(TARGET graspfill)
    graspfill_stage_data()
  endif()
  if(NOT GRASPFILL_INSTALL)
    return()
  endif()
  get_property(targets GLOBAL PROPERTY GRASPFILL_EXPORTED_TARGETS)
  install(TARGETS ${targets} EXPORT graspfillTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(EXPORT graspfillTargets
    NAMESPACE graspfill::
    DESTINATION ${GRASPFILL_INSTALL_CMAKEDIR})

  configure_package_config_file(
    ${PROJECT_SOURCE_DIR}/cmake/graspfillConfig.cmake.in
    ${PROJECT_BINARY_DIR}/graspfillConfig.cmake
    INSTALL_DESTINATION ${GRASPFILL_INSTALL_CMAKEDIR}
    PATH_VARS GRASPFILL_INSTALL_DATADIR)
  # 0.x: a minor release may break the API.
  write_basic_package_version_file(
    ${PROJECT_BINARY_DIR}/graspfillConfigVersion.cmake
    VERSION ${PROJECT_VERSION}
    COMPATIBILITY SameMinorVersion)
  install(FILES
    ${PROJECT_BINARY_DIR}/graspfillConfig.cmake
    ${PROJECT_BINARY_DIR}/graspfillConfigVersion.cmake
    DESTINATION ${GRASPFILL_INSTALL_CMAKEDIR})

  # Public headers: include/graspfill/..., the runtime's under
  # include/graspfill/rt/ (included as "sources/...", "sinks/...",
  # "module/..."; graspfill::rt_* carry that folder). The generated LCM
  # headers go beside them (lcm_gen_cpp).
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/graspfill
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
    FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
  install(DIRECTORY
      ${PROJECT_SOURCE_DIR}/rt/sources
      ${PROJECT_SOURCE_DIR}/rt/sinks
      ${PROJECT_SOURCE_DIR}/rt/module
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/graspfill/rt
    FILES_MATCHING PATTERN "*.hpp")

  graspfill_write_pkg_config()

  install(DIRECTORY ${PROJECT_SOURCE_DIR}/replay/
    DESTINATION ${GRASPFILL_INSTALL_DATADIR}/replay)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/claws/
    DESTINATION ${GRASPFILL_INSTALL_DATADIR}/claws)
  install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/NOTICE
    DESTINATION ${CMAKE_INSTALL_DOCDIR})
endfunction()
