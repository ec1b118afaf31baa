# Finds every dependency; each failure names the Debian package that provides it
# (scripts/setup.sh installs them all).

macro(qsmesh_require found what package)
  if(NOT ${found})
    message(FATAL_ERROR "qsmesh: ${what} not found. Install the Debian package '${package}' "
                        "(or run scripts/setup.sh, which installs every dependency).")
  endif()
endmacro()

find_package(PkgConfig QUIET)
qsmesh_require(PkgConfig_FOUND "pkg-config" "pkg-config")

# OpenCASCADE 7.6
# (OpenCASCADE's version file accepts exact versions only, so the minimum is checked here.)
find_package(OpenCASCADE QUIET)
if(OpenCASCADE_FOUND AND OpenCASCADE_VERSION VERSION_LESS 7.6)
  set(OpenCASCADE_FOUND FALSE)
endif()
qsmesh_require(OpenCASCADE_FOUND "OpenCASCADE >= 7.6" "libocct-data-exchange-dev")
add_library(qsmesh_occt INTERFACE)
target_include_directories(qsmesh_occt SYSTEM INTERFACE ${OpenCASCADE_INCLUDE_DIR})
target_link_libraries(qsmesh_occt INTERFACE
  TKernel TKMath TKG2d TKG3d TKGeomBase TKBRep TKGeomAlgo TKTopAlgo TKPrim TKBO TKBool
  TKShHealing TKOffset TKFillet TKMesh TKSTEP TKSTEPBase TKSTEPAttr TKSTEP209 TKIGES TKXSBase)

# MPI
find_package(MPI QUIET COMPONENTS C)
qsmesh_require(MPI_C_FOUND "MPI (C bindings)" "libopenmpi-dev")
# The C API only: OpenMPI's and MPICH's mpi.h otherwise pull in the deprecated C++ bindings.
add_library(qsmesh_mpi INTERFACE)
target_link_libraries(qsmesh_mpi INTERFACE MPI::MPI_C)
target_compile_definitions(qsmesh_mpi INTERFACE OMPI_SKIP_MPICXX=1 MPICH_SKIP_MPICXX=1)

# TBB
find_package(TBB QUIET CONFIG)
qsmesh_require(TBB_FOUND "oneTBB" "libtbb-dev")

# Eigen
find_package(Eigen3 3.3 QUIET NO_MODULE)
qsmesh_require(Eigen3_FOUND "Eigen3" "libeigen3-dev")

# PETSc (with MUMPS), through pkg-config
pkg_check_modules(PETSC QUIET IMPORTED_TARGET petsc)
qsmesh_require(PETSC_FOUND "PETSc" "petsc-dev")
find_library(MUMPS_D_LIBRARY dmumps)
qsmesh_require(MUMPS_D_LIBRARY "MUMPS" "libmumps-dev")

# qsmesh_find_plain(TARGET HEADER LIBRARY WHAT PACKAGE): a library without CMake or pkg-config
# files, found by header and library name, as the interface target TARGET.
function(qsmesh_find_plain target header library what package)
  find_path(${target}_INCLUDE_DIR ${header})
  find_library(${target}_LIBRARY ${library})
  if(${target}_INCLUDE_DIR AND ${target}_LIBRARY)
    set(found TRUE)
  endif()
  qsmesh_require(found "${what}" "${package}")
  add_library(${target} INTERFACE)
  target_include_directories(${target} SYSTEM INTERFACE ${${target}_INCLUDE_DIR})
  target_link_libraries(${target} INTERFACE ${${target}_LIBRARY})
endfunction()

# METIS
qsmesh_find_plain(qsmesh_metis metis.h metis "METIS" "libmetis-dev")

# nauty (canonical labelling), used only by the build-time generator of the disk-quadrangulation
# table (src/remesh/tools); its header sits in a multiarch folder, hence the nauty/ prefix.
qsmesh_find_plain(qsmesh_nauty nauty/nauty.h nauty "nauty" "libnauty2-dev")

# COIN-OR CBC (its C interface), the integer program solver of the coarse block layout
# (src/layout/ilp_cbc.cpp; docs/architecture.md says why CBC)
qsmesh_find_plain(qsmesh_cbc coin/Cbc_C_Interface.h CbcSolver "COIN-OR CBC" "coinor-libcbc-dev")

# HDF5 (serial: Debian's libcgns is built against it)
pkg_check_modules(HDF5S QUIET IMPORTED_TARGET hdf5-serial)
qsmesh_require(HDF5S_FOUND "HDF5 (serial)" "libhdf5-dev")

# CGNS: Debian ships neither CMake nor pkg-config files for it
qsmesh_find_plain(qsmesh_cgns cgnslib.h cgns "CGNS" "libcgns-dev")
target_link_libraries(qsmesh_cgns INTERFACE PkgConfig::HDF5S)

find_program(CGNSCHECK_EXECUTABLE cgnscheck)
if(NOT CGNSCHECK_EXECUTABLE)
  message(WARNING "qsmesh: cgnscheck not found (Debian package 'cgns-convert'); CGNS validation tests are skipped.")
endif()

# GoogleTest
if(QSMESH_BUILD_TESTS)
  find_package(GTest QUIET)
  qsmesh_require(GTest_FOUND "GoogleTest" "libgtest-dev")
  find_program(MPIEXEC_EXECUTABLE_FOUND NAMES mpiexec)
endif()
