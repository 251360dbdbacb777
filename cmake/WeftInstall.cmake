# Install rules and the CMake package: `cmake --install <build> --prefix P` puts the weft binary
# in P/bin, the static libraries in P/lib, the public headers in P/include (none includes
# OpenVDB, VTK or Embree), the Python package in P/${WEFT_PYTHON_INSTALL_DIR} and the package
# config in P/lib/cmake/weft, so a consumer writes
#   find_package(weft CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE weft::weft)     # or weft::transmittance, weft::volume, ...
# and weftConfig.cmake finds the libraries' own dependencies (find_dependency).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS weft RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

get_property(weft_modules GLOBAL PROPERTY WEFT_MODULES)
# weft::weft: every module.
add_library(weft_all INTERFACE)
set_target_properties(weft_all PROPERTIES EXPORT_NAME weft)
target_link_libraries(weft_all INTERFACE ${weft_modules})

# weft_warnings travels with the static libraries ($<LINK_ONLY:...>: only its link options, e.g.
# the sanitizer runtime of a sanitized build, reach the consumer).
install(TARGETS ${weft_modules} weft_all weft_warnings EXPORT weftTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT weftTargets NAMESPACE weft:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/weft)

# Public headers; grid_openvdb.h and the internal *_impl.h headers (OpenVDB, inlined kernels) are
# the library's private business.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lib/weft DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h" PATTERN "grid_openvdb.h" EXCLUDE PATTERN "*_impl.h" EXCLUDE)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data_gen DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/weftConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/weftConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/weft)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/weftConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/weftConfig.cmake ${PROJECT_BINARY_DIR}/weftConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/WeftLibraryDependencies.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/weft)
