# CTest install.consumer: installs the build to a fresh prefix, checks what landed there (binary,
# libraries, package config, Python module; no OpenVDB/VTK/Embree include in any public header),
# then configures, builds and runs tests/install/consumer against it with find_package(weft).
# Arguments: -DBUILD_DIR= -DSOURCE_DIR= -DWORK_DIR= -DPYTHON= -DGENERATOR= -DPYTHON_DIR=
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

foreach(f bin/weft lib/libweft_core.a lib/libweft_transmittance.a lib/libweft_render.a
          lib/cmake/weft/weftConfig.cmake lib/cmake/weft/weftTargets.cmake include/weft/transmittance/law.h
          include/data_gen/cloth/spec.h)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${prefix}/${f}")
  endif()
endforeach()
file(GLOB_RECURSE headers ${prefix}/include/*.h)
foreach(h ${headers})
  file(STRINGS ${h} heavy REGEX "#include *[<\"](openvdb|vtk|embree[0-9]*)/")
  if(heavy)
    message(FATAL_ERROR "public header ${h} includes a heavy dependency: ${heavy}")
  endif()
endforeach()

# The installed binary runs from the prefix.
run(${prefix}/bin/weft model --law gamma --alpha 0.5 --mean-extinction 2 --t 1)

# The installed Python module imports and evaluates a law, from the prefix alone.
if(PYTHON)
  run(${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/${PYTHON_DIR} ${PYTHON}
      ${SOURCE_DIR}/tests/install/check_module.py ${prefix})
endif()

run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/consumer -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/consumer)
message(STATUS "${last_output}")
run(${WORK_DIR}/build/consumer_transmittance)
file(REMOVE_RECURSE ${WORK_DIR})
