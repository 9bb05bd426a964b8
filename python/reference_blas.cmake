# symoro_reference_blas_object(<out var>): an object file with the reference BLAS and LAPACK
# routines (Debian's libblas-dev, liblapack-dev) that the solver libraries the module links call
# (CSDP, Ipopt with MUMPS, Ceres with SuiteSparse; found from their symbol tables), for
# linking into the module (python/CMakeLists.txt says why). Taken from the static archives by a
# relocatable link (ld -r -u <routine>...), which pulls only those routines and what they call:
# Debian's archives are not position-independent as a whole (their CBLAS part), their Fortran
# routines are. Sets <out var> to "" when the archives or the tools are missing.
function(symoro_reference_blas_object out)
  set(${out} "" PARENT_SCOPE)
  set(_arch_dir /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE})
  find_library(SYMORO_BLAS_ARCHIVE NAMES libblas.a PATHS ${_arch_dir}/blas NO_DEFAULT_PATH)
  find_library(SYMORO_LAPACK_ARCHIVE NAMES liblapack.a PATHS ${_arch_dir}/lapack NO_DEFAULT_PATH)
  if(NOT SYMORO_BLAS_ARCHIVE OR NOT SYMORO_LAPACK_ARCHIVE OR NOT SYMORO_BLAS OR NOT SYMORO_LAPACK OR NOT CMAKE_NM
     OR NOT CMAKE_LINKER OR NOT TARGET Ceres::ceres)
    return()
  endif()
  # The solver libraries (Ceres: Debian's is static, SuiteSparse is what it loads) and
  # everything they load (ldd), but the BLAS/LAPACK implementations.
  get_target_property(_ceres Ceres::ceres LOCATION)
  set(_shared ${CSDP_LIBRARY} ${pkgcfg_lib_IPOPT_ipopt})
  foreach(name IN ITEMS cholmod spqr cxsparse)
    find_library(_lib_${name} ${name})
    if(_lib_${name})
      list(APPEND _shared ${_lib_${name}})
    endif()
  endforeach()
  set(_closure "")
  foreach(lib IN LISTS _shared)
    list(APPEND _closure ${lib})
    execute_process(COMMAND ldd ${lib} OUTPUT_VARIABLE _ldd ERROR_QUIET)
    string(REGEX MATCHALL "=> [^ \n]+" _deps "${_ldd}")
    foreach(d IN LISTS _deps)
      string(SUBSTRING "${d}" 3 -1 d)
      if(NOT d MATCHES "blas|lapack|atlas")
        list(APPEND _closure ${d})
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES _closure)
  # The Fortran routines the reference libraries define, and those the closure calls.
  execute_process(COMMAND ${CMAKE_NM} -D --defined-only ${SYMORO_BLAS} ${SYMORO_LAPACK} OUTPUT_VARIABLE _defined)
  string(REGEX MATCHALL " T [a-z0-9_]+_\n" _defined "${_defined}")
  execute_process(COMMAND ${CMAKE_NM} -D --undefined-only ${_closure} OUTPUT_VARIABLE _undefined ERROR_QUIET)
  if(_ceres MATCHES "[.]a$")
    execute_process(COMMAND ${CMAKE_NM} --undefined-only ${_ceres} OUTPUT_VARIABLE _static ERROR_QUIET)
    string(APPEND _undefined "${_static}")
  endif()
  set(_flags "")
  set(_routines "")
  foreach(d IN LISTS _defined)
    string(REGEX REPLACE " T ([a-z0-9_]+)\n" "\\1" name "${d}")
    if(_undefined MATCHES " U ${name}(@|\n)")
      list(APPEND _flags -u ${name})
      list(APPEND _routines ${name})
    endif()
  endforeach()
  list(LENGTH _routines _count)
  if(_count EQUAL 0)
    return()
  endif()
  message(STATUS "symoro: the Python module carries ${_count} reference BLAS/LAPACK routines and what they call")
  set(_object ${CMAKE_CURRENT_BINARY_DIR}/reference_blas.o)
  add_custom_command(OUTPUT ${_object}
    COMMAND ${CMAKE_LINKER} -r -o ${_object} ${_flags} ${SYMORO_LAPACK_ARCHIVE} ${SYMORO_BLAS_ARCHIVE}
    DEPENDS ${SYMORO_LAPACK_ARCHIVE} ${SYMORO_BLAS_ARCHIVE}
    COMMENT "symoro: the reference BLAS/LAPACK routines for the Python module" VERBATIM)
  set(${out} ${_object} PARENT_SCOPE)
endfunction()
