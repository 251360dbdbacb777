# The bad-input catalogue (docs/robustness.md): one CTest per row of bad_inputs/cases.tsv, run by
# bad_inputs/run_case.cmake. Rows with a reason in the `xfail` column are known bugs (WILL_FAIL).
set(WEFT_BAD_DIR ${CMAKE_CURRENT_SOURCE_DIR}/bad_inputs)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${WEFT_BAD_DIR}/cases.tsv)
file(STRINGS ${WEFT_BAD_DIR}/cases.tsv weft_bad_rows)
foreach(row IN LISTS weft_bad_rows)
  if(row MATCHES "^#" OR row STREQUAL "" OR NOT row MATCHES "^([^\t]+)\t([^\t]*)\t([^\t]*)\t([^\t]*)\t")
    continue()
  endif()
  set(id ${CMAKE_MATCH_1})
  set(input "${CMAKE_MATCH_2}")
  set(xfail "${CMAKE_MATCH_4}")
  set(name cli.bad_inputs.${id})
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DTABLE=${WEFT_BAD_DIR}/cases.tsv -DCASE=${id}
                   -DWORK=${CMAKE_CURRENT_BINARY_DIR}/bad_inputs/${id} -DGRIDS=${CMAKE_CURRENT_BINARY_DIR}/grids
                   -DDATA=${WEFT_BAD_DIR}/data -P ${WEFT_BAD_DIR}/run_case.cmake)
  set_tests_properties(${name} PROPERTIES LABELS cli TIMEOUT 20)
  # Refusals that an estimate makes before spending must come at once: a few seconds,
  # where the run they refuse would take minutes and gigabytes.
  if(id MATCHES "^(gen_absurd_input_scale|gen_huge_yarns|fit_huge_block)$")
    set_tests_properties(${name} PROPERTIES TIMEOUT 5)
  endif()
  # Grids come from weft_make_test_grids (fixture of cli_validate.cmake).
  if(input MATCHES "^grid:" OR row MATCHES "@GRIDS@")
    set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED weft_grids)
  endif()
  if(xfail MATCHES "^skip: ")
    # Known bugs too costly or too random to run (e.g. a multi-gigabyte allocation): listed, not run.
    set_tests_properties(${name} PROPERTIES DISABLED TRUE)
  elseif(NOT xfail STREQUAL "-")
    set_tests_properties(${name} PROPERTIES WILL_FAIL TRUE)
  endif()
endforeach()
