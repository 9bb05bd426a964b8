# Installs symoro as a CMake package: find_package(symoro) gives symoro::core and one
# symoro::<robot> target per generated robot (header-only over Eigen), and the runtime's stages
# as static libraries: symoro::io (logs, import), symoro::trajectory, symoro::preprocess,
# symoro::control, symoro::parallel (the task farm, MPI or threads), symoro::twin, symoro::report
# (SVG figures, Markdown tables), symoro::identify (the identification model; OLS, audit, SDP,
# CLIE), symoro::excitation, symoro::study (the study, its acceptance, validation and report),
# symoro::model_export (URDF), symoro::diagnose, symoro::dynamixel, symoro::hardware, symoro::twin_bus (the twin behind the
# virtual bus), and symoro::runtime (all of them). docs/architecture.md draws them.
include(CMakePackageConfigHelpers)

install(TARGETS symoro_core EXPORT symoroTargets)
set(_symoro_exported symoro_runtime)
foreach(area IN LISTS SYMORO_RUNTIME_AREAS)
  list(APPEND _symoro_exported symoro_${area})
  set_target_properties(symoro_${area} PROPERTIES EXPORT_NAME ${area})
endforeach()
set_target_properties(symoro_runtime PROPERTIES EXPORT_NAME runtime)
install(TARGETS ${_symoro_exported} EXPORT symoroTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY "${PROJECT_SOURCE_DIR}/runtime/include/" DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT symoroTargets
  NAMESPACE symoro::
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/symoro)

configure_package_config_file(
  "${PROJECT_SOURCE_DIR}/cmake/symoroConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/symoroConfig.cmake"
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/symoro)
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/symoroConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES
  "${PROJECT_BINARY_DIR}/symoroConfig.cmake"
  "${PROJECT_BINARY_DIR}/symoroConfigVersion.cmake"
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/symoro)

# symoro_installable: every target `cmake --install` copies, so that a build of only what the
# README's main command runs can be installed (tools/run_main.sh builds it; a fresh clone's install
# once failed on the Python module, which no built target had made).
add_custom_target(symoro_installable)
set(_installable symoroc dynid ${_symoro_exported})
foreach(robot IN LISTS SYMORO_ROBOTS)
  list(APPEND _installable symoro_${robot}_identification symoro_${robot}_diagnosis)
endforeach()
if(TARGET symoro_python)
  list(APPEND _installable symoro_python)  # the module and the package's staged .py files
endif()
foreach(t IN LISTS _installable)
  if(TARGET ${t})
    get_target_property(_type ${t} TYPE)
    if(NOT _type STREQUAL "INTERFACE_LIBRARY")  # (a custom target is UTILITY)
      add_dependencies(symoro_installable ${t})
    endif()
  endif()
endforeach()
