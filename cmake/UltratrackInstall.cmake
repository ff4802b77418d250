# SPDX-License-Identifier: GPL-3.0-or-later
# `cmake --install`: every layer library registered by ultratrack_layer() (global property ULTRATRACK_LAYERS)
# with its headers as include/ultratrack/<layer>/*.hpp, exported as the package Ultratrack: find_package(Ultratrack)
# gives Ultratrack::io, Ultratrack::signals, ... (one target per layer, linking the layers it needs), and finds the
# external dependencies again (cmake/UltratrackConfig.cmake.in). Include this after every layer's add_subdirectory.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ULTRATRACK_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/Ultratrack")
get_property(ultratrack_layers GLOBAL PROPERTY ULTRATRACK_LAYERS)
foreach(layer IN LISTS ultratrack_layers)
  install(TARGETS ultratrack_${layer} EXPORT UltratrackTargets
    ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
    LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
  get_property(layer_headers GLOBAL PROPERTY ULTRATRACK_LAYER_HEADERS_${layer})
  install(FILES ${layer_headers} DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/ultratrack/${layer}")
endforeach()

install(EXPORT UltratrackTargets NAMESPACE Ultratrack:: DESTINATION "${ULTRATRACK_INSTALL_CMAKEDIR}")
configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/UltratrackConfig.cmake.in"
  "${CMAKE_CURRENT_BINARY_DIR}/UltratrackConfig.cmake" INSTALL_DESTINATION "${ULTRATRACK_INSTALL_CMAKEDIR}")
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/UltratrackConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/UltratrackConfig.cmake"
  "${CMAKE_CURRENT_BINARY_DIR}/UltratrackConfigVersion.cmake" DESTINATION "${ULTRATRACK_INSTALL_CMAKEDIR}")
