# Same answer for any number of ranks (docs/scale-out.md): runs one `weft` command without mpirun
# (--threads 2) and under mpirun -n 1, 2, 3 (--threads 1), each into a fresh folder, then requires
# the same files with the same bytes. JSON reports are compared without timing entries and
# without "ranks", "threads" and "resumed_units"; the sweep's CSV without its timing columns and
# the Pareto flag (which is decided by the timings).
#
# The corpus case also runs without mpirun on one thread (t1): cases then run one after the
# other instead of side by side.
#
# With -DREFERENCE=<dir> (scripts/check_mpich: another build's WORK of the same CASE, e.g. against
# another MPI library) the plain and -n 2 runs must also equal that folder's.
#
# Usage: cmake -DWEFT=<weft> -DCASE=sim2d|sweep|render|corpus|gen -DMPIEXEC=<mpirun> -DMPIFLAGS=<flags> -DWORK=<dir>
#              [-DREFERENCE=<dir>] -P mpi_compare.cmake
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/mpi_common.cmake)

file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/in")
if(CASE STREQUAL "sim2d")
  # 4 realizations of 12500 disks: 3 ranks get 2, 1 and 1 of them.
  set(run_args sim2d --quick --no-plot --eta 0.5 --radius 4e-4 --mfp 0.1 --realizations 4 --samples 100 --seed 5 --out "${WORK}/@RUN@")
elseif(CASE STREQUAL "sweep")
  file(WRITE "${WORK}/in/cloth.json"
       "{\"pattern\": \"plain\", \"warp_count\": 2, \"weft_count\": 2, \"voxel_size\": 0.02}\n")
  set(run_args validate --sweep --quick --no-plot --axes x,z --cloth "${WORK}/in/cloth.json" --seed 3
               --out "${WORK}/@RUN@")
elseif(CASE STREQUAL "corpus")
  # The quick corpus: 2 cases (plain and stockinette, cotton, 20 um), so -n 3 leaves a rank idle.
  set(run_args validate --corpus --quick --no-plot --seed 3 --out "${WORK}/@RUN@")
elseif(CASE STREQUAL "gen")
  # 3x3 yarns at 10 um: 2300 leaves, 9 units of 256 leaves over the ranks; .vdb without its UUID.
  set(run_args gen --yarns 3x3 --write grid,config,yarns --seed 2 --out "${WORK}/@RUN@")
elseif(CASE STREQUAL "render")
  # Media, surfaces and lights on a small film: tiles of 16² pixels over the ranks.
  set(run_args render cornell_media --quick --spp 2 --seed 7 -o "${WORK}/@RUN@/image.exr")
  foreach(run plain n1 n2 n3)
    file(MAKE_DIRECTORY "${WORK}/${run}")
  endforeach()
else()
  message(FATAL_ERROR "unknown CASE '${CASE}'")
endif()

set(runs plain n1 n2 n3)
if(CASE STREQUAL "corpus")
  list(APPEND runs t1)
endif()
foreach(run IN LISTS runs)
  string(REPLACE "@RUN@" "${run}" args "${run_args}")
  if(run STREQUAL "plain")
    set(cmd "${WEFT}" --quiet --threads 2 ${args})
  elseif(run STREQUAL "t1")
    set(cmd "${WEFT}" --quiet --threads 1 ${args})
  else()
    string(SUBSTRING "${run}" 1 -1 n)
    set(cmd "${MPIEXEC}" ${MPIFLAGS} -n ${n} "${WEFT}" --quiet --threads 1 ${args})
  endif()
  execute_process(COMMAND ${cmd} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${cmd} failed (${rc}): ${err}")
  endif()
endforeach()

set(others ${runs})
list(REMOVE_ITEM others plain)
foreach(run IN LISTS others)
  compare_folders("${WORK}/plain" "${WORK}/${run}" differ)
  if(differ)
    message(FATAL_ERROR "${CASE}: the plain run (2 threads) and run ${run} differ in: ${differ} (outputs kept in ${WORK})")
  endif()
endforeach()
if(REFERENCE)
  foreach(run plain n2)
    compare_folders("${REFERENCE}/${run}" "${WORK}/${run}" differ)
    if(differ)
      message(FATAL_ERROR "${CASE}: run ${run} differs from ${REFERENCE}/${run} in: ${differ}")
    endif()
  endforeach()
  message(STATUS "${CASE}: plain and -n 2 identical to ${REFERENCE}")
endif()
# The reports say how they were run (gen writes no report: its cloth.json and scene.json are inputs
# for other commands).
if(CASE STREQUAL "gen")
  set(report_runs "")
else()
  set(report_runs ${runs})
endif()
foreach(run IN LISTS report_runs)
  file(GLOB reports "${WORK}/${run}/*.json")
  foreach(r IN LISTS reports)
    file(READ "${r}" j)
    string(JSON ranks GET "${j}" ranks)
    string(JSON threads GET "${j}" threads)
    set(expect_ranks 1)
    set(expect_threads 1)
    if(run STREQUAL "plain")
      set(expect_threads 2)
    elseif(run STREQUAL "t1")
      set(expect_threads 1)
    else()
      string(SUBSTRING "${run}" 1 -1 expect_ranks)
    endif()
    if(NOT ranks EQUAL expect_ranks OR NOT threads EQUAL expect_threads)
      message(FATAL_ERROR "${r}: ranks ${ranks}, threads ${threads}; expected ${expect_ranks}, ${expect_threads}")
    endif()
  endforeach()
endforeach()
file(GLOB_RECURSE files RELATIVE "${WORK}/plain" "${WORK}/plain/*")
message(STATUS "${CASE}: identical for runs ${runs} (plain: no mpirun; nK: mpirun -n K; t1: one thread): ${files}")
