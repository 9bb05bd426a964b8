# Every folder of robots/ with a robot.yaml becomes an INTERFACE target symoro::<name> over its
# headers: the committed ones in generated/<name>/ when present, otherwise headers symoroc
# writes into the build tree (a robot just dropped into robots/ builds with no other change).

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
