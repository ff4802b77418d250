# SPDX-License-Identifier: GPL-3.0-or-later
# ultratrack_layer(NAME DEPS...) builds the static library ultratrack_<NAME> from every .cpp in the
# layer's folder. Headers are included as "<layer>/<file>.hpp". Each layer gets a private include root
# in the build tree that holds only a link to its own folder, so a layer can include exactly the layers
# it links: the dependency rule is enforced by the compiler, not by discipline. Installed, the headers are
# include/ultratrack/<layer>/*.hpp under one include root, and the library is Ultratrack::<layer> of the
# exported package (every layer is listed in the global property ULTRATRACK_LAYERS, which
# cmake/UltratrackInstall.cmake installs). With ULTRATRACK_LAYERS_PIC the libraries are position-independent (the
# Python module links them).
function(ultratrack_layer name)
  cmake_parse_arguments(ARG "" "" "DEPS;EXTERNAL" ${ARGN})
  set(include_root "${CMAKE_BINARY_DIR}/layer_include/${name}")
  file(MAKE_DIRECTORY "${include_root}")
  if(NOT EXISTS "${include_root}/${name}")
    file(CREATE_LINK "${CMAKE_CURRENT_SOURCE_DIR}" "${include_root}/${name}" SYMBOLIC)
  endif()
  file(GLOB sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.cpp")
  file(GLOB headers CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.hpp")
  set(include_dirs "$<BUILD_INTERFACE:${include_root}>" "$<INSTALL_INTERFACE:include/ultratrack>")
  if(sources)
    add_library(ultratrack_${name} STATIC ${sources} ${headers})
    target_include_directories(ultratrack_${name} PUBLIC ${include_dirs})
    target_compile_options(ultratrack_${name} PRIVATE -Wall -Wextra -Wpedantic)
    target_link_libraries(ultratrack_${name} PUBLIC ${ARG_DEPS} ${ARG_EXTERNAL})
  else()  # a layer that has only headers so far
    add_library(ultratrack_${name} INTERFACE)
    target_include_directories(ultratrack_${name} INTERFACE ${include_dirs})
    target_link_libraries(ultratrack_${name} INTERFACE ${ARG_DEPS} ${ARG_EXTERNAL})
  endif()
  set_target_properties(ultratrack_${name} PROPERTIES EXPORT_NAME ${name})
  if(ULTRATRACK_LAYERS_PIC AND sources)  # linked into the Python extension module (python/)
    set_target_properties(ultratrack_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()
  add_library(ultratrack::${name} ALIAS ultratrack_${name})
  set_property(GLOBAL APPEND PROPERTY ULTRATRACK_LAYERS ${name})
  set_property(GLOBAL PROPERTY ULTRATRACK_LAYER_HEADERS_${name} "${headers}")
endfunction()

# ultratrack_test(NAME SOURCES... LIBS...) one GoogleTest executable per test folder.
function(ultratrack_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE -Wall -Wextra)
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main ultratrack_test_support)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
