# Every dependency comes from a Debian 12 package.  A missing one stops the
# configure step with the name of the package that provides it.

macro(efsi_require found_var what debian_pkg)
  if(NOT ${found_var})
    message(FATAL_ERROR
      "${what} not found: install it with 'apt-get install ${debian_pkg}' "
      "(or run ci/install-deps.sh)")
  endif()
endmacro()

if(EFSI_SIMGRID)
  # smpicxx puts SMPI's mpi.h and library on every compile and link line itself.
  get_filename_component(_efsi_cxx ${CMAKE_CXX_COMPILER} NAME)
  if(NOT _efsi_cxx STREQUAL "smpicxx")
    message(FATAL_ERROR "EFSI_SIMGRID needs SimGrid's compiler wrappers: configure with the simgrid preset "
                        "(CMAKE_CXX_COMPILER=smpicxx, from 'apt-get install libsimgrid-dev'); got ${CMAKE_CXX_COMPILER}")
  endif()
  add_library(MPI::MPI_C INTERFACE IMPORTED)
  add_library(MPI::MPI_CXX INTERFACE IMPORTED)
  find_program(MPIEXEC_EXECUTABLE smpirun)
  efsi_require(MPIEXEC_EXECUTABLE "smpirun" "libsimgrid-dev")
else()
  find_package(MPI COMPONENTS C CXX)
  efsi_require(MPI_CXX_FOUND "MPI (C++ bindings)" "libopenmpi-dev openmpi-bin")
endif()

find_package(OpenMP COMPONENTS CXX)
efsi_require(OpenMP_CXX_FOUND "OpenMP" "libgomp1 (part of g++)")

find_package(PkgConfig)
efsi_require(PKG_CONFIG_FOUND "pkg-config" "pkg-config")
pkg_check_modules(FFTW3 IMPORTED_TARGET fftw3)
efsi_require(FFTW3_FOUND "FFTW3 (double precision)" "libfftw3-dev")
# FFTW's OpenMP-threaded library has no .pc file of its own; it sits beside libfftw3.
find_library(FFTW3_OMP_LIBRARY NAMES fftw3_omp HINTS ${FFTW3_LIBRARY_DIRS})
efsi_require(FFTW3_OMP_LIBRARY "FFTW3 OpenMP library (libfftw3_omp)" "libfftw3-dev")
add_library(efsi_fftw INTERFACE)
target_link_libraries(efsi_fftw INTERFACE ${FFTW3_OMP_LIBRARY} PkgConfig::FFTW3 OpenMP::OpenMP_CXX)

find_package(CLI11 CONFIG)
efsi_require(CLI11_FOUND "CLI11" "libcli11-dev")

if(EFSI_BUILD_TESTS)
  find_package(GTest CONFIG)
  efsi_require(GTest_FOUND "GoogleTest" "libgtest-dev googletest")
endif()

if(EFSI_BUILD_BENCHMARKS)
  find_package(benchmark CONFIG)
  efsi_require(benchmark_FOUND "Google Benchmark" "libbenchmark-dev")
endif()

if(EFSI_SIMGRID)
  message(STATUS "Simulation build (SMPI): hypre (the mg method) and parallel HDF5 (checkpoints, snapshots, "
                 "restarts) are left out: Debian builds both on Open MPI")
  return()
endif()

# hypre (the multigrid pressure method, kernels/pressure/mg): Debian's build on Open MPI,
# 32-bit indices, no OpenMP of its own.
find_path(HYPRE_INCLUDE_DIR HYPRE_struct_ls.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY NAMES HYPRE)
efsi_require(HYPRE_INCLUDE_DIR "hypre headers (HYPRE_struct_ls.h)" "libhypre-dev")
efsi_require(HYPRE_LIBRARY "hypre library (libHYPRE)" "libhypre-dev")
add_library(efsi_hypre INTERFACE)
target_include_directories(efsi_hypre SYSTEM INTERFACE ${HYPRE_INCLUDE_DIR})
target_link_libraries(efsi_hypre INTERFACE ${HYPRE_LIBRARY} MPI::MPI_C)

# Parallel HDF5 (snapshots and checkpoints, kernels/io): Debian's Open MPI build, found
# through its h5pcc wrapper.  A serial HDF5 would compile but could not write collectively.
set(HDF5_PREFER_PARALLEL TRUE)
find_package(HDF5 COMPONENTS C)
efsi_require(HDF5_FOUND "HDF5" "libhdf5-openmpi-dev")
if(NOT HDF5_IS_PARALLEL)
  message(FATAL_ERROR "HDF5 found is not the parallel build: install it with 'apt-get install libhdf5-openmpi-dev'")
endif()
add_library(efsi_hdf5 INTERFACE)
target_include_directories(efsi_hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS})
target_compile_definitions(efsi_hdf5 INTERFACE ${HDF5_C_DEFINITIONS})
target_link_libraries(efsi_hdf5 INTERFACE ${HDF5_C_LIBRARIES} MPI::MPI_C)
