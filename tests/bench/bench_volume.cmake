# Axis-beam benchmark: streaming pass vs per-ray DDAs on the default cloth (docs/benchmarks.md).
if(TARGET weft_cloth)
  add_executable(bench_volume ${CMAKE_CURRENT_LIST_DIR}/volume_bench.cpp)
  target_link_libraries(bench_volume PRIVATE weft_volume weft_cloth OpenVDB::openvdb TBB::tbb benchmark::benchmark benchmark::benchmark_main
                                             weft_warnings)
endif()
