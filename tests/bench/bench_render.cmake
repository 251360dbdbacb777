add_executable(bench_render ${CMAKE_CURRENT_LIST_DIR}/render_bench.cpp)
target_link_libraries(bench_render PRIVATE weft_render benchmark::benchmark benchmark::benchmark_main weft_warnings)
