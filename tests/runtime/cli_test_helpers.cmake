# What the command-line test scripts share (included by dynid_cli, anyrobot_cli, loaded_robot_cli,
# bag_to_mjcf_cli, mpi_ranks).

# Runs a command; fails the test unless it exits with expect_code. out_var: stdout and stderr.
function(run_command expect_code out_var)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL expect_code)
    message(FATAL_ERROR "${ARGN}: exit ${code}, expected ${expect_code}\n${out}\n${err}")
  endif()
  set(${out_var} "${out}${err}" PARENT_SCOPE)
endfunction()

function(expect text pattern)
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "expected /${pattern}/ in:\n${text}")
  endif()
endfunction()

# Runs ${DYNID} <arguments> (the scripts' -DDYNID) with run_command.
function(run expect_code out_var)
  run_command(${expect_code} out ${DYNID} ${ARGN})
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()
