# Installs the build into a scratch prefix, then builds tests/consumer against it twice: through
# find_package(dwivedi CONFIG) and through pkg-config, and runs both programs.
foreach(var SOURCE_DIR BUILD_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run.cmake needs -D${var}=...")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# 1. CMake package
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${WORK_DIR}/cmake-build -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/cmake-build)
run(${WORK_DIR}/cmake-build/consumer)

# 2. pkg-config
find_program(PKG_CONFIG pkg-config REQUIRED)
find_program(CC NAMES cc gcc REQUIRED)
file(GLOB_RECURSE pc_files ${prefix}/dwivedi.pc)
list(GET pc_files 0 pc_file)
get_filename_component(pc_dir ${pc_file} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
execute_process(COMMAND ${PKG_CONFIG} --cflags --libs dwivedi OUTPUT_VARIABLE flags RESULT_VARIABLE rc
                OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config does not know dwivedi")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
string(REGEX MATCH "-L[^ ;]+" libdir_flag "${flags}")
string(SUBSTRING "${libdir_flag}" 2 -1 libdir)
run(${CC} -std=c99 -Wall -Wextra -Wpedantic -Werror ${SOURCE_DIR}/tests/consumer/main.c ${flags} -lm
    -Wl,-rpath,${libdir} -o ${WORK_DIR}/consumer-pkgconfig)
run(${WORK_DIR}/consumer-pkgconfig)

# 3. Only dwv_* symbols are exported, and the SONAME is libdwivedi.so.1
file(GLOB_RECURSE so_files ${prefix}/libdwivedi.so.*.*.*)
list(GET so_files 0 so_file)
find_program(NM nm REQUIRED)
execute_process(COMMAND ${NM} -D --defined-only ${so_file} OUTPUT_VARIABLE symbols)
string(REGEX MATCHALL "\n[0-9a-f]+ [TDBRVW] [^\n]+" entries "\n${symbols}")
foreach(entry IN LISTS entries)
  string(REGEX REPLACE "\n[0-9a-f]+ [TDBRVW] " "" name "${entry}")
  if(NOT name MATCHES "^dwv_" AND NOT name MATCHES "^DWIVEDI_1$")
    message(FATAL_ERROR "exported symbol that is not dwv_*: ${name}")
  endif()
endforeach()
find_program(OBJDUMP objdump REQUIRED)
execute_process(COMMAND ${OBJDUMP} -p ${so_file} OUTPUT_VARIABLE dynamic)
if(NOT dynamic MATCHES "SONAME +libdwivedi\\.so\\.1\n")
  message(FATAL_ERROR "SONAME is not libdwivedi.so.1:\n${dynamic}")
endif()
message(STATUS "installed package, pkg-config, exported symbols and SONAME are as documented")
