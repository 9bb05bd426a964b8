# `symoroc check` must fail, naming the file, when one generated header was edited by hand.
file(REMOVE_RECURSE "${WORK_DIR}")
file(COPY "${SOURCE_DIR}/generated/" DESTINATION "${WORK_DIR}/generated")
set(victim "${WORK_DIR}/generated/planar2r/include/symoro/planar2r/regressor.hpp")
file(APPEND "${victim}" "// edited by hand\n")
execute_process(COMMAND "${SYMOROC}" check --robots "${SOURCE_DIR}/robots" --generated "${WORK_DIR}/generated"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(rc EQUAL 0 OR NOT out MATCHES "differs +[^\n]*planar2r/regressor.hpp")
  message(FATAL_ERROR "symoroc check did not report the edit (exit ${rc}):\n${out}")
endif()
