# What weft's libraries link, in one list for the build (WeftDependencies.cmake) and for consumers
# of the installed package (weftConfig.cmake). The caller defines weft_find_dependency(...):
# find_package(... REQUIRED) in the build, find_dependency(...) in the installed config.

# TBB must be found before OpenVDB, whose Find module looks for it.
weft_find_dependency(TBB CONFIG)
weft_find_dependency(Eigen3 3.4 CONFIG)
weft_find_dependency(Boost 1.74)
weft_find_dependency(fmt CONFIG)
weft_find_dependency(nlohmann_json 3.10 CONFIG)

# Debian's OpenVDB ships only a Find module, outside CMake's default search path.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
weft_find_dependency(OpenVDB)

weft_find_dependency(embree 3 CONFIG)
weft_find_dependency(CGAL CONFIG)
weft_find_dependency(OpenEXR CONFIG)
weft_find_dependency(X11)

weft_find_dependency(VTK 9.1 COMPONENTS
  CommonCore CommonDataModel CommonColor ChartsCore
  FiltersCore FiltersSources FiltersGeneral
  IOImage IOXML IOLegacy IOGeometry IOPLY
  InteractionStyle RenderingCore RenderingOpenGL2 RenderingFreeType
  RenderingVolume RenderingVolumeOpenGL2 RenderingContext2D RenderingContextOpenGL2
  RenderingAnnotation ViewsContext2D)
