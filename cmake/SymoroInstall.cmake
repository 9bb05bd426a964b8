# Installs symoro as a CMake package: find_package(symoro) gives symoro::core and one
# symoro::<robot> target per generated robot, header-only over Eigen.
include(CMakePackageConfigHelpers)

install(TARGETS symoro_core EXPORT symoroTargets)
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
