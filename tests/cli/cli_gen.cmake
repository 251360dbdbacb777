# `weft gen` end to end. This file has two roles: included by tests/cli/CMakeLists.txt it adds
# the tests; run as `cmake -DWEFT=... -DWORK=... -DCASE=... -P cli_gen.cmake` it is the check
# script those tests call (content checks that a plain exit code cannot express).

if(CMAKE_SCRIPT_MODE_FILE)
  function(gen_fail message)
    message(FATAL_ERROR "cli.gen.${CASE}: ${message}")
  endfunction()

  # Runs weft with ARGN; sets rc/out/err in the caller.
  function(run_weft)
    execute_process(COMMAND ${WEFT} ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr
                    TIMEOUT 300)
    set(rc "${code}" PARENT_SCOPE)
    set(out "${stdout}" PARENT_SCOPE)
    set(err "${stderr}" PARENT_SCOPE)
  endfunction()

  # OpenVDB writes a random file UUID at bytes 21..57 of the header; everything after it must
  # be identical for identical grids and metadata.
  function(vdb_body path var)
    file(READ ${path} hex HEX)
    string(SUBSTRING "${hex}" 114 -1 body)
    set(${var} "${body}" PARENT_SCOPE)
  endfunction()

  file(REMOVE_RECURSE ${WORK})
  file(MAKE_DIRECTORY ${WORK})

  if(CASE STREQUAL "roundtrip")
    run_weft(gen --out ${WORK}/a)
    if(NOT rc EQUAL 0)
      gen_fail("default run failed (${rc}): ${err}")
    endif()
    foreach(f cloth.vdb fibers.vtp yarns.bcc cloth.json)
      if(NOT EXISTS ${WORK}/a/${f})
        gen_fail("missing ${f}")
      endif()
      if(NOT out MATCHES "${f}")
        gen_fail("the summary does not say where ${f} went: ${out}")
      endif()
    endforeach()
    file(READ ${WORK}/a/yarns.bcc magic LIMIT 4 HEX)
    if(NOT magic STREQUAL "42434344")
      gen_fail("yarns.bcc does not start with BCC 0x44 (${magic})")
    endif()
    file(READ ${WORK}/a/cloth.json json)
    string(JSON pattern GET "${json}" pattern)
    string(JSON units GET "${json}" units)
    string(JSON radius GET "${json}" warp_yarn fiber_radius)
    if(NOT pattern STREQUAL "plain" OR NOT units STREQUAL "mm" OR NOT radius GREATER 0)
      gen_fail("cloth.json lacks the parameters: ${json}")
    endif()
    file(READ ${WORK}/a/fibers.vtp vtp LIMIT 4000)
    if(NOT vtp MATCHES "PolyData" OR NOT vtp MATCHES "Name=\"yarn\"" OR NOT vtp MATCHES "Name=\"ply\"")
      gen_fail("fibers.vtp lacks polydata with yarn/ply ids")
    endif()
    file(READ ${WORK}/a/cloth.vdb vdbhex HEX)
    # "generator" and "units" metadata keys, in hex (the file is binary).
    if(NOT vdbhex MATCHES "67656e657261746f72" OR NOT vdbhex MATCHES "756e697473")
      gen_fail("cloth.vdb lacks provenance metadata")
    endif()
    # The recorded parameters rebuild the same grid, on one thread this time.
    run_weft(--threads 1 gen --config ${WORK}/a/cloth.json --out ${WORK}/b)
    if(NOT rc EQUAL 0)
      gen_fail("--config run failed (${rc}): ${err}")
    endif()
    foreach(f cloth.json yarns.bcc)
      file(SHA256 ${WORK}/a/${f} ha)
      file(SHA256 ${WORK}/b/${f} hb)
      if(NOT ha STREQUAL hb)
        gen_fail("${f} differs between the run and its --config rerun")
      endif()
    endforeach()
    vdb_body(${WORK}/a/cloth.vdb va)
    vdb_body(${WORK}/b/cloth.vdb vb)
    if(NOT va STREQUAL vb)
      gen_fail("cloth.vdb differs (beyond the file UUID) between the run and its --config rerun")
    endif()
    # Another seed is another cloth.
    run_weft(gen --quiet --seed 2 --out ${WORK}/c)
    vdb_body(${WORK}/c/cloth.vdb vc)
    if(va STREQUAL vc)
      gen_fail("--seed 2 gave the same grid as seed 1")
    endif()
  elseif(CASE STREQUAL "import")
    foreach(input two_yarns_c0.bcc two_yarns.obj)
      run_weft(gen --quiet --input ${DATA}/${input} --voxel-size 0.02 --out ${WORK}/${input} --fibers-bcc)
      if(NOT rc EQUAL 0)
        gen_fail("import of ${input} failed (${rc}): ${err}")
      endif()
      file(READ ${WORK}/${input}/cloth.json json)
      string(JSON pattern GET "${json}" pattern)
      if(NOT pattern STREQUAL "import" OR NOT EXISTS ${WORK}/${input}/fibers.bcc)
        gen_fail("import of ${input} did not record pattern 'import' or write fibers.bcc")
      endif()
    endforeach()
  elseif(CASE STREQUAL "twill")
    run_weft(gen --quiet --pattern twill22 --yarns 3x3 --voxel-size 0.02 --yarn polyester --out ${WORK}/t)
    if(NOT rc EQUAL 0)
      gen_fail("twill run failed (${rc}): ${err}")
    endif()
    file(READ ${WORK}/t/cloth.json json)
    string(JSON pattern GET "${json}" pattern)
    string(JSON warps GET "${json}" warp_count)
    string(JSON preset GET "${json}" weft_yarn preset)
    if(NOT pattern STREQUAL "twill22" OR NOT warps EQUAL 3 OR NOT preset STREQUAL "polyester")
      gen_fail("cloth.json does not record the options: ${json}")
    endif()
  elseif(CASE STREQUAL "only_what_is_asked")
    # --write without grid builds no grid: a cloth whose grid is far over the budget (about
    # 118 GiB) writes its parameters and centrelines at once; fibres alone are checked without the
    # grid. cloth.json is the same bytes as a whole run's.
    run_weft(gen --quiet --yarns 40x40 --voxel-size 0.002 --write config,yarns --out ${WORK}/c)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/c/yarns.bcc OR EXISTS ${WORK}/c/cloth.vdb)
      gen_fail("config and yarns of a cloth whose grid is over the budget (${rc}): ${err}")
    endif()
    run_weft(gen --yarns 2x2 --voxel-size 0.02 --write fibers --out ${WORK}/f)
    if(NOT rc EQUAL 0 OR NOT out MATCHES "no grid" OR out MATCHES "voxelized" OR EXISTS ${WORK}/f/cloth.vdb)
      gen_fail("fibres alone built a grid or failed (${rc}): ${out}${err}")
    endif()
    run_weft(gen --quiet --yarns 2x2 --voxel-size 0.02 --write config --out ${WORK}/s)
    run_weft(gen --quiet --yarns 2x2 --voxel-size 0.02 --out ${WORK}/all)
    file(READ ${WORK}/s/cloth.json alone)
    file(READ ${WORK}/all/cloth.json whole)
    if(NOT alone STREQUAL whole)
      gen_fail("cloth.json alone differs from a whole run's")
    endif()
  else()
    # Bad input: non-zero exit, a one-line error matching EXPECT, and no output folder content.
    separate_arguments(args UNIX_COMMAND "${ARGS}")
    run_weft(gen ${args} --out ${WORK}/out)
    if(rc EQUAL 0)
      gen_fail("accepted bad input: ${ARGS}")
    endif()
    string(STRIP "${err}" line)
    if(NOT line MATCHES "^weft: error: " OR line MATCHES "\n")
      gen_fail("expected one 'weft: error:' line, got: ${err}")
    endif()
    if(NOT line MATCHES "${EXPECT}")
      gen_fail("error does not name '${EXPECT}': ${line}")
    endif()
    file(GLOB written ${WORK}/out/*)
    if(written)
      gen_fail("bad input left files behind: ${written}")
    endif()
  endif()
  return()
endif()

set(WEFT_GEN_DATA ${PROJECT_SOURCE_DIR}/tests/data/cloth)
foreach(case roundtrip import twill only_what_is_asked)
  add_test(NAME cli.gen.${case}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DWORK=${CMAKE_CURRENT_BINARY_DIR}/gen_${case}
                   -DDATA=${WEFT_GEN_DATA} -DCASE=${case} -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli.gen.${case} PROPERTIES LABELS cli TIMEOUT 300)
endforeach()

# name | arguments | what the error must name
set(WEFT_GEN_BAD_CASES
    "voxel_size_zero|--voxel-size 0|--voxel-size: must be finite and > 0"
    "voxel_size_nan|--voxel-size nan|--voxel-size"
    "negative_spacing|--spacing -0.5|spacing"
    "negative_radius|--set fiber_radius=-0.01|fiber_radius"
    "nan_pitch|--set warp.ply_pitch=nan|ply_pitch"
    "zero_pitch|--set fiber_pitch=0|fiber_pitch"
    "unknown_pattern|--pattern lace|lace"
    "bad_yarns|--yarns 8by8|--yarns"
    "memory_budget|--voxel-size 0.0004 --max-memory 64M|memory budget"
    "missing_bcc|--input ${WEFT_GEN_DATA}/no_such_file.bcc|no_such_file.bcc: no such file"
    "truncated_bcc|--input ${WEFT_GEN_DATA}/truncated.bcc|truncated.bcc"
    "bad_signature_bcc|--input ${WEFT_GEN_DATA}/bad_signature.bcc|bad_signature.bcc: not a BCC file"
    "wrong_count_bcc|--input ${WEFT_GEN_DATA}/wrong_count.bcc|wrong_count.bcc"
    "truncated_obj|--input ${WEFT_GEN_DATA}/truncated.obj|truncated.obj:4"
    "missing_config|--config ${WEFT_GEN_DATA}/no_such.json|no_such.json")
foreach(entry ${WEFT_GEN_BAD_CASES})
  string(REPLACE "|" ";" parts "${entry}")
  list(GET parts 0 name)
  list(GET parts 1 args)
  list(GET parts 2 expect)
  add_test(NAME cli.gen.bad.${name}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DWORK=${CMAKE_CURRENT_BINARY_DIR}/gen_bad_${name}
                   -DCASE=bad.${name} "-DARGS=${args}" "-DEXPECT=${expect}" -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli.gen.bad.${name} PROPERTIES LABELS cli TIMEOUT 120)
endforeach()

add_test(NAME cli.gen.help COMMAND weft gen --help)
set_tests_properties(cli.gen.help PROPERTIES LABELS cli
                     PASS_REGULAR_EXPRESSION "--voxel-size.*--max-memory.*fiber_radius.*migration_period")
