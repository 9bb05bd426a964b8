# symoroc model from the command line (issue 42, items 13 and 16): a robot folder whose name is a
# C++ keyword is refused before anything is written; --lock values are named with the option; on
# a full disk the reason is said and no file of the folder is written.
# Inputs: SYMOROC, URDF (a public arm's URDF), WORK.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

function(expect_failure what)
  cmake_parse_arguments(E "" "" "ARGS;MESSAGE" ${ARGN})
  execute_process(COMMAND ${SYMOROC} ${E_ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0)
    message(FATAL_ERROR "${what}: symoroc ${E_ARGS} succeeded:\n${out}")
  endif()
  foreach(m IN LISTS E_MESSAGE)
    string(FIND "${err}" "${m}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${what}: the message lacks '${m}':\n${err}")
    endif()
  endforeach()
endfunction()

expect_failure("a keyword folder" ARGS model ${URDF} -o ${WORK}/class
  MESSAGE "${WORK}/class: the robot's name 'class' is a C++ keyword")
if(EXISTS "${WORK}/class")
  message(FATAL_ERROR "a keyword folder: ${WORK}/class was created")
endif()
expect_failure("std" ARGS model ${URDF} -o ${WORK}/std MESSAGE "would hide the namespace std")
expect_failure("--lock =abc" ARGS model ${URDF} -o ${WORK}/arm --lock =abc MESSAGE "symoroc: --lock '=abc': write joint=position")
expect_failure("--lock j=abc" ARGS model ${URDF} -o ${WORK}/arm --lock j=abc
  MESSAGE "symoroc: --lock 'j=abc': the position 'abc' is not a number")

# A full disk: nothing written, the reason said. The disk is a 16 KiB tmpfs when the test may
# mount one (root), else a 2 KiB file size limit (prlimit --fsize, SIGXFSZ ignored), which fails the
# write the same way with EFBIG: the case runs either way.
file(MAKE_DIRECTORY "${WORK}/full")
execute_process(COMMAND mount -t tmpfs -o size=16k tmpfs "${WORK}/full" RESULT_VARIABLE mounted OUTPUT_QUIET ERROR_QUIET)
if(mounted EQUAL 0)
  set(reason "no space left on device")
  execute_process(COMMAND ${SYMOROC} model ${URDF} -o ${WORK}/full/arm RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  file(GLOB written "${WORK}/full/arm/*" "${WORK}/full/arm/.*")
  execute_process(COMMAND umount "${WORK}/full")
else()
  set(reason "File too large")
  execute_process(COMMAND sh -c "trap '' XFSZ; exec prlimit --fsize=2048 '${SYMOROC}' model '${URDF}' -o '${WORK}/full/arm'"
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  file(GLOB written "${WORK}/full/arm/*" "${WORK}/full/arm/.*")
endif()
if(rc EQUAL 0)
  message(FATAL_ERROR "a full disk: symoroc model succeeded")
endif()
foreach(m "${reason}" "no file of the")
  string(FIND "${err}" "${m}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "a full disk: the message lacks '${m}':\n${err}")
  endif()
endforeach()
if(written)
  message(FATAL_ERROR "a full disk: files were left: ${written}")
endif()
