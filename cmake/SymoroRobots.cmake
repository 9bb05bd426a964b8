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

# symoro_add_robot_identification(<name> <model count>): the static library
# symoro::<name>_identification with each model's IdentificationModel
# (symoro/identify/identification_model.hpp), the only part of identification compiled per
# model: one unit per model (cmake/identification_unit.cpp.in), the last one also taking any model
# beyond the count. Whatever studies the robot's models (dynid, tests, applications) links it.
function(symoro_add_robot_identification name count)
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
    set(file "${CMAKE_BINARY_DIR}/robot_units/${name}/identification_${i}.cpp")
    configure_file("${PROJECT_SOURCE_DIR}/cmake/identification_unit.cpp.in" "${file}" @ONLY)
    list(APPEND units "${file}")
  endforeach()
  set(target symoro_${name}_identification)
  add_library(${target} STATIC ${units})
  add_library(symoro::${name}_identification ALIAS ${target})
  target_link_libraries(${target} PUBLIC symoro_robot_${name} symoro_identify)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name}_identification POSITION_INDEPENDENT_CODE ON)
  install(TARGETS ${target} EXPORT symoroTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()

# symoro_add_robot_diagnosis(<name> <model count>): the static library symoro::<name>_diagnosis
# with each model's DiagnosisModel (symoro/diagnose/diagnosis_model.hpp), the only part of the
# diagnosis compiled per model: one unit per model (cmake/diagnosis_unit.cpp.in, the last one
# also taking any model beyond the count) and one for the robot's twin (diagnosis_backlash.cpp.in).
function(symoro_add_robot_diagnosis name count)
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
    set(file "${CMAKE_BINARY_DIR}/robot_units/${name}/diagnosis_${i}.cpp")
    configure_file("${PROJECT_SOURCE_DIR}/cmake/diagnosis_unit.cpp.in" "${file}" @ONLY)
    list(APPEND units "${file}")
  endforeach()
  set(file "${CMAKE_BINARY_DIR}/robot_units/${name}/diagnosis_backlash.cpp")
  configure_file("${PROJECT_SOURCE_DIR}/cmake/diagnosis_backlash.cpp.in" "${file}" @ONLY)
  list(APPEND units "${file}")
  set(target symoro_${name}_diagnosis)
  add_library(${target} STATIC ${units})
  add_library(symoro::${name}_diagnosis ALIAS ${target})
  target_link_libraries(${target} PUBLIC symoro_robot_${name} symoro_${name}_identification symoro_diagnose)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name}_diagnosis POSITION_INDEPENDENT_CODE ON)
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
  if(TARGET symoro_identify)
    symoro_add_robot_identification(${name} ${models})
  endif()
  if(TARGET symoro_diagnose)
    symoro_add_robot_diagnosis(${name} ${models})
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
