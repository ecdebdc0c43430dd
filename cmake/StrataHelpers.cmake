# strata_add_library(NAME SOURCES ... DEPS ...): a library with public headers in include/.
# strata_add_test(NAME SOURCES ... DEPS ... [LABELS ...] [ENVIRONMENT VAR=value ...]): one GoogleTest
# binary, registered with ctest.

set(CMAKE_CXX_STANDARD 20)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)

add_library(strata_options INTERFACE)
target_compile_options(strata_options INTERFACE -Wall -Wextra -Wpedantic $<$<CXX_COMPILER_ID:GNU>:-Wshadow=local>
                                                $<$<CXX_COMPILER_ID:Clang>:-Wshadow;-Wno-pass-failed>)
if(STRATA_UNITY_BUILD)
  # GCC says a class with external linkage that holds an anonymous namespace's type belongs in a
  # header; a unity batch includes the .cpp files that define such private Impl classes.
  target_compile_options(strata_options INTERFACE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
endif()
if(STRATA_WERROR)
  target_compile_options(strata_options INTERFACE -Werror)
endif()
# GLM: radians everywhere, depth range [0,1] for reversed-Z, no implicit experimental warnings.
target_compile_definitions(strata_options INTERFACE GLM_FORCE_RADIANS GLM_FORCE_DEPTH_ZERO_TO_ONE
                                                    GLM_ENABLE_EXPERIMENTAL)
if(STRATA_SANITIZE)
  # GCC 12's -Wmaybe-uninitialized gives false positives inside libstdc++ (std::regex,
  # std::function) once sanitizer instrumentation is in: the warning stays on in the normal build.
  target_compile_options(strata_options INTERFACE -fsanitize=${STRATA_SANITIZE} -fno-omit-frame-pointer
                                                  -fno-sanitize-recover=undefined
                                                  $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>)
  target_link_options(strata_options INTERFACE -fsanitize=${STRATA_SANITIZE})
endif()

function(strata_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  if(STRATA_BUILD_PYTHON)
    set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)  # linked into python/'s module
  endif()
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
                                     PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(${name} PUBLIC strata_options ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

function(strata_add_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE strata_options ${ARG_DEPS})
endfunction()

# Tests get STRATA_SOURCE_DIR / STRATA_DATA_DIR (../shared/data) / STRATA_BINARY_DIR compiled in.
set(STRATA_DATA_DIR "${PROJECT_SOURCE_DIR}/../shared/data" CACHE PATH "Shared real DEMs")
function(strata_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS;ENVIRONMENT" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE strata_options ${ARG_DEPS} GTest::gtest GTest::gmock strata_test_main)
  target_compile_definitions(${name} PRIVATE
    STRATA_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    STRATA_DATA_DIR="${STRATA_DATA_DIR}"
    STRATA_TEST_OUTPUT_DIR="${PROJECT_BINARY_DIR}/test-output")
  set(properties)  # an empty value would swallow the next property's name
  if(ARG_LABELS)
    list(APPEND properties LABELS "${ARG_LABELS}")
  endif()
  if(ARG_ENVIRONMENT)
    list(APPEND properties ENVIRONMENT "${ARG_ENVIRONMENT}")
  endif()
  gtest_discover_tests(${name} PROPERTIES ${properties} DISCOVERY_TIMEOUT 60)
endfunction()
