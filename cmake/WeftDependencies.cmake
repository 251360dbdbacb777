# All dependencies come from Debian 12 packages (docs/architecture.md §9).

# The libraries' dependencies (shared with the installed package's config).
macro(weft_find_dependency)
  find_package(${ARGV} REQUIRED)
endmacro()
include(WeftLibraryDependencies)

# Only the app needs CLI11.
find_package(CLI11 CONFIG REQUIRED)

# MPI (docs/scale-out.md): independent work units spread over ranks under mpirun. The C
# API only (MPI's C++ bindings left the standard in MPI 3), so Open MPI and MPICH both serve.
# weft_dist links it privately; a consumer of an installed WEFT_MPI build needs MPI too.
find_package(MPI COMPONENTS C)
option(WEFT_MPI "Spread work units over MPI ranks under mpirun (weft/dist); ON when MPI is found" ${MPI_C_FOUND})
if(WEFT_MPI AND NOT MPI_C_FOUND)
  message(FATAL_ERROR "WEFT_MPI is ON but no MPI C library was found (Debian: libopenmpi-dev or libmpich-dev)")
endif()

if(WEFT_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
  # Debian ships GoogleMock apart (libgmock-dev); GTestConfig.cmake includes its targets optionally.
  if(NOT TARGET GTest::gmock)
    message(FATAL_ERROR "GoogleTest was found without GoogleMock, which the unit tests' matchers need (Debian: libgmock-dev)")
  endif()
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
