add_executable(bench_media2d ${CMAKE_CURRENT_LIST_DIR}/media2d_bench.cpp)
target_link_libraries(bench_media2d PRIVATE weft_media2d benchmark::benchmark benchmark::benchmark_main weft_warnings)
