# The dependencies and the core library (every stage of the pipeline, src/), shared by
# the main build and the libFuzzer build (fuzz/CMakeLists.txt). Expects DIVERSE_ROOT (the
# repository root) and DIVERSE_VERSION_STRING.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
# Debian's mujocoConfig.cmake names include directories that no package installs
# (libqhull_r), so the library is located directly instead of through its config.
find_path(MUJOCO_INCLUDE_DIR mujoco/mujoco.h REQUIRED)
find_library(MUJOCO_LIBRARY mujoco REQUIRED)
add_library(diverse_mujoco INTERFACE)
target_include_directories(diverse_mujoco SYSTEM INTERFACE ${MUJOCO_INCLUDE_DIR})
target_link_libraries(diverse_mujoco INTERFACE ${MUJOCO_LIBRARY})
set_target_properties(diverse_mujoco PROPERTIES EXPORT_NAME mujoco)
find_package(tomlplusplus REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)
find_package(PNG REQUIRED)
# glTF export (src/io/gltf.h): Debian's tinygltf, shipped as a shared library.
find_package(TinyGLTF REQUIRED)
# Offscreen rendering (src/render/) uses Mesa's OSMesa; see docs/guide/rendering.md.
find_path(OSMESA_INCLUDE_DIR GL/osmesa.h REQUIRED)
find_library(OSMESA_LIBRARY OSMesa REQUIRED)

set(DIVERSE_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  # GCC 12 reports std::string concatenation as overlapping memcpy (GCC bug 105329).
  list(APPEND DIVERSE_WARNINGS -Wno-restrict)
endif()

# The core library: every stage of the pipeline, one folder each under src/.
# A build may name the folders it needs (DIVERSE_CORE_FOLDERS, e.g. the fuzz build) and extra
# single files (DIVERSE_CORE_EXTRA); by default the library holds every folder.
if(DEFINED DIVERSE_CORE_FOLDERS)
  set(DIVERSE_SOURCES ${DIVERSE_CORE_EXTRA})
  foreach(folder ${DIVERSE_CORE_FOLDERS})
    file(GLOB folder_sources CONFIGURE_DEPENDS ${DIVERSE_ROOT}/src/${folder}/*.cc)
    list(APPEND DIVERSE_SOURCES ${folder_sources})
  endforeach()
else()
  file(GLOB_RECURSE DIVERSE_SOURCES CONFIGURE_DEPENDS ${DIVERSE_ROOT}/src/*.cc)
endif()
# MPI (src/distribute/): optional. Found, `mpirun -n R diverse run ...` spreads a run over
# R processes; not found, the build has cluster_none.cc, which says so when mpirun starts it.
option(DIVERSE_MPI "Build MPI support when an MPI library is found" ON)
if(DIVERSE_MPI)
  find_package(MPI COMPONENTS CXX QUIET)
endif()
set(DIVERSE_HAS_MPI OFF)
if(MPI_CXX_FOUND)
  set(DIVERSE_HAS_MPI ON)
endif()
if(DIVERSE_HAS_MPI)
  list(FILTER DIVERSE_SOURCES EXCLUDE REGEX "/distribute/cluster_none\\.cc$")
  message(STATUS "diverse: MPI found (${MPI_CXX_LIBRARIES}): `mpirun -n R diverse run` enabled")
else()
  list(FILTER DIVERSE_SOURCES EXCLUDE REGEX "/distribute/cluster_mpi\\.cc$")
  message(STATUS "diverse: no MPI (DIVERSE_MPI is OFF or no MPI library was found): runs use one "
                 "process; `mpirun -n R diverse run` needs libopenmpi-dev (scripts/setup.sh)")
endif()
add_library(diverse_core STATIC ${DIVERSE_SOURCES})
add_library(diverse::core ALIAS diverse_core)
set_target_properties(diverse_core PROPERTIES EXPORT_NAME core POSITION_INDEPENDENT_CODE ON)
# Installed, the headers keep their folders under include/diverse (#include "optimize/cmaes.h").
target_include_directories(diverse_core PUBLIC
  $<BUILD_INTERFACE:${DIVERSE_ROOT}/src> $<INSTALL_INTERFACE:include/diverse>)
target_compile_options(diverse_core PRIVATE ${DIVERSE_WARNINGS})
target_compile_definitions(diverse_core PRIVATE DIVERSE_VERSION="${DIVERSE_VERSION_STRING}")
# The source tree's path, for the two library files that look there (the built-in tasks, the
# gallery page's sources) and for tests, benchmarks and fuzz targets (diverse_source_dir). Only
# where it is read, so that the rest of the library compiles the same from any checkout.
set_property(SOURCE ${DIVERSE_ROOT}/src/task/task.cc ${DIVERSE_ROOT}/src/render/gallery.cc
  APPEND PROPERTY COMPILE_DEFINITIONS DIVERSE_SOURCE_DIR="${DIVERSE_ROOT}")
add_library(diverse_source_dir INTERFACE)
target_compile_definitions(diverse_source_dir INTERFACE DIVERSE_SOURCE_DIR="${DIVERSE_ROOT}")
target_link_libraries(diverse_core PUBLIC
  Eigen3::Eigen diverse_mujoco tomlplusplus::tomlplusplus
  nlohmann_json::nlohmann_json Threads::Threads PNG::PNG ${OSMESA_LIBRARY})
target_include_directories(diverse_core SYSTEM PRIVATE ${OSMESA_INCLUDE_DIR})
# Nearly every stage includes Eigen, nlohmann-json and MuJoCo: compiled once, not once per
# source file. The libFuzzer build leaves them out (DIVERSE_PRECOMPILE_HEADERS OFF), so
# each file's own includes are still checked there.
if(DIVERSE_PRECOMPILE_HEADERS)
  target_precompile_headers(diverse_core PRIVATE
    <Eigen/Dense> <nlohmann/json.hpp> <mujoco/mujoco.h> <algorithm> <memory> <string> <vector>)
endif()
target_link_libraries(diverse_core PRIVATE TinyGLTF::TinyGLTF)
if(DIVERSE_HAS_MPI)
  target_link_libraries(diverse_core PRIVATE MPI::MPI_CXX)
endif()
