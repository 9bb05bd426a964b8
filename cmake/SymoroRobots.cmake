# Every folder of robots/ with a robot.yaml becomes an INTERFACE target symoro::<name> over its
# headers: the committed ones in generated/<name>/ when present, otherwise headers symoroc
# writes into the build tree (a robot just dropped into robots/ builds with no other change).

# symoro_robot_model_count(<robot.yaml> <out var>): 1 (the full model) + the variants robot.yaml
# lists in block style (`variants:`, then one `  <name>:` line each; flow style counts 0). Only
# how the templated tests split their units (tests/CMakeLists.txt).
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

# symoro_robot_library(<name> <kind> <area> <template>...): the static library symoro::<name>_<kind>
# over symoro_<area>, with one unit from each template cmake/<t>.cpp.in (all the robot's models).
function(symoro_robot_library name kind area)
  set(units "")
  set(unit_robot ${name})
  foreach(template IN LISTS ARGN)
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

# symoro_robot_kernels(<name> <robot dir> <headers>...): the robot's generated kernels, compiled
# once, by symoroc build: its robot library into the build tree's robot cache (what dynid, the
# Python package and the tests load for a folder, found there with no compile) and the same
# objects, partially linked, into robot_units/<name>/kernels.o, which symoro::<name>_identification
# holds (compiled_model<Model>()). It reruns when the robot's files, its generated headers, the
# ABI's headers or the configured compiler and flags change.
function(symoro_robot_kernels name robot_dir)
  set(objects "${CMAKE_BINARY_DIR}/robot_units/${name}/kernels.o")
  file(GLOB inputs CONFIGURE_DEPENDS "${robot_dir}/*")
  set(abi "")
  foreach(h IN LISTS SYMORO_ROBOT_ABI_HEADERS)  # codegen/CMakeLists.txt: the cache key's headers
    list(APPEND abi "${PROJECT_SOURCE_DIR}/runtime/include/symoro/${h}")
  endforeach()
  add_custom_command(
    OUTPUT "${objects}"
    COMMAND symoroc build "${robot_dir}" --cache "${PROJECT_BINARY_DIR}/robot_cache" --jobs 1 --objects "${objects}"
    DEPENDS ${inputs} ${ARGN} ${abi} "${PROJECT_BINARY_DIR}/codegen/config/robot_library_config.hpp"
    COMMENT "symoroc build: ${name}'s kernels (its robot library and kernels.o)"
    VERBATIM)
  set_source_files_properties("${objects}" PROPERTIES EXTERNAL_OBJECT TRUE GENERATED TRUE)
  target_sources(symoro_${name}_identification PRIVATE "${objects}")
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
  # The number of models (tests/CMakeLists.txt splits a robot's templated tests by it).
  symoro_robot_model_count("${robot_dir}/robot.yaml" models)
  set_property(GLOBAL PROPERTY SYMORO_ROBOT_MODELS_${name} ${models})
  # What is compiled per robot: its generated kernels in the robot library's C ABI, once
  # (symoro_robot_kernels), under the runtime's one IdentificationModel and DiagnosisModel
  # (symoro/identify/loaded_model.hpp, symoro/diagnose/loaded_model.hpp): whatever studies or
  # diagnoses the robot's models (dynid, the Python package, tests, applications) links
  # symoro::<name>_identification, symoro::<name>_diagnosis.
  if(TARGET symoro_identify)
    symoro_robot_library(${name} identification identify kernels identification)
    if(EXISTS "${committed}/symoro/${name}.hpp")
      file(GLOB_RECURSE headers CONFIGURE_DEPENDS "${committed}/*.hpp")
    else()
      set(headers "${include_dir}/symoro/${name}.hpp")
    endif()
    symoro_robot_kernels(${name} "${robot_dir}" ${headers})
  endif()
  if(TARGET symoro_diagnose)
    symoro_robot_library(${name} diagnosis diagnose diagnosis)
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
