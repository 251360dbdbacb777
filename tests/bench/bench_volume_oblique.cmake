# Oblique-beam benchmark: per-ray weft DDA vs OpenVDB math::DDA on the default cloth (scripts/bench).
if(TARGET weft_cloth)
  add_executable(bench_volume_oblique ${CMAKE_CURRENT_LIST_DIR}/volume_oblique_bench.cpp)
  target_link_libraries(bench_volume_oblique PRIVATE weft_volume weft_cloth benchmark::benchmark
                                                     benchmark::benchmark_main weft_warnings)
endif()
