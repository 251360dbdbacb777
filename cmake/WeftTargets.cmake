# Shared compile settings for every weft target.
add_library(weft_warnings INTERFACE)
target_compile_options(weft_warnings INTERFACE -Wall -Wextra -Wpedantic)
if(WEFT_WERROR)
  target_compile_options(weft_warnings INTERFACE -Werror)
endif()
if(WEFT_SANITIZE)
  target_compile_options(weft_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                 -fno-sanitize-recover=undefined)
  target_link_options(weft_warnings INTERFACE -fsanitize=address,undefined)
endif()

# Fuzzing (preset `fuzz`, docs/robustness.md): weft code gets libFuzzer's coverage instrumentation plus
# ASan/UBSan; the targets in fuzz/ link libFuzzer's main. fuzz/targets.cmake is included once the
# whole project has been read (deferred: subdirectories cannot be added then), so it can link any
# weft module.
option(WEFT_FUZZ "Build the libFuzzer targets in fuzz/ (needs clang)" OFF)
if(WEFT_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "WEFT_FUZZ needs clang (libFuzzer); use the `fuzz` preset")
  endif()
  target_compile_options(weft_warnings INTERFACE -fsanitize=fuzzer-no-link,address,undefined
                                                 -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(weft_warnings INTERFACE -fsanitize=address,undefined)
endif()
# Every build with tests gets the replay drivers fuzz_replay_<target> instead (fuzz/replay_main.cpp
# calls the same entry points without libFuzzer; CTest fuzz.replay.* replays the regression inputs).
if(WEFT_FUZZ OR WEFT_BUILD_TESTS)
  cmake_language(DEFER DIRECTORY ${PROJECT_SOURCE_DIR} CALL include ${PROJECT_SOURCE_DIR}/fuzz/targets.cmake)
endif()

# Floating-point traps (preset `fp-trap`, docs/robustness.md): every unit test links a GoogleTest
# environment that enables FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW before the tests run, so an
# unintended NaN, division by zero or overflow stops the test with SIGFPE where it happens.
option(WEFT_TRAP_FP "Unit tests trap floating-point exceptions (invalid, divide-by-zero, overflow)" OFF)
if(WEFT_TRAP_FP)
  # Turns on weft::HeldFpExceptions (weft/core/fp_hold.h) around library calls that compute with
  # infinities on purpose; in every other build the scope compiles to nothing.
  add_compile_definitions(WEFT_TRAP_FP=1)
endif()

# weft_module(NAME SOURCES ... DEPS ... [PRIVATE_DEPS ...])
# One static library per module under lib/weft/<name> or data_gen/<name>; include paths are
# rooted at lib/ and the repository root so headers read as <weft/core/error.h> and
# <data_gen/cloth/yarn.h>.
function(weft_module name)
  cmake_parse_arguments(M "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  if(NOT M_SOURCES)
    # A module whose sources are not written yet is headers only.
    add_library(weft_${name} INTERFACE)
    target_include_directories(weft_${name} INTERFACE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/lib>
                                                      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
    target_link_libraries(weft_${name} INTERFACE ${M_DEPS})
    return()
  endif()
  add_library(weft_${name} STATIC ${M_SOURCES})
  # Installed headers live under <prefix>/include (weft/..., data_gen/...; cmake/WeftInstall.cmake).
  target_include_directories(weft_${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/lib>
                                                 $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                                 $<INSTALL_INTERFACE:include>)
  target_link_libraries(weft_${name} PUBLIC ${M_DEPS} PRIVATE weft_warnings ${M_PRIVATE_DEPS})
  # Every module is part of the installed CMake package (weft::<name>, cmake/WeftInstall.cmake).
  set_property(GLOBAL APPEND PROPERTY WEFT_MODULES weft_${name})
  # Position independent: linked into the Python extension (a shared object) and, installed,
  # into consumers' shared libraries.
  set_target_properties(weft_${name} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
endfunction()

# weft_unit_test(NAME SOURCES ... DEPS ... [LABELS ...])
function(weft_unit_test name)
  cmake_parse_arguments(T "" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  # gmock for its matchers (tests/unit/error_matchers.h); gtest_main still supplies main().
  target_link_libraries(${name} PRIVATE ${T_DEPS} GTest::gmock GTest::gtest GTest::gtest_main weft_warnings)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/unit)
  target_compile_definitions(${name} PRIVATE WEFT_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data")
  if(WEFT_TRAP_FP)
    target_sources(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/unit/fp_trap_environment.cpp)
    # -rdynamic: the SIGFPE backtrace then names the functions (weft's static libraries included).
    target_link_options(${name} PRIVATE -rdynamic)
  endif()
  if(NOT T_LABELS)
    set(T_LABELS unit)
  endif()
  include(GoogleTest)
  gtest_discover_tests(${name} NO_PRETTY_VALUES PROPERTIES LABELS "${T_LABELS}" DISCOVERY_TIMEOUT 60)
endfunction()

# Names OpenVDB's library first among the shared libraries a binary or module needs. The dynamic
# loader resolves each symbol relocation by searching the loaded objects in the order the binary
# names them (then their own dependencies, breadth first), and OpenVDB alone holds about three
# quarters of the process's relocations (68 870 of 92 336, mostly its own template instances and
# vtables). After the 22 VTK libraries, each of its lookups first tried every one of them; named
# first, the start of every run is ≈ 14 ms shorter, 73 → 60 ms for `weft --version`
# (docs/benchmarks.notes.md "Start-up: the shared libraries' order"). Definitions do not change:
# every symbol is defined once, or as identical inline copies.
# A link option, not a link item: CMake places a library item after the static libraries that
# use it, while options come before every object and library on the command line.
function(weft_link_startup_order target)
  target_link_options(${target} PRIVATE "LINKER:--push-state,--no-as-needed"
                      "$<TARGET_FILE:OpenVDB::openvdb>" "LINKER:--pop-state")
endfunction()
