# Fuzz targets (docs/robustness.md): one fuzz/<target>_fuzz.cpp per loader, each defining
# LLVMFuzzerTestOneInput. cmake/WeftTargets.cmake includes this file once the whole project has
# been read (deferred, so every weft module exists), in two kinds of build:
#
# - WEFT_FUZZ=ON (preset `fuzz`: clang, weft code instrumented with
#   -fsanitize=fuzzer-no-link,address,undefined through weft_warnings): `fuzz_<target>` links
#   libFuzzer's main (-fsanitize=fuzzer). Run one with `scripts/fuzz TARGET SECONDS`; seed corpora
#   are in fuzz/corpus/<target>/. CTest `fuzz.<target>.regressions` replays the target's
#   regression inputs through libFuzzer.
# - otherwise, with tests (every ordinary build, gcc included): `fuzz_replay_<target>` links
#   fuzz/replay_main.cpp instead of libFuzzer, and CTest `fuzz.replay.<target>.<input>` (labels
#   `unit;fuzz`, well under a second each) replays one regression input, so CI guards them.
#
# Regression inputs: tests/data/fuzz_regressions/<target>/, crash inputs found by fuzzing and
# kept after the fix (inputs of open bugs wait in tests/data/fuzz_regressions/open/, replayed by
# nothing). OpenVDB leaks the nodes of a tree whose topology read throws (inside libopenvdb, not
# weft; docs/robustness.md, "Fuzzing"): fuzz/lsan.supp suppresses exactly that leak wherever
# LeakSanitizer runs (these tests, scripts/fuzz, the asan-ubsan test preset).

set(WEFT_FUZZ_TARGETS
    "scene:weft_render"
    "bcc:weft_curves"
    "obj_curves:weft_curves"
    "obj_mesh:weft_render"
    "cloth_spec:weft_cloth"
    "vdb:weft_volume")
set(WEFT_LSAN_OPTIONS "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/fuzz/lsan.supp:print_suppressions=0")

if(NOT WEFT_FUZZ AND WEFT_BUILD_TESTS)
  add_library(weft_fuzz_replay_main OBJECT ${CMAKE_CURRENT_LIST_DIR}/replay_main.cpp)
  target_link_libraries(weft_fuzz_replay_main PRIVATE weft_warnings)
endif()

foreach(entry ${WEFT_FUZZ_TARGETS})
  string(REPLACE ":" ";" parts ${entry})
  list(GET parts 0 target)
  list(GET parts 1 dep)
  set(regressions ${PROJECT_SOURCE_DIR}/tests/data/fuzz_regressions/${target})
  set(inputs "")
  if(WEFT_BUILD_TESTS AND IS_DIRECTORY ${regressions})
    file(GLOB inputs CONFIGURE_DEPENDS ${regressions}/*)
  endif()

  if(WEFT_FUZZ)
    add_executable(fuzz_${target} ${CMAKE_CURRENT_LIST_DIR}/${target}_fuzz.cpp)
    target_include_directories(fuzz_${target} PRIVATE ${PROJECT_SOURCE_DIR})
    target_link_libraries(fuzz_${target} PRIVATE ${dep} weft_warnings)
    target_link_options(fuzz_${target} PRIVATE -fsanitize=fuzzer)
    if(inputs)
      # libFuzzer runs each file once and fails on any crash, leak or sanitizer report.
      add_test(NAME fuzz.${target}.regressions COMMAND fuzz_${target} -rss_limit_mb=2048 ${inputs})
      set_tests_properties(fuzz.${target}.regressions PROPERTIES LABELS "unit;fuzz" TIMEOUT 120
                                                                 ENVIRONMENT "${WEFT_LSAN_OPTIONS}")
    endif()
  elseif(WEFT_BUILD_TESTS)
    add_executable(fuzz_replay_${target} ${CMAKE_CURRENT_LIST_DIR}/${target}_fuzz.cpp
                                         $<TARGET_OBJECTS:weft_fuzz_replay_main>)
    target_include_directories(fuzz_replay_${target} PRIVATE ${PROJECT_SOURCE_DIR})
    target_link_libraries(fuzz_replay_${target} PRIVATE ${dep} weft_warnings)
    foreach(input ${inputs})
      get_filename_component(name ${input} NAME_WE)
      add_test(NAME fuzz.replay.${target}.${name} COMMAND fuzz_replay_${target} ${input})
      set_tests_properties(fuzz.replay.${target}.${name} PROPERTIES LABELS "unit;fuzz" TIMEOUT 60
                                                                    ENVIRONMENT "${WEFT_LSAN_OPTIONS}")
    endforeach()
  endif()
endforeach()
