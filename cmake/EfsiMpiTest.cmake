# efsi_add_mpi_test(<name> <target> RANKS n1 n2 ... [ARGS ...] [TIMEOUT s] [THREADS t])
# Registers one CTest test per rank count, run through mpiexec.  More ranks than
# cores are oversubscribed, and Open MPI is allowed to run as root (CI runs as root).
function(efsi_add_mpi_test name target)
  cmake_parse_arguments(T "" "TIMEOUT;THREADS" "RANKS;ARGS" ${ARGN})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  set(suffix "")
  if(NOT T_THREADS)
    set(T_THREADS 1)
  else()
    set(suffix "_omp${T_THREADS}")
  endif()
  foreach(np IN LISTS T_RANKS)
    set(test_name ${name}_np${np}${suffix})
    # Open MPI 4.1 creates its session directory (TMPDIR/ompi.HOST.UID) without tolerating a
    # concurrent mkdir, so two tests launched at the same moment can fail with "File exists":
    # each test gets a base directory of its own.
    set(session ${CMAKE_BINARY_DIR}/ompi-sessions/${test_name})
    file(MAKE_DIRECTORY ${session})
    add_test(NAME ${test_name}
      COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} --oversubscribe
              ${MPIEXEC_PREFLAGS} $<TARGET_FILE:${target}> ${MPIEXEC_POSTFLAGS} ${T_ARGS})
    set_tests_properties(${test_name} PROPERTIES
      TIMEOUT ${T_TIMEOUT}
      PROCESSORS ${np}
      LABELS "mpi"
      ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1;OMPI_MCA_btl_vader_single_copy_mechanism=none;OMP_NUM_THREADS=${T_THREADS};ASAN_OPTIONS=detect_leaks=0;OMPI_MCA_orte_tmpdir_base=${session}")
  endforeach()
endfunction()
