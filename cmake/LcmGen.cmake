# SPDX-License-Identifier: BSD-3-Clause
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

# Bindings for planners in other languages (issue 11), generated from the
# same .lcm files. Python needs nothing but the interpreter (the generated
# classes use only `struct`); Java needs a JDK and LCM's own jar
# (liblcm-java), and is skipped with a note when either is missing.
set(GRASPFILL_INSTALL_PYTHONDIR lib/python3/dist-packages CACHE STRING
  "Where the Python package `graspfill` (lcm-gen -p) is installed, relative to the prefix")
set(GRASPFILL_INSTALL_JAVADIR ${CMAKE_INSTALL_DATADIR}/java CACHE STRING
  "Where graspfill_lcmtypes.jar is installed, relative to the prefix")

# lcm_gen_python(<target> FILES ... [INIT_APPEND file]): the package
# `graspfill` under <build>/lcmgen/python (one lcm-gen call: it writes
# __init__.py for all types); INIT_APPEND's text is added to that
# __init__.py (the Python module's imports, rt/python).
function(lcm_gen_python target)
  cmake_parse_arguments(ARG "" "INIT_APPEND" "FILES" ${ARGN})
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/lcmgen/python)
  set(sources)
  set(modules ${out_dir}/graspfill/__init__.py)
  foreach(lcm_file ${ARG_FILES})
    get_filename_component(type_name ${lcm_file} NAME_WE)
    list(APPEND sources ${CMAKE_CURRENT_SOURCE_DIR}/${lcm_file})
    list(APPEND modules ${out_dir}/graspfill/${type_name}.py)
  endforeach()
  set(append_init)
  if(ARG_INIT_APPEND)
    set(append_init COMMAND ${CMAKE_COMMAND} -DFROM=${ARG_INIT_APPEND}
      -DTO=${out_dir}/graspfill/__init__.py -P ${PROJECT_SOURCE_DIR}/cmake/AppendFile.cmake)
  endif()
  add_custom_command(
    OUTPUT ${modules}
    # A fresh __init__.py: lcm-gen adds to an existing one. The folder stays:
    # the Python module is built into it (rt/python).
    COMMAND ${CMAKE_COMMAND} -E rm -f ${out_dir}/graspfill/__init__.py
    COMMAND ${LCM_GEN_EXECUTABLE} --python --ppath ${out_dir} ${sources}
    ${append_init}
    DEPENDS ${sources} ${ARG_INIT_APPEND}
    COMMENT "lcm-gen --python"
    VERBATIM)
  add_custom_target(${target} ALL DEPENDS ${modules})
  set_target_properties(${target} PROPERTIES PYTHON_PATH ${out_dir})
  if(GRASPFILL_INSTALL)
    install(FILES ${modules} DESTINATION ${GRASPFILL_INSTALL_PYTHONDIR}/graspfill)
  endif()
endfunction()

# lcm_gen_java(<target> FILES ...): graspfill_lcmtypes.jar (classes
# graspfill.<type>), or no target when no JDK or lcm.jar is found. The
# target's property LCM_JAR is LCM's jar (compile and run against both).
function(lcm_gen_java target)
  cmake_parse_arguments(ARG "" "" "FILES" ${ARGN})
  find_package(Java 1.8 COMPONENTS Development QUIET)
  pkg_check_modules(LCM_JAVA QUIET lcm-java)
  if(LCM_JAVA_FOUND)
    pkg_get_variable(lcm_jar lcm-java classpath)
  endif()
  if(NOT Java_FOUND OR NOT lcm_jar OR NOT EXISTS "${lcm_jar}")
    message(STATUS "graspfill: no Java bindings (needs a JDK and liblcm-java's lcm.jar: "
      "apt-get install default-jdk-headless liblcm-java)")
    return()
  endif()
  include(UseJava)
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/lcmgen/java)
  set(sources)
  set(java_files)
  foreach(lcm_file ${ARG_FILES})
    get_filename_component(type_name ${lcm_file} NAME_WE)
    list(APPEND sources ${CMAKE_CURRENT_SOURCE_DIR}/${lcm_file})
    list(APPEND java_files ${out_dir}/graspfill/${type_name}.java)
  endforeach()
  add_custom_command(
    OUTPUT ${java_files}
    COMMAND ${LCM_GEN_EXECUTABLE} --java --jpath ${out_dir} ${sources}
    DEPENDS ${sources}
    COMMENT "lcm-gen --java"
    VERBATIM)
  add_jar(${target} SOURCES ${java_files} INCLUDE_JARS ${lcm_jar}
    OUTPUT_NAME graspfill_lcmtypes)
  if(GRASPFILL_INSTALL)
    install_jar(${target} DESTINATION ${GRASPFILL_INSTALL_JAVADIR})
  endif()
  set_property(TARGET ${target} PROPERTY LCM_JAR ${lcm_jar})
endfunction()
