# All dependencies come from Debian 12 packages (shared/design.md §5).

# The libraries' dependencies (shared with the installed package's config).
macro(weft_find_dependency)
  find_package(${ARGV} REQUIRED)
endmacro()
include(WeftLibraryDependencies)

# Only the app needs CLI11.
find_package(CLI11 CONFIG REQUIRED)

if(WEFT_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(WEFT_BUILD_BENCH)
  find_package(benchmark CONFIG REQUIRED)
endif()

if(WEFT_BUILD_PYTHON)
  # Debian's interpreter, which sees Debian's python3-numpy/pytest/pybind11 (a python3 earlier on
  # PATH, e.g. a pyenv build, does not); override with -DPython3_EXECUTABLE=...
  if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter for the weft module and its tests")
  endif()
  find_package(Python3 3.9 REQUIRED COMPONENTS Interpreter Development.Module)
  set(PYBIND11_FINDPYTHON ON)
  find_package(pybind11 2.6 CONFIG REQUIRED)
endif()
