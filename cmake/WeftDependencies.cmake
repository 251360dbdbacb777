# All dependencies come from Debian 12 packages (shared/design.md §5).

# TBB must be found before OpenVDB, whose Find module looks for it.
find_package(TBB CONFIG REQUIRED)
find_package(Eigen3 3.4 CONFIG REQUIRED)
find_package(Boost 1.74 REQUIRED)
find_package(fmt CONFIG REQUIRED)
find_package(nlohmann_json 3.10 CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)

# Debian's OpenVDB ships only a Find module, outside CMake's default search path.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)

find_package(embree 3 CONFIG REQUIRED)
find_package(CGAL CONFIG REQUIRED)
find_package(OpenEXR CONFIG REQUIRED)

find_package(VTK 9.1 REQUIRED COMPONENTS
  CommonCore CommonDataModel CommonColor ChartsCore
  FiltersCore FiltersSources FiltersGeneral
  IOImage IOXML IOLegacy IOGeometry IOPLY
  InteractionStyle RenderingCore RenderingOpenGL2 RenderingFreeType
  RenderingVolume RenderingVolumeOpenGL2 RenderingContext2D RenderingContextOpenGL2
  RenderingAnnotation ViewsContext2D)

if(WEFT_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(WEFT_BUILD_BENCH)
  find_package(benchmark CONFIG REQUIRED)
endif()
