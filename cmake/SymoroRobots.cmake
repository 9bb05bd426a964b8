# Every folder of robots/ with a robot.yaml becomes an INTERFACE target symoro::<name> over its
# headers: the committed ones in generated/<name>/ when present, otherwise headers symoroc
# writes into the build tree (a robot just dropped into robots/ builds with no other change).

# symoro_robot_model_count(<robot.yaml> <out var>): 1 (the full model) + the variants robot.yaml
# lists in block style (`variants:`, then one `  <name>:` line each; flow style counts 0). Only
# how dynid splits its units (runtime/tools): a count that is off still compiles every model.
function(symoro_robot_model_count yaml out)
  file(STRINGS "${yaml}" lines)
  set(count 1)
  set(in_variants FALSE)
  set(indent "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^variants:[ \t]*(#.*)?$")
      set(in_variants TRUE)
    elseif(in_variants AND line MATCHES "^[^ \t#]")
      break()  # the next top-level key
    elseif(in_variants AND line MATCHES "^( +)[a-z][a-z0-9_]*:")
      if(indent STREQUAL "")
        set(indent "${CMAKE_MATCH_1}")
      endif()
      if(CMAKE_MATCH_1 STREQUAL indent)
        math(EXPR count "${count} + 1")
      endif()
    endif()
  endforeach()
  set(${out} ${count} PARENT_SCOPE)
endfunction()

# symoro_robot_library(<name> <model count> <kind> <area> [PER_MODEL <template>...] [ONCE
# <template>...]): the static library symoro::<name>_<kind> over symoro_<area>, with one unit per
# model of the robot from each PER_MODEL template cmake/<t>_unit.cpp.in (the last one also taking
# any model beyond the count), so that a robot's models compile in parallel, and one unit from
# each ONCE template cmake/<t>.cpp.in (all models: index 0, tail).
function(symoro_robot_library name count kind area)
  cmake_parse_arguments(ARG "" "" "PER_MODEL;ONCE" ${ARGN})
  set(units "")
  math(EXPR last "${count} - 1")
  set(unit_robot ${name})
  foreach(i RANGE 0 ${last})
    set(unit_index ${i})
    if(i EQUAL last)
      set(unit_tail true)
      set(unit_what "model ${i} of its Models, and any later one")
    else()
      set(unit_tail false)
      set(unit_what "model ${i} of its Models")
    endif()
    foreach(template IN LISTS ARG_PER_MODEL)
      set(file "${CMAKE_BINARY_DIR}/robot_units/${name}/${template}_${i}.cpp")
      configure_file("${PROJECT_SOURCE_DIR}/cmake/${template}_unit.cpp.in" "${file}" @ONLY)
      list(APPEND units "${file}")
    endforeach()
  endforeach()
  set(unit_index 0)
  set(unit_tail true)
  set(unit_what "all its models")
  foreach(template IN LISTS ARG_ONCE)
    set(file "${CMAKE_BINARY_DIR}/robot_units/${name}/${template}.cpp")
    configure_file("${PROJECT_SOURCE_DIR}/cmake/${template}.cpp.in" "${file}" @ONLY)
    list(APPEND units "${file}")
  endforeach()
  set(target symoro_${name}_${kind})
  add_library(${target} STATIC ${units})
  add_library(symoro::${name}_${kind} ALIAS ${target})
  target_link_libraries(${target} PUBLIC symoro_robot_${name} symoro_${area})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name}_${kind} POSITION_INDEPENDENT_CODE ON)
  install(TARGETS ${target} EXPORT symoroTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()

# symoro_add_robot(<name> <robot dir>)
function(symoro_add_robot name robot_dir)
  set(committed "${PROJECT_SOURCE_DIR}/generated/${name}/include")
  set(target symoro_robot_${name})
  add_library(${target} INTERFACE)
  add_library(symoro::${name} ALIAS ${target})
  if(EXISTS "${committed}/symoro/${name}.hpp")
    set(include_dir "${committed}")
  else()
    set(out_root "${CMAKE_BINARY_DIR}/generated")
    set(include_dir "${out_root}/${name}/include")
    file(GLOB inputs CONFIGURE_DEPENDS "${robot_dir}/*")
    add_custom_command(
      OUTPUT "${include_dir}/symoro/${name}.hpp"
      COMMAND symoroc generate "${robot_dir}" -o "${out_root}"
      DEPENDS symoroc ${inputs}
      COMMENT "symoroc: generating ${name} (no committed headers in generated/${name})"
      VERBATIM)
    add_custom_target(symoro_generate_${name} DEPENDS "${include_dir}/symoro/${name}.hpp")
    add_dependencies(${target} symoro_generate_${name})
    file(MAKE_DIRECTORY "${include_dir}")
  endif()
  target_include_directories(${target} INTERFACE
    $<BUILD_INTERFACE:${include_dir}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} INTERFACE symoro_core)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  install(TARGETS ${target} EXPORT symoroTargets)
  install(DIRECTORY "${include_dir}/" DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  set_property(GLOBAL APPEND PROPERTY SYMORO_ROBOTS ${name})
  # A variant added to robot.yaml reconfigures, so it gets its own dynid units.
  symoro_robot_model_count("${robot_dir}/robot.yaml" models)
  set_property(GLOBAL PROPERTY SYMORO_ROBOT_MODELS_${name} ${models})
  # What is compiled per model: its generated kernels in the robot library's C ABI
  # (symoro/robot/compiled_model.hpp), under the runtime's one IdentificationModel and
  # DiagnosisModel (symoro/identify/loaded_model.hpp, symoro/diagnose/loaded_model.hpp): whatever
  # studies or diagnoses the robot's models (dynid, the Python package, tests, applications) links
  # symoro::<name>_identification, symoro::<name>_diagnosis.
  if(TARGET symoro_identify)
    symoro_robot_library(${name} ${models} identification identify PER_MODEL kernels kernels_d2 ONCE identification)
  endif()
  if(TARGET symoro_diagnose)
    symoro_robot_library(${name} ${models} diagnosis diagnose ONCE diagnosis)
    target_link_libraries(symoro_${name}_diagnosis PUBLIC symoro_${name}_identification)
  endif()
  set_property(DIRECTORY "${PROJECT_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${robot_dir}/robot.yaml")
endfunction()

# symoro_add_all_robots(<robots dir>): one target per robot folder; sets SYMORO_ROBOTS.
function(symoro_add_all_robots robots_dir)
  file(GLOB yamls CONFIGURE_DEPENDS "${robots_dir}/*/robot.yaml")
  list(SORT yamls)
  set(names)
  foreach(yaml IN LISTS yamls)
    get_filename_component(dir "${yaml}" DIRECTORY)
    get_filename_component(name "${dir}" NAME)
    symoro_add_robot(${name} "${dir}")
    list(APPEND names ${name})
  endforeach()
  set(SYMORO_ROBOTS ${names} PARENT_SCOPE)
endfunction()
