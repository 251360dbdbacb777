# Render times of a chart and of a volume view (docs/benchmarks.md); needs an X display or Xvfb.
add_executable(bench_viz ${CMAKE_CURRENT_LIST_DIR}/viz_bench.cpp)
target_link_libraries(bench_viz PRIVATE weft_viz weft_volume OpenVDB::openvdb benchmark::benchmark
                                        benchmark::benchmark_main weft_warnings)
