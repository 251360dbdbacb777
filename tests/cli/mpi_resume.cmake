# Nothing lost on failure (issue 16).
#  MODE=resume: a sweep killed midway (WEFT_TEST_KILL_AFTER_UNITS=5: rank 0 SIGKILLs itself once
#    it has recorded 5 units, as a crash or a cluster's time limit would) leaves its finished units
#    in OUT/units/ and no outputs; `--resume` (with another number of ranks) computes only the
#    rest and writes the bytes of an uninterrupted run.
#  MODE=failing: WEFT_TEST_FAIL_UNIT=1 makes sim2d's realization 1 throw (on rank 1 of 2 under
#    mpirun): the run stops with exit code 1 and one `weft: error:` line naming the unit, writes
#    no report, and does not hang (the test's timeout).
# Without MPI the same runs go without mpirun.
# Usage: cmake -DWEFT=<weft> -DMPIEXEC=<mpirun> -DMPIFLAGS=<flags> -DWEFT_MPI=ON|OFF -DWORK=<dir>
#              -DMODE=resume|failing -P mpi_resume.cmake
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/mpi_common.cmake)

# launch(<ranks> <result var> <stderr var> args...): weft under mpirun -n <ranks> (plain if no MPI).
function(launch ranks rc_var err_var)
  if(WEFT_MPI AND MPIEXEC)
    set(cmd "${MPIEXEC}" ${MPIFLAGS} -n ${ranks} "${WEFT}" --quiet --threads 1 ${ARGN})
  else()
    set(cmd "${WEFT}" --quiet --threads 1 ${ARGN})
  endif()
  execute_process(COMMAND ${cmd} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${rc_var} "${rc}" PARENT_SCOPE)
  set(${err_var} "${err}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/in")
if(MODE STREQUAL "resume")
  file(WRITE "${WORK}/in/cloth.json"
       "{\"pattern\": \"plain\", \"warp_count\": 2, \"weft_count\": 2, \"voxel_size\": 0.02}\n")
  set(common validate --sweep --quick --no-plot --axes x,y,z --cloth "${WORK}/in/cloth.json")
  set(args ${common} --seed 4)
  # 4 factor units + 3 axes x 3 ray strides = 13 units.
  launch(1 rc err ${args} --out "${WORK}/whole")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "uninterrupted sweep failed (${rc}): ${err}")
  endif()
  if(EXISTS "${WORK}/whole/units")
    message(FATAL_ERROR "a finished run left its units folder")
  endif()

  set(ENV{WEFT_TEST_KILL_AFTER_UNITS} 5)
  launch(2 rc err ${args} --out "${WORK}/resumed")
  unset(ENV{WEFT_TEST_KILL_AFTER_UNITS})
  if(rc EQUAL 0)
    message(FATAL_ERROR "the run to be killed finished (${rc})")
  endif()
  if(EXISTS "${WORK}/resumed/accuracy_time.csv" OR EXISTS "${WORK}/resumed/sweep.json")
    message(FATAL_ERROR "the killed run wrote its outputs")
  endif()
  file(GLOB units "${WORK}/resumed/units/unit-*.bin")
  list(LENGTH units n_units)
  if(n_units LESS 5 OR n_units GREATER 12)
    message(FATAL_ERROR "the killed run recorded ${n_units} units; expected 5 to 12 of 13 (exit ${rc}: ${err})")
  endif()
  # Leftovers of an interrupted write (.unit-*.tmp*) are allowed; a half-written unit is not.
  file(GLOB partial "${WORK}/resumed/units/unit-*.tmp*")
  if(partial)
    message(FATAL_ERROR "partial unit files: ${partial}")
  endif()

  # Another run's units are refused.
  launch(1 rc err ${common} --seed 5 --resume --out "${WORK}/resumed")
  if(rc EQUAL 0 OR NOT err MATCHES "weft: error: [^\n]*--resume[^\n]*different run")
    message(FATAL_ERROR "--resume with other options: expected a refusal, got ${rc}: ${err}")
  endif()

  launch(3 rc err ${args} --resume --out "${WORK}/resumed")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--resume failed (${rc}): ${err}")
  endif()
  file(READ "${WORK}/resumed/sweep.json" report)
  string(JSON resumed GET "${report}" resumed_units)
  if(NOT resumed EQUAL n_units)
    message(FATAL_ERROR "--resume reports ${resumed} resumed units, the killed run left ${n_units}")
  endif()
  compare_folders("${WORK}/whole" "${WORK}/resumed" differ)
  if(differ)
    message(FATAL_ERROR "killed + resumed differs from the uninterrupted run in: ${differ}")
  endif()
  message(STATUS "killed after ${n_units} of 13 units, resumed on 3 ranks: same bytes as an uninterrupted run")
elseif(MODE STREQUAL "failing")
  set(ENV{WEFT_TEST_FAIL_UNIT} 1)
  launch(2 rc err sim2d --quick --no-plot --eta 0.5 --radius 4e-4 --mfp 0.1 --realizations 4 --samples 100 --out "${WORK}/run")
  unset(ENV{WEFT_TEST_FAIL_UNIT})
  if(NOT rc EQUAL 1)
    message(FATAL_ERROR "a failing unit: exit code ${rc}, expected 1; stderr: ${err}")
  endif()
  string(REGEX MATCHALL "weft: error:[^\n]*" lines "${err}")
  list(LENGTH lines n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "expected one error line, got ${n}: ${err}")
  endif()
  set(rank_note "")
  if(WEFT_MPI AND MPIEXEC)
    set(rank_note " on rank 1")
  endif()
  if(NOT lines MATCHES "^weft: error: sim2d realization 1 of eta 0.5 failed${rank_note}: failed on purpose")
    message(FATAL_ERROR "the error line does not name the unit: ${lines}")
  endif()
  if(EXISTS "${WORK}/run/report.json")
    message(FATAL_ERROR "a failed run wrote report.json")
  endif()
  message(STATUS "one line: ${lines}")
else()
  message(FATAL_ERROR "unknown MODE '${MODE}'")
endif()
