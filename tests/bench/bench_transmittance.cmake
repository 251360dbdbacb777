add_executable(bench_transmittance ${CMAKE_CURRENT_LIST_DIR}/transmittance_bench.cpp)
target_link_libraries(bench_transmittance PRIVATE weft_transmittance benchmark::benchmark benchmark::benchmark_main
                                                  weft_warnings)
