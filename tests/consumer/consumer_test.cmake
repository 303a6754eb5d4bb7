# The install_consumer test (tests/CMakeLists.txt): installs the build into a fresh prefix,
# configures and builds tests/consumer against it with the same compiler and flags, and runs
# the program; then compiles the same main.cpp with the flags of `pkg-config --static covrast`
# and runs that too. cmake -P with -DBUILD_DIR, -DSOURCE_DIR, -DWORK_DIR, -DGENERATOR,
# -DCXX_COMPILER, -DBUILD_TYPE, -DCXX_FLAGS and -DCXX_FLAGS_CONFIG (the build type's flags).
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER BUILD_TYPE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "consumer_test.cmake: -D${var}=... missing")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    list(JOIN ARGN " " command)
    message(FATAL_ERROR "failed (${result}): ${command}")
  endif()
endfunction()

string(TOUPPER "${BUILD_TYPE}" BUILD_TYPE_UPPER)
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
# The fresh prefix comes first (CMAKE_PREFIX_PATH), and no package registry is read.
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${WORK_DIR}/build -G ${GENERATOR}
  -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_BUILD_TYPE=${BUILD_TYPE}
  "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_CXX_FLAGS_${BUILD_TYPE_UPPER}=${CXX_FLAGS_CONFIG}"
  -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
  -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/covrast_consumer)

# The same program through the pkg-config module (covrast.pc), compiled by hand.
find_program(PKG_CONFIG pkg-config REQUIRED)
file(GLOB pc_file ${prefix}/lib*/pkgconfig/covrast.pc ${prefix}/lib/*/pkgconfig/covrast.pc)
if(NOT pc_file)
  message(FATAL_ERROR "not installed: lib/pkgconfig/covrast.pc")
endif()
list(GET pc_file 0 pc_file)
get_filename_component(pc_dir ${pc_file} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
execute_process(COMMAND ${PKG_CONFIG} --static --cflags --libs covrast
  OUTPUT_VARIABLE pc_flags OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "pkg-config --static --cflags --libs covrast failed")
endif()
separate_arguments(pc_flags UNIX_COMMAND "${pc_flags}")
separate_arguments(flags UNIX_COMMAND "${CXX_FLAGS} ${CXX_FLAGS_CONFIG}")
run(${CXX_COMPILER} -std=c++20 ${flags} ${SOURCE_DIR}/tests/consumer/main.cpp ${pc_flags}
  -o ${WORK_DIR}/covrast_consumer_pc)
run(${WORK_DIR}/covrast_consumer_pc)
file(REMOVE_RECURSE ${WORK_DIR})
