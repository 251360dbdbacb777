add_executable(bench_cloth ${CMAKE_CURRENT_LIST_DIR}/cloth_bench.cpp)
target_link_libraries(bench_cloth PRIVATE weft_cloth benchmark::benchmark benchmark::benchmark_main weft_warnings)
