# `scripts/bench --quick` on the built tree: runs every benchmark executable once, the whole-run
# timings, the scaling study, the 1- vs 2-thread runs and their scaling model, and checks the markdown it writes. Included by
# tests/cli/CMakeLists.txt to declare the test; the same file runs in script mode (cmake -P) to
# drive the script and check its output.
if(CMAKE_SCRIPT_MODE_FILE AND MODE STREQUAL "update")
  # `scripts/bench --update --sections none` on a copy of docs/benchmarks.md measures nothing:
  # the generated part (up to "## Notes and analysis") stays byte for byte, and what follows is
  # docs/benchmarks.notes.md verbatim.
  file(REMOVE_RECURSE "${OUT}")
  file(MAKE_DIRECTORY "${OUT}")
  set(md "${OUT}/benchmarks.md")
  file(READ "${SOURCE_DIR}/docs/benchmarks.md" before)
  string(APPEND before "\n(a line the update must drop: it is after the notes heading)\n")
  file(WRITE "${md}" "${before}")
  execute_process(COMMAND bash "${SOURCE_DIR}/scripts/bench" --update --sections none --out "${md}"
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "scripts/bench --update --sections none failed (${rc}): ${err}")
  endif()
  file(READ "${md}" after)
  file(READ "${SOURCE_DIR}/docs/benchmarks.notes.md" notes)
  set(heading "\n## Notes and analysis\n")
  string(FIND "${before}" "${heading}" at_before)
  string(FIND "${after}" "${heading}" at_after)
  if(at_before EQUAL -1 OR NOT at_before EQUAL at_after)
    message(FATAL_ERROR "${md}: the notes heading moved (${at_before} -> ${at_after})")
  endif()
  string(SUBSTRING "${before}" 0 ${at_before} generated_before)
  string(SUBSTRING "${after}" 0 ${at_after} generated_after)
  if(NOT generated_before STREQUAL generated_after)
    message(FATAL_ERROR "${md}: --update --sections none changed the generated part")
  endif()
  string(SUBSTRING "${after}" ${at_after} -1 tail)
  if(NOT tail STREQUAL "${heading}\n${notes}")
    message(FATAL_ERROR "${md}: what follows the notes heading is not docs/benchmarks.notes.md")
  endif()
  return()
endif()
if(CMAKE_SCRIPT_MODE_FILE)
  file(REMOVE_RECURSE "${OUT}")
  file(MAKE_DIRECTORY "${OUT}")
  set(md "${OUT}/benchmarks.md")
  execute_process(COMMAND bash "${SOURCE_DIR}/scripts/bench" --quick --no-build --build-dir "${BUILD_DIR}" --out "${md}"
                          --keep "${OUT}/raw" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "scripts/bench --quick failed (${rc}): ${err}")
  endif()
  if(NOT EXISTS "${md}")
    message(FATAL_ERROR "scripts/bench --quick exited 0 but wrote no ${md}")
  endif()
  file(READ "${md}" text)
  set(needles
      "## Machine" "| CPU |" "| cores (online) |" "| memory |" "| load average" "| OS |" "| compiler |" "| commit |"
      "## Headline ratios" "## Micro-benchmarks (Google Benchmark)" "## Whole runs (`/usr/bin/time -v`)"
      "| validate |" "| sim2d --quick |" "## Scaling: `weft gen` + `weft validate` vs active voxels"
      "## Notes and analysis" "## Threads: 1 vs 2" "| render cube 64x64 " "| render cloth 1024x768 " "| sim2d | `"
      "| gen | `" "| sweep | `" "| validate large grid | `" "| corpus | `" "**Modelled from unit costs**")
  # One table per benchmark executable that was built, one row per built-in scene.
  file(GLOB bench_cmake "${SOURCE_DIR}/tests/bench/bench_*.cmake")
  foreach(f ${bench_cmake})
    get_filename_component(exe "${f}" NAME_WE)
    if(EXISTS "${BUILD_DIR}/tests/bench/${exe}")
      list(APPEND needles "### ${exe}\n")
    endif()
  endforeach()
  execute_process(COMMAND "${BUILD_DIR}/weft" render --list-scenes OUTPUT_VARIABLE scenes RESULT_VARIABLE rc)
  string(REGEX MATCHALL "[^\n]+" scenes "${scenes}")
  foreach(s ${scenes})
    list(APPEND needles "| render ${s} |")
  endforeach()
  foreach(n ${needles})
    string(FIND "${text}" "${n}" pos)
    if(pos EQUAL -1)
      message(FATAL_ERROR "${md} lacks '${n}'")
    endif()
  endforeach()
  # Four scaling rows per series with fibre length and active voxel counts, fitted exponents, the
  # memory ratios and the time per metre.
  string(REGEX MATCHALL "\n\\| weave [0-9]+×[0-9]+ \\| [0-9.]+ m \\| [0-9]+ \\|" rows "${text}")
  list(LENGTH rows nrows)
  string(REGEX MATCHALL "\n\\| one yarn, [0-9]+ points \\| [0-9.]+ m \\| [0-9]+ \\|" long_rows "${text}")
  list(LENGTH long_rows nlong)
  if(NOT nrows EQUAL 4 OR NOT nlong EQUAL 4)
    message(FATAL_ERROR "${md}: ${nrows} weave and ${nlong} long-yarn scaling rows, expected 4 each")
  endif()
  if(NOT text MATCHES "\\| gen \\+ validate wall \\| \\*\\*-?[0-9]+\\.[0-9][0-9]\\*\\*")
    message(FATAL_ERROR "${md}: no fitted scaling exponent")
  endif()
  if(NOT text MATCHES "gen RSS / memUsage" OR NOT text MATCHES "per metre of fibre on [0-9]+ cores: \\*\\*[0-9.]+×\\*\\*")
    message(FATAL_ERROR "${md}: no memory ratio or time per metre of fibre")
  endif()
  # The thread model: measured units of a render, a modelled speed-up at 2; 16; 64 threads.
  if(NOT text MATCHES "\n\\| render cube 64x64 [0-9]+ spp \\| [0-9]+ units, [0-9.]+ s, largest [0-9.]+ s \\| [0-9.]+ s \\| [0-9.]+;[0-9.]+;[0-9.]+ \\|")
    message(FATAL_ERROR "${md}: no modelled thread speed-ups for the render")
  endif()
  string(TOLOWER "${text}" lower)
  if(lower MATCHES "[^a-z]nan[^a-z]" OR lower MATCHES "[^a-z]inf[^a-z]")
    message(FATAL_ERROR "${md} contains a nan or inf figure")
  endif()
  if(text MATCHES "\\| failed \\|")
    message(FATAL_ERROR "${md}: a benchmark failed")
  endif()
  return()
endif()

add_test(NAME cli.bench.quick
         COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${PROJECT_BINARY_DIR}
                 -DOUT=${CMAKE_CURRENT_BINARY_DIR}/bench_quick -P ${CMAKE_CURRENT_LIST_FILE})
# Runs every benchmark executable once plus whole runs: RUN_SERIAL keeps it from competing with
# (and slowing) the rest of the suite.
set_tests_properties(cli.bench.quick PROPERTIES LABELS "cli" TIMEOUT 600 RUN_SERIAL TRUE)
# The notes refreshed into docs/benchmarks.md without measuring (scripts/bench --update).
add_test(NAME cli.bench.update_notes
         COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DMODE=update
                 -DOUT=${CMAKE_CURRENT_BINARY_DIR}/bench_update -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(cli.bench.update_notes PROPERTIES LABELS "cli")
