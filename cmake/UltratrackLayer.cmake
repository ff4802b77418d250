# SPDX-License-Identifier: GPL-3.0-or-later
# ultratrack_layer(NAME DEPS...) builds the static library ultratrack_<NAME> from every .cpp in the
# layer's folder. Headers are included as "<layer>/<file>.hpp". Each layer gets a private include root
# in the build tree that holds only a link to its own folder, so a layer can include exactly the layers
# it links: the dependency rule is enforced by the compiler, not by discipline. Installed, the headers are
# include/ultratrack/<layer>/*.hpp under one include root, and the library is Ultratrack::<layer> of the
# exported package (every layer is listed in the global property ULTRATRACK_LAYERS, which
# cmake/UltratrackInstall.cmake installs). With ULTRATRACK_LAYERS_PIC the libraries are position-independent (the
# Python module links them).
# ultratrack_precompile(TARGET GROUP [EIGEN] [FMT] [GTEST] [CLI] [TOML] [HEADERS h...]) precompiles the standard and third-party
# headers that the target's sources include (never the project's own headers, which change while one works):
# parsing them is most of a source's compile time (Eigen, GoogleTest and CLI11 take 1.5-3 s each per file), so a
# cold build, which is what CI pays, takes much less. Targets of one GROUP have the same flags and share the first
# one's precompiled header (building one costs ~6 s). The build is the same with ULTRATRACK_PRECOMPILE_HEADERS=OFF:
# every source still includes what it uses.
option(ULTRATRACK_PRECOMPILE_HEADERS "Precompile the system headers of each target (faster cold builds)" ON)
function(ultratrack_precompile target group)
  if(NOT ULTRATRACK_PRECOMPILE_HEADERS)
    return()
  endif()
  get_property(owner GLOBAL PROPERTY ULTRATRACK_PCH_OWNER_${group})
  if(owner)
    target_precompile_headers(${target} REUSE_FROM ${owner})
    return()
  endif()
  cmake_parse_arguments(ARG "EIGEN;FMT;GTEST;CLI;TOML" "" "HEADERS" ${ARGN})
  set(headers <algorithm> <array> <chrono> <cmath> <complex> <cstdint> <filesystem> <fstream> <functional> <map>
              <memory> <optional> <sstream> <stdexcept> <string> <string_view> <utility> <vector>)
  if(ARG_EIGEN)
    list(APPEND headers <Eigen/Dense> <Eigen/Geometry>)
  endif()
  if(ARG_FMT)
    list(APPEND headers <fmt/format.h>)
  endif()
  if(ARG_GTEST)
    list(APPEND headers <gtest/gtest.h>)
  endif()
  if(ARG_CLI)
    list(APPEND headers <CLI/CLI.hpp>)
  endif()
  if(ARG_TOML)
    list(APPEND headers <toml++/toml.h>)
  endif()
  target_precompile_headers(${target} PRIVATE ${headers} ${ARG_HEADERS})
  set_property(GLOBAL PROPERTY ULTRATRACK_PCH_OWNER_${group} ${target})
endfunction()

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
    if(ULTRATRACK_SANITIZE OR ULTRATRACK_FUZZ)
      # Instrumented code needs the sanitizer runtime wherever it is linked: exported with the target, so that a
      # program built against a sanitized install (examples/consumer in ctest install.consumer) links it too.
      target_link_options(ultratrack_${name} INTERFACE -fsanitize=address,undefined)
    endif()
    if(name STREQUAL "config")  # the only layer that reads TOML
      ultratrack_precompile(ultratrack_${name} config EIGEN FMT TOML)
    elseif(NOT name STREQUAL "io")  # io: five small files, nothing to gain
      ultratrack_precompile(ultratrack_${name} layers EIGEN FMT)
    endif()
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

# ultratrack_test(NAME SOURCES... LIBS...) one GoogleTest executable per test folder. Its own sources compile at -O1
# (the layers they test keep the build type's flags): the tests spend their time in the layers' code, so at -O1 no
# test ran more than 0.2 s longer (the filter Monte Carlos included), and the tests' share of a cold build fell by a
# third (304 against 444 CPU-s). Without -march and
# -ffast-math the optimisation level does not change a floating-point result.
function(ultratrack_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE -Wall -Wextra -O1)
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main ultratrack_test_support)
  ultratrack_precompile(${name} tests EIGEN FMT GTEST)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
