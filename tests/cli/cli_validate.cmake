# `weft validate`, end to end on a small cloth (plots under Xvfb via scripts/test), and the bad
# inputs every stage command refuses. Fixtures (.vdb files) come from weft_make_test_grids.
set(WEFT_CLI_GRIDS ${CMAKE_CURRENT_BINARY_DIR}/grids)
add_test(NAME cli.validate.fixtures
         COMMAND ${CMAKE_COMMAND} -E make_directory ${WEFT_CLI_GRIDS})
add_test(NAME cli.validate.make_grids COMMAND weft_make_test_grids ${WEFT_CLI_GRIDS})
set_tests_properties(cli.validate.fixtures PROPERTIES LABELS cli FIXTURES_SETUP weft_grids_dir)
set_tests_properties(cli.validate.make_grids PROPERTIES LABELS cli FIXTURES_SETUP weft_grids
                     FIXTURES_REQUIRED weft_grids_dir)

add_test(NAME cli.validate.small_cloth
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DOUT=${CMAKE_CURRENT_BINARY_DIR}/validate_small -DPLOT=ON -DPROBE=$<TARGET_FILE:png_probe>
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_validate.cmake)
set_tests_properties(cli.validate.small_cloth PROPERTIES LABELS cli TIMEOUT 300)

add_test(NAME cli.validate.user_grid
         COMMAND weft validate --grid ${WEFT_CLI_GRIDS}/good.vdb --grid-name density --axes x,-z --sigma 20 --window extent --no-plot
                 --out ${CMAKE_CURRENT_BINARY_DIR}/validate_grid)
set_tests_properties(cli.validate.user_grid PROPERTIES LABELS cli FIXTURES_REQUIRED weft_grids
                     PASS_REGULAR_EXPRESSION "predicted [(]local-gamma-two-scale, fixed before measuring[)]: [+]x .* -z ")

# --no-vti: the dense ParaView copy is not written, and report.json says why.
add_test(NAME cli.validate.no_vti
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DGRID=${WEFT_CLI_GRIDS}/good.vdb
                 -DOUT=${CMAKE_CURRENT_BINARY_DIR}/validate_no_vti -P ${CMAKE_CURRENT_SOURCE_DIR}/check_no_vti.cmake)
set_tests_properties(cli.validate.no_vti PROPERTIES LABELS cli FIXTURES_REQUIRED weft_grids)

# --models predicted: the prediction alone, the same numbers as in the full run.
add_test(NAME cli.validate.models_predicted
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DGRID=${WEFT_CLI_GRIDS}/good.vdb
                 -DOUT=${CMAKE_CURRENT_BINARY_DIR}/validate_models -P ${CMAKE_CURRENT_SOURCE_DIR}/check_validate_models.cmake)
set_tests_properties(cli.validate.models_predicted PROPERTIES LABELS cli FIXTURES_REQUIRED weft_grids)

# A sigma so small that T = 1 everywhere: every model and the exponential are exact, and a ratio
# to the exponential's error 0 is undefined. Said so ("n/a" and why), never "nan" or "misses 1/3".
add_test(NAME cli.validate.exact_exponential
         COMMAND weft validate --grid ${WEFT_CLI_GRIDS}/good.vdb --axes x,-z --sigma 1e-300 --window extent --no-plot
                 --no-vti --out ${CMAKE_CURRENT_BINARY_DIR}/validate_exact)
set_tests_properties(cli.validate.exact_exponential PROPERTIES LABELS cli FIXTURES_REQUIRED weft_grids
  PASS_REGULAR_EXPRESSION "fixed before measuring[)]: [+]x n/a -z n/a.*ratios /exp undefined on [+]x -z: the exponential baseline is exact at this sigma"
  FAIL_REGULAR_EXPRESSION "nan|misses")

# Bad input: one line, non-zero exit, no output folder.
function(weft_bad_input name expect)
  add_test(NAME cli.validate.bad.${name}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DOUT=${CMAKE_CURRENT_BINARY_DIR}/bad_${name}
                   "-DEXPECT=${expect}" "-DARGS=${ARGN}" -P ${CMAKE_CURRENT_SOURCE_DIR}/check_bad_input.cmake)
  set_tests_properties(cli.validate.bad.${name} PROPERTIES LABELS cli FIXTURES_REQUIRED weft_grids)
endfunction()
weft_bad_input(missing "no such file" validate --grid ${WEFT_CLI_GRIDS}/does_not_exist.vdb)
weft_bad_input(corrupt "corrupt.vdb: cannot read OpenVDB file" validate --grid ${WEFT_CLI_GRIDS}/corrupt.vdb)
weft_bad_input(grid_name "no grid named 'smoke'" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --grid-name smoke)
weft_bad_input(not_float "weft needs a float grid" validate --grid ${WEFT_CLI_GRIDS}/int.vdb --grid-name labels)
weft_bad_input(no_float "holds no float grid" validate --grid ${WEFT_CLI_GRIDS}/int.vdb)
weft_bad_input(negative "invalid value -0.5" validate --grid ${WEFT_CLI_GRIDS}/negative.vdb)
weft_bad_input(nan "invalid value nan" validate --grid ${WEFT_CLI_GRIDS}/nan.vdb)
weft_bad_input(stretched "non-uniform voxel size" validate --grid ${WEFT_CLI_GRIDS}/stretched.vdb)
weft_bad_input(empty "empty" validate --grid ${WEFT_CLI_GRIDS}/empty.vdb)
weft_bad_input(sigma "sigma" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --sigma -1)
weft_bad_input(axes "not x, y or z" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --axes x,w)
weft_bad_input(models "'bogus' is not a model" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --sigma 2 --models gamma,bogus)
weft_bad_input(models_corpus "--models needs a validation" validate --corpus --models predicted)
weft_bad_input(cloth_json "missing.json: no such file" validate --cloth ${WEFT_CLI_GRIDS}/missing.json)
weft_bad_input(measure_missing "no such file" measure --grid ${WEFT_CLI_GRIDS}/does_not_exist.vdb)
weft_bad_input(measure_empty "empty" measure --grid ${WEFT_CLI_GRIDS}/empty.vdb)
weft_bad_input(measure_direction "direction '0,0,0'" measure --grid ${WEFT_CLI_GRIDS}/good.vdb --direction 0,0,0)
weft_bad_input(fit_nan "invalid value nan" fit --grid ${WEFT_CLI_GRIDS}/nan.vdb)
weft_bad_input(fit_block "--block" fit --grid ${WEFT_CLI_GRIDS}/good.vdb --block -2)

# σ and the scale come from the grid's provenance, so `--grid cloth.vdb` of a generated
# cloth reproduces the built-in run's numbers; beams of another σ are refused; a grid without
# provenance needs --sigma and --window.
add_test(NAME cli.validate.grid_equals_builtin
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DOUT=${CMAKE_CURRENT_BINARY_DIR}/validate_provenance
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_validate_provenance.cmake)
set_tests_properties(cli.validate.grid_equals_builtin PROPERTIES LABELS cli TIMEOUT 300)
weft_bad_input(no_sigma "without sigma in its metadata.*--sigma" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --no-plot)
weft_bad_input(no_yarn_scale "records no yarn diameter.*--window" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --sigma 3 --no-plot)
weft_bad_input(bad_window "window 'yran' is not yarn" validate --grid ${WEFT_CLI_GRIDS}/good.vdb --sigma 3 --window yran --no-plot)
