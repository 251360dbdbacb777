# Work units over MPI ranks (docs/scale-out.md). Included by tests/cli/CMakeLists.txt.
#  - cli.mpi.same_bytes.<case>: the same command without mpirun and under mpirun -n 1, 2, 3
#    writes the same files, byte for byte (timings, "ranks", "threads" aside): mpi_compare.cmake.
#  - cli.mpi.resume: a sweep killed midway (SIGKILL after 5 recorded units), then --resume,
#    gives the bytes of an uninterrupted run: mpi_resume.cmake; cli.mpi.resume.corpus the same for
#    the quick corpus (killed after 1 of its 2 cases).
#  - cli.mpi.failing_rank: a unit that throws on rank 1 stops the run with one line naming it;
#    cli.mpi.failing_rank.corpus for a corpus case.
# Tiny runs: the machine has 2 cores and several ranks oversubscribe them. CI runs as root, which
# Open MPI refuses without --allow-run-as-root. RUN_SERIAL: two mpirun jobs at once on 2 cores
# made a launch fail under load.
set(_mpi_launcher "")
if(WEFT_MPI AND MPIEXEC_EXECUTABLE)
  set(_mpi_launcher ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG})
  execute_process(COMMAND ${MPIEXEC_EXECUTABLE} --version OUTPUT_VARIABLE _mpi_version ERROR_QUIET)
  if(_mpi_version MATCHES "Open MPI|OpenRTE")
    # --quiet: no "Primary job terminated normally…" banner around weft's own error line.
    set(_mpi_flags "--allow-run-as-root;--oversubscribe;--quiet")
  else()
    set(_mpi_flags "")
  endif()
  foreach(case sim2d sweep render corpus gen)
    add_test(NAME cli.mpi.same_bytes.${case}
             COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=${case} "-DMPIEXEC=${MPIEXEC_EXECUTABLE}"
                     "-DMPIFLAGS=${_mpi_flags}" -DWORK=${CMAKE_CURRENT_BINARY_DIR}/mpi_${case}
                     -P ${CMAKE_CURRENT_SOURCE_DIR}/mpi_compare.cmake)
    set_tests_properties(cli.mpi.same_bytes.${case} PROPERTIES LABELS "cli;mpi" TIMEOUT 300 RUN_SERIAL TRUE)
  endforeach()
endif()
add_test(NAME cli.mpi.resume
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> "-DMPIEXEC=${MPIEXEC_EXECUTABLE}" "-DMPIFLAGS=${_mpi_flags}"
                 -DWEFT_MPI=${WEFT_MPI} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/mpi_resume -DMODE=resume
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/mpi_resume.cmake)
set_tests_properties(cli.mpi.resume PROPERTIES LABELS "cli;mpi" TIMEOUT 300 RUN_SERIAL TRUE)
add_test(NAME cli.mpi.failing_rank
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> "-DMPIEXEC=${MPIEXEC_EXECUTABLE}" "-DMPIFLAGS=${_mpi_flags}"
                 -DWEFT_MPI=${WEFT_MPI} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/mpi_failing -DMODE=failing
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/mpi_resume.cmake)
set_tests_properties(cli.mpi.failing_rank PROPERTIES LABELS "cli;mpi" TIMEOUT 120)
add_test(NAME cli.mpi.resume.corpus
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> "-DMPIEXEC=${MPIEXEC_EXECUTABLE}" "-DMPIFLAGS=${_mpi_flags}"
                 -DWEFT_MPI=${WEFT_MPI} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/mpi_resume_corpus -DMODE=resume_corpus
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/mpi_resume.cmake)
set_tests_properties(cli.mpi.resume.corpus PROPERTIES LABELS "cli;mpi" TIMEOUT 300 RUN_SERIAL TRUE)
add_test(NAME cli.mpi.failing_rank.corpus
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> "-DMPIEXEC=${MPIEXEC_EXECUTABLE}" "-DMPIFLAGS=${_mpi_flags}"
                 -DWEFT_MPI=${WEFT_MPI} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/mpi_failing_corpus -DMODE=failing_corpus
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/mpi_resume.cmake)
set_tests_properties(cli.mpi.failing_rank.corpus PROPERTIES LABELS "cli;mpi" TIMEOUT 120 RUN_SERIAL TRUE)
