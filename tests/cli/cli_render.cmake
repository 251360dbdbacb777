# `weft render` end to end. This file is both included by tests/cli/CMakeLists.txt (it adds the
# tests) and run as a script (`cmake -DCASE=... -P cli_render.cmake`) for checks that need a
# scene file written first or several runs compared.

if(CMAKE_SCRIPT_MODE_FILE)
  # ---- script mode: one case --------------------------------------------------------------
  file(REMOVE_RECURSE ${WORK})
  file(MAKE_DIRECTORY ${WORK})

  # Runs weft on a scene text; expects failure, a one-line error matching `pattern`, no images.
  function(expect_bad_scene text pattern)
    file(WRITE ${WORK}/bad.json "${text}")
    execute_process(COMMAND ${WEFT} render ${WORK}/bad.json -o ${WORK}/bad.exr --spp 1
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(rc EQUAL 0)
      message(FATAL_ERROR "expected failure for ${pattern}, got success: ${out}")
    endif()
    if(NOT err MATCHES "${pattern}")
      message(FATAL_ERROR "error '${err}' does not match '${pattern}'")
    endif()
    string(STRIP "${err}" stripped)
    if(stripped MATCHES "\n")
      message(FATAL_ERROR "error is not one line: ${err}")
    endif()
    if(EXISTS ${WORK}/bad.exr OR EXISTS ${WORK}/bad.png)
      message(FATAL_ERROR "a failed run left an image behind")
    endif()
  endfunction()

  # A small cloth grid and its scene in ${WORK}/g1 (relative: the cases give the scene's folder).
  function(small_cloth)
    execute_process(COMMAND ${WEFT} --quiet gen --yarns 2x2 --voxel-size 0.02 --set fiber_count=16 --out g1 --write grid
                    WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gen failed (rc=${rc}): ${err}")
    endif()
  endfunction()

  set(ok_head "{\"materials\": {\"w\": {}}, ")
  if(CASE STREQUAL "bad_input")
    expect_bad_scene("{\n  \"camera\": {\"fov\": 40,,}\n}" "weft: error: .*bad.json:2:[0-9]+: invalid JSON")
    expect_bad_scene("${ok_head}\"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"materal\": \"w\"}]}"
                     "unknown key 'materal' \\(did you mean 'material'\\?\\)")
    expect_bad_scene("${ok_head}\"shapes\": [{\"type\": \"cylinder\", \"material\": \"w\"}]}"
                     "unknown shape type 'cylinder'")
    expect_bad_scene("${ok_head}\"shapes\": [{\"type\": \"mesh\", \"file\": \"gone.obj\", \"material\": \"w\"}]}"
                     "gone.obj' does not exist")
    expect_bad_scene("${ok_head}\"shapes\": [{\"type\": \"sphere\", \"radius\": -2, \"material\": \"w\"}]}"
                     "'radius' must be > 0")
    expect_bad_scene("{\"media\": {\"m\": {\"law\": {\"name\": \"gamma-path\", \"k\": 0.5, \"theta\": 1}}}}"
                     "media.m.*does not exist")
    expect_bad_scene("{\"media\": {\"m\": {\"law\": {\"name\": \"gamma\", \"mean_extinction\": 1, \"alpha\": -1}}}}"
                     "media.m.*alpha")
    execute_process(COMMAND ${WEFT} render furnase RESULT_VARIABLE rc ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
    if(rc EQUAL 0 OR NOT err MATCHES "did you mean 'furnace'")
      message(FATAL_ERROR "unknown built-in scene: rc=${rc} ${err}")
    endif()
  elseif(CASE STREQUAL "threads")
    foreach(threads 1 2)
      execute_process(COMMAND ${WEFT} --quiet --threads ${threads} render furnace --spp 4 --seed 3
                              -o ${WORK}/t${threads}.exr RESULT_VARIABLE rc)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "render with ${threads} threads failed")
      endif()
    endforeach()
    # Both files: the EXR's ZIP blocks are compressed on OpenEXR's pool and the PNG's sRGB codes
    # on all threads when there are two (render/image.cpp); the bytes must not change.
    foreach(ext exr png)
      execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/t1.${ext} ${WORK}/t2.${ext} RESULT_VARIABLE same)
      if(NOT same EQUAL 0)
        message(FATAL_ERROR "${ext} images differ between --threads 1 and --threads 2")
      endif()
    endforeach()
  elseif(CASE STREQUAL "round_trip")
    execute_process(COMMAND ${WEFT} render cornell_media --print-scene OUTPUT_FILE ${WORK}/a.json RESULT_VARIABLE rc)
    execute_process(COMMAND ${WEFT} render ${WORK}/a.json --print-scene OUTPUT_FILE ${WORK}/b.json RESULT_VARIABLE rc2)
    execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/a.json ${WORK}/b.json RESULT_VARIABLE same)
    if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0 OR NOT same EQUAL 0)
      message(FATAL_ERROR "scene does not round-trip through --print-scene")
    endif()
  elseif(CASE STREQUAL "convergence")
    execute_process(COMMAND ${WEFT} --quiet render furnace --spp 16 -o ${WORK}/ref.exr RESULT_VARIABLE rc)
    execute_process(COMMAND ${WEFT} --quiet render furnace --spp 8 --seed 9 --convergence ${WORK}/ref.exr
                            -o ${WORK}/run.exr RESULT_VARIABLE rc2)
    if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0 OR NOT EXISTS ${WORK}/run.convergence.csv)
      message(FATAL_ERROR "convergence run failed")
    endif()
    file(STRINGS ${WORK}/run.convergence.csv rows)
    list(LENGTH rows n)
    # header + spp 1, 2, 4, 8
    if(NOT n EQUAL 5)
      message(FATAL_ERROR "expected 5 CSV rows, got ${n}: ${rows}")
    endif()
  elseif(CASE STREQUAL "fibres")
    # The fibre-curves example: Embree round curves from a BCC file next to the scene.
    execute_process(COMMAND ${WEFT} render ${SCENES}/cloth_fibres/cloth_fibres.json --spp 1 -o ${WORK}/fibres.exr
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/fibres.exr OR NOT EXISTS ${WORK}/fibres.png)
      message(FATAL_ERROR "fibre example failed (rc=${rc}): ${out}${err}")
    endif()
    if(NOT out MATCHES "features: [^\n]*curves")
      message(FATAL_ERROR "run summary does not list the curves feature: ${out}")
    endif()
  elseif(CASE STREQUAL "local_gamma")
    # gen -> fit -> render: the local-gamma example renders the fields that `weft fit` writes.
    execute_process(COMMAND ${WEFT} --quiet gen --yarns 2x2 --out ${WORK}/cloth RESULT_VARIABLE rc)
    execute_process(COMMAND ${WEFT} --quiet fit --grid ${WORK}/cloth/cloth.vdb --block 8 --out ${WORK}/fit
                    RESULT_VARIABLE rc2 ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0 OR NOT EXISTS ${WORK}/fit/local_fields.vdb)
      message(FATAL_ERROR "gen/fit for the local-gamma example failed: ${rc} ${rc2} ${err}")
    endif()
    file(COPY ${SCENES}/local_gamma/cloth_local_gamma.json ${WORK}/fit/local_fields.vdb DESTINATION ${WORK}/scene)
    execute_process(COMMAND ${WEFT} render ${WORK}/scene/cloth_local_gamma.json --spp 1 -o ${WORK}/lg.exr
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/lg.exr)
      message(FATAL_ERROR "local-gamma render failed (rc=${rc}): ${out}${err}")
    endif()
    if(NOT out MATCHES "features: [^\n]*local-gamma medium, per-voxel gamma law, hazard inversion")
      message(FATAL_ERROR "run summary does not name the local-gamma medium and its estimator: ${out}")
    endif()
  elseif(CASE STREQUAL "default_cloth")
    # `weft render` with no scene renders the default cloth of `weft gen` as a grid medium.
    execute_process(COMMAND ${WEFT} render --quick --spp 8 -o ${WORK}/d.exr
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT out MATCHES "default scene 'default_cloth'.*grid medium, exponential law")
      message(FATAL_ERROR "default render failed (rc=${rc}): ${out}${err}")
    endif()
    execute_process(COMMAND ${CHECK} ${WORK}/d.exr RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "default cloth image: ${out}${err}")
    endif()
    # The default picture (docs/render.md §5c): the cloth fills the film and almost nothing clips.
    execute_process(COMMAND ${WEFT} render --quick --print-scene OUTPUT_FILE ${WORK}/d.json RESULT_VARIABLE rc)
    execute_process(COMMAND ${CHECK} --picture ${WORK}/d.json ${WORK}/d.exr RESULT_VARIABLE rc OUTPUT_VARIABLE out
                    ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "default picture: ${out}${err}")
    endif()
  elseif(CASE STREQUAL "gen_scene")
    # `weft gen` writes scene.json beside cloth.vdb; `weft render <out>/scene.json` renders it as is.
    execute_process(COMMAND ${WEFT} --quiet gen --yarns 2x2 --out ${WORK}/cloth RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/cloth/scene.json)
      message(FATAL_ERROR "gen did not write scene.json (rc=${rc}): ${err}")
    endif()
    execute_process(COMMAND ${WEFT} render ${WORK}/cloth/scene.json --quick --spp 8 -o ${WORK}/g.exr
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "render of gen's scene.json failed (rc=${rc}): ${out}${err}")
    endif()
    execute_process(COMMAND ${CHECK} ${WORK}/g.exr RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gen scene image: ${out}${err}")
    endif()
    execute_process(COMMAND ${WEFT} render ${WORK}/cloth/scene.json --quick --print-scene OUTPUT_FILE ${WORK}/g.json
                    RESULT_VARIABLE rc)
    execute_process(COMMAND ${CHECK} --picture ${WORK}/g.json ${WORK}/g.exr RESULT_VARIABLE rc OUTPUT_VARIABLE out
                    ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gen scene picture: ${out}${err}")
    endif()
  elseif(CASE STREQUAL "relative_scene_path")
    # A scene given by a relative path with a folder (docs/scene-format.md: its files are relative
    # to its folder): the study re-reads it and --print-scene writes a scene that loads beside it.
    small_cloth()
    execute_process(COMMAND ${WEFT} --quiet render g1/scene.json --study --quick --study-spp 2 --reference-spp 4
                            --study-factors 2 --out st WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/st/scene.study.json)
      message(FATAL_ERROR "study of g1/scene.json failed (rc=${rc}): ${err}")
    endif()
    execute_process(COMMAND ${WEFT} render g1/scene.json --print-scene OUTPUT_FILE ${WORK}/g1/printed.json
                    WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc)
    execute_process(COMMAND ${WEFT} --quiet render printed.json --quick --spp 1 -o ${WORK}/p.exr
                    WORKING_DIRECTORY ${WORK}/g1 RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "the printed scene does not load beside the original (rc=${rc}): ${err}")
    endif()
  elseif(CASE STREQUAL "study_any_tracking")
    # The study takes a fine scene with any tracking: a candidate that needs another (the
    # direction-dependent shadow-directional-Nx needs delta tracking) uses it, and every candidate
    # is read before the first render (it used to fail after the reference and four candidates).
    small_cloth()
    file(READ ${WORK}/g1/scene.json scene)
    string(REPLACE "\"tracking\": \"delta\"" "\"tracking\": \"optical-depth\"" scene "${scene}")
    file(WRITE ${WORK}/g1/od.json "${scene}")
    execute_process(COMMAND ${WEFT} --quiet render g1/od.json --study --quick --study-spp 1 --reference-spp 2
                            --study-factors 2 --out st WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/st/od.study/shadow-directional-2x.exr)
      message(FATAL_ERROR "study of a scene with optical-depth tracking failed (rc=${rc}): ${err}")
    endif()
    file(READ ${WORK}/st/od.study/reference.json reference)
    if(NOT reference MATCHES "optical-depth")
      message(FATAL_ERROR "the reference did not keep the scene's tracking")
    endif()
  elseif(CASE STREQUAL "film_budget")
    # A film the memory budget (half the address-space limit here) cannot hold is one line and
    # exit 1, before anything is allocated; a study that fails so leaves no folder behind.
    small_cloth()
    file(READ ${WORK}/g1/scene.json text)
    string(REGEX REPLACE "\"width\": [0-9]+" "\"width\": 16384" text "${text}")
    string(REGEX REPLACE "\"height\": [0-9]+" "\"height\": 16384" text "${text}")
    file(WRITE ${WORK}/g1/big.json "${text}")
    foreach(args "--spp 1 -o big.exr" "--study --study-spp 1 --reference-spp 1 --study-factors 2 --out st")
      execute_process(COMMAND sh -c "ulimit -v 3000000 && exec ${WEFT} render g1/big.json ${args}"
                      WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
      string(STRIP "${err}" err)
      if(NOT rc EQUAL 1 OR NOT err MATCHES "^weft: error: [^\n]*big.json: (study candidate .reference.: )?the camera.s 16384x16384 film needs about .* over the memory budget of .*: lower camera.width and camera.height"
         OR err MATCHES "\n")
        message(FATAL_ERROR "${args}: expected one line and exit 1, got rc=${rc}: ${err}")
      endif()
    endforeach()
    if(EXISTS ${WORK}/st OR EXISTS ${WORK}/big.exr OR EXISTS ${WORK}/big.png)
      message(FATAL_ERROR "a failed render or study left output behind")
    endif()
  elseif(CASE STREQUAL "model_scenes")
    # The example scenes of docs/render.md §5d: the fine grid, the local fields of `weft fit --block` and a
    # homogeneous slab per predicted law of `weft validate --scenes`, each rendered as written.
    execute_process(COMMAND ${WEFT} --quiet gen --yarns 2x2 --out ${WORK}/cloth RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gen failed (rc=${rc}): ${err}")
    endif()
    execute_process(COMMAND ${WEFT} --quiet fit --grid ${WORK}/cloth/cloth.vdb --block 15 --out ${WORK}/fit
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/fit/local_fields_scene.json)
      message(FATAL_ERROR "fit --block did not write local_fields_scene.json (rc=${rc}): ${err}")
    endif()
    execute_process(COMMAND ${WEFT} --quiet validate --grid ${WORK}/cloth/cloth.vdb --axes z --no-plot --scenes
                            --out ${WORK}/val RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "validate --scenes failed (rc=${rc}): ${err}")
    endif()
    set(_scenes fit/local_fields_scene val/scenes/grid val/scenes/local_gamma)
    set(_slabs gamma gap-gamma across-beam isotropic exponential)
    foreach(m ${_slabs})
      list(APPEND _scenes val/scenes/slab_${m})
    endforeach()
    foreach(sc ${_scenes})
      if(NOT EXISTS ${WORK}/${sc}.json)
        message(FATAL_ERROR "missing scene ${sc}.json")
      endif()
      string(REPLACE "/" "_" img ${sc})
      # The slabs at 64 spp: the back light's scattered share (docs/render.md §2, "Shadow rays to
      # a light point") narrows the gamma slab's lead over the exponential one to ~4 standard
      # errors of an 8-spp centre; at 64 spp it is ~7, past the 5 the comparison below asks.
      set(_spp 8)
      if(sc MATCHES "slab_")
        set(_spp 64)
      endif()
      execute_process(COMMAND ${WEFT} render ${WORK}/${sc}.json --quick --spp ${_spp} -o ${WORK}/${img}.exr
                      RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "render of ${sc}.json failed (rc=${rc}): ${out}${err}")
      endif()
      if(sc MATCHES "slab_")
        if(NOT out MATCHES "homogeneous medium")
          message(FATAL_ERROR "${sc}: the summary does not name a homogeneous medium: ${out}")
        endif()
        set(_mode --slab)
      else()
        if(NOT out MATCHES "local-gamma medium|grid medium")
          message(FATAL_ERROR "${sc}: the summary does not name the grid or local-gamma medium: ${out}")
        endif()
        set(_mode)
      endif()
      execute_process(COMMAND ${CHECK} ${_mode} ${WORK}/${img}.exr RESULT_VARIABLE rc OUTPUT_VARIABLE cout
                      ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "${sc} image: ${cout}${err}")
      endif()
    endforeach()
    # Positive correlation lets more light through than the exponential of the same mean
    # (Jensen: E[e^{-sigma C t}] >= e^{-sigma E[C] t}): the gamma slab is brighter.
    execute_process(COMMAND ${CHECK} --slab ${WORK}/val_scenes_slab_gamma.exr --brighter-than
                            ${WORK}/val_scenes_slab_exponential.exr RESULT_VARIABLE rc OUTPUT_VARIABLE cout
                            ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gamma vs exponential slab: ${cout}${err}")
    endif()
  else()
    message(FATAL_ERROR "unknown CASE ${CASE}")
  endif()
  return()
endif()

# ---- configure mode: the tests --------------------------------------------------------------
set(_render_work ${CMAKE_CURRENT_BINARY_DIR}/render)
file(MAKE_DIRECTORY ${_render_work})

add_test(NAME cli.render.default_scene COMMAND weft render --quick --spp 2 WORKING_DIRECTORY ${_render_work})
set_tests_properties(cli.render.default_scene PROPERTIES LABELS "cli;render"
                     PASS_REGULAR_EXPRESSION "default scene 'default_cloth'.*wrote default_cloth.exr")

# Pixel statistics of a cloth image (the cloth is visible), for the default_cloth and gen_scene cases.
add_executable(weft_cloth_image_check ${CMAKE_CURRENT_LIST_DIR}/cloth_image_check.cpp)
target_link_libraries(weft_cloth_image_check PRIVATE weft_render weft_warnings)

add_test(NAME cli.render.list_scenes COMMAND weft render --list-scenes)
set_tests_properties(cli.render.list_scenes PROPERTIES LABELS "cli;render" PASS_REGULAR_EXPRESSION "cornell_media")

add_test(NAME cli.render.features_summary COMMAND weft render cornell_media --spp 1 -o ${_render_work}/cornell.exr)
set_tests_properties(cli.render.features_summary PROPERTIES LABELS "cli;render"
                     PASS_REGULAR_EXPRESSION "features: .*medium '[a-z_]+': homogeneous medium, gamma law, T_Q/T_S flights.*samples/s")

add_test(NAME cli.render.time_budget COMMAND weft render furnace --spp 1000000 --time-budget 0.5
                                             -o ${_render_work}/budget.exr)
set_tests_properties(cli.render.time_budget PROPERTIES LABELS "cli;render" TIMEOUT 120
                     PASS_REGULAR_EXPRESSION "64x64 at [0-9]+ spp")

foreach(case bad_input threads round_trip convergence fibres local_gamma default_cloth gen_scene model_scenes
             relative_scene_path study_any_tracking film_budget)
  add_test(NAME cli.render.${case}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=${case} -DWORK=${_render_work}/${case}
                   -DCHECK=$<TARGET_FILE:weft_cloth_image_check>
                   -DSCENES=${PROJECT_SOURCE_DIR}/scenes -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli.render.${case} PROPERTIES LABELS "cli;render")
endforeach()
