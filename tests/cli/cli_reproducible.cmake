# Reproducibility (docs/robustness.md): `weft validate`, `weft render` and `weft sim2d --quick` with the same
# seed write bit-identical files for --threads 1 and --threads 2 (report.json compared without its
# timing entries). The comparison is reproducible_compare.cmake; PNGs need a display (scripts/test
# runs ctest under xvfb-run).
# Sanitizer builds run these 3-10x slower (two sim2d runs with charts take ~2 min under ASan).
set(_reproducible_timeout 120)
if(WEFT_SANITIZE)
  set(_reproducible_timeout 600)
endif()
foreach(case validate render sim2d gen_long_yarn)
  add_test(NAME cli.reproducible.${case}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=${case}
                   -DDATA=${PROJECT_SOURCE_DIR}/tests/data/cloth
                   -DWORK=${CMAKE_CURRENT_BINARY_DIR}/reproducible_${case}
                   -P ${CMAKE_CURRENT_SOURCE_DIR}/reproducible_compare.cmake)
  set_tests_properties(cli.reproducible.${case} PROPERTIES LABELS cli TIMEOUT ${_reproducible_timeout})
endforeach()
