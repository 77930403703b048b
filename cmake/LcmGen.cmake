# Debian's liblcm-dev ships no CMake config, so lcm-gen is driven here directly.
# lcm_gen_cpp(<target> <dir> <files...>) generates C++ headers for the .lcm files
# into the build tree and exposes them through an INTERFACE target; installed
# beside the public headers (<prefix>/include/graspfill/<type>.hpp).
find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)

function(lcm_gen_cpp target)
  cmake_parse_arguments(ARG "" "" "FILES" ${ARGN})
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/lcmgen)
  set(headers)
  foreach(lcm_file ${ARG_FILES})
    get_filename_component(type_name ${lcm_file} NAME_WE)
    # Every graspfill type lives in package `graspfill`.
    set(header ${out_dir}/graspfill/${type_name}.hpp)
    list(APPEND headers ${header})
    add_custom_command(
      OUTPUT ${header}
      COMMAND ${LCM_GEN_EXECUTABLE} --cpp --cpp-hpath ${out_dir} ${CMAKE_CURRENT_SOURCE_DIR}/${lcm_file}
      DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${lcm_file}
      COMMENT "lcm-gen ${lcm_file}"
      VERBATIM)
  endforeach()
  add_custom_target(${target}_gen DEPENDS ${headers})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_gen)
  target_include_directories(${target} INTERFACE
    $<BUILD_INTERFACE:${out_dir}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  if(GRASPFILL_INSTALL)
    install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/graspfill)
  endif()
endfunction()
