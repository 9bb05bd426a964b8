# The C++ sources follow .clang-format (issue 43): clang-format 14 leaves every file of runtime/,
# codegen/, grammar/, tests/, bench/ and python/ as it is (generated/ is the emitter's layout).
# A file it would change is named with its first differing lines; `clang-format-14 -i <file>`
# formats it.
# Run: cmake -DSOURCE=<project dir> -DCLANG_FORMAT=<clang-format-14> -P format_check.cmake
cmake_minimum_required(VERSION 3.16)
set(files "")
foreach(dir runtime codegen grammar tests bench python)
  file(GLOB_RECURSE found ${SOURCE}/${dir}/*.cpp ${SOURCE}/${dir}/*.hpp ${SOURCE}/${dir}/*.h)
  list(APPEND files ${found})
endforeach()
list(LENGTH files count)
if(count LESS 100)
  message(FATAL_ERROR "format_check: only ${count} C++ files under ${SOURCE}: not the project's tree")
endif()
execute_process(COMMAND ${CLANG_FORMAT} --style=file --dry-run --Werror ${files}
                WORKING_DIRECTORY ${SOURCE} RESULT_VARIABLE rc ERROR_VARIABLE problems OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0)
  string(REGEX MATCHALL "[^\n]*: error: code should be clang-formatted[^\n]*" where "${problems}")
  list(LENGTH where n)
  string(SUBSTRING "${problems}" 0 4000 first)
  message(FATAL_ERROR "${n} place(s) not formatted as .clang-format says (clang-format-14 -i <file> formats it):\n${first}")
endif()
message(STATUS "${count} C++ files follow .clang-format")
