# Shared compile settings for every airseg target.
add_library(airseg_options INTERFACE)
target_compile_features(airseg_options INTERFACE cxx_std_20)
target_include_directories(airseg_options INTERFACE ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/generated)
target_compile_options(airseg_options INTERFACE -Wall -Wextra -Wpedantic)
if(AIRSEG_WERROR)
  target_compile_options(airseg_options INTERFACE -Werror)
endif()
# Boost.Asio is header-only here; keep its deprecated API out so the code stays portable to newer Boost.
target_compile_definitions(airseg_options INTERFACE BOOST_ASIO_NO_DEPRECATED BOOST_ASIO_NO_TS_EXECUTORS
                                                    AIRSEG_VERSION="${PROJECT_VERSION}")
# No absolute path of this checkout in any object: file names in debug information and __FILE__ are relative
# to the top of the tree, so that a compiler cache (with CCACHE_BASEDIR at the top) serves a clone of the tree
# in another directory, and two clones build identical objects. Tests find the trees at run time
# (tests/support/tree_paths.hpp), not through compiled-in paths. CI turns it on; a debugger then needs
# `set substitute-path . TOP` or to run from the top.
option(AIRSEG_RELATIVE_PATHS "Map the tree's absolute path to . in objects (-ffile-prefix-map)" OFF)
if(AIRSEG_RELATIVE_PATHS)
  target_compile_options(airseg_options INTERFACE "-ffile-prefix-map=${PROJECT_SOURCE_DIR}=.")
endif()
if(AIRSEG_SANITIZE)
  target_compile_options(airseg_options INTERFACE -fsanitize=${AIRSEG_SANITIZE} -fno-omit-frame-pointer)
  target_link_options(airseg_options INTERFACE -fsanitize=${AIRSEG_SANITIZE})
  if(AIRSEG_SANITIZE MATCHES "thread" AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # GCC 12 warns (-Wtsan) about atomic_thread_fence inside libstdc++ itself; not our code to fix.
    target_compile_options(airseg_options INTERFACE -Wno-tsan)
  endif()
endif()

# Test-only code (the test executables' own sources and the test support library) may be compiled at another
# optimisation level than the shipped code, e.g. -O1: CI's ARM package builds, where the test sources, heavy
# with GoogleTest and Boost.Asio templates, are two thirds of the compile time and -O1 costs 20-40 % less than
# -O2; and -O0 in CI's ASan+UBSan build, where clang compiles test code at -O0 in half the time of -O1 (GCC
# for ARM gains less than a fifth there, and its suites run the test code under qemu). The libraries and
# programs under test keep the build's flags (-O2 in the packages).
set(AIRSEG_TEST_OPTIMIZATION "" CACHE STRING "Extra optimisation flag for test-only code, e.g. -O1 (empty: the build's)")

# airseg_test_code(TARGET): the compile settings of test-only code. Besides AIRSEG_TEST_OPTIMIZATION: no libFuzzer
# coverage in it (nothing fuzzes a test; the libraries it links keep theirs for the fuzz targets), which is 16 %
# of a test batch's compile in the sanitizer build (autopilot_tests: 52.0 -> 43.8 CPU-s). An interface library
# linked last, so that its flags come after airseg_options' on the command line.
add_library(airseg_test_flags INTERFACE)
if(AIRSEG_TEST_OPTIMIZATION)
  target_compile_options(airseg_test_flags INTERFACE ${AIRSEG_TEST_OPTIMIZATION})
endif()
if(AIRSEG_SANITIZE MATCHES "fuzzer-no-link" AND CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  target_compile_options(airseg_test_flags INTERFACE -fno-sanitize=fuzzer-no-link)
endif()
# AIRSEG_TEST_UNITY_BATCH_SIZE: the unity batch size of test-only targets, e.g. 0 (each target one translation
# unit) in CI, where a test executable of 9 to 16 sources otherwise parses GoogleTest, Boost.Asio and fmt and
# instantiates their templates twice. Only test code: at -O2 one large translation unit of shipped code costs
# GCC more than the repeated headers save (docs/operations.md). Empty: the build's (8); a developer editing one
# test file recompiles a batch, not the whole executable.
set(AIRSEG_TEST_UNITY_BATCH_SIZE "" CACHE STRING "Unity batch size of test-only targets (0: one per target; empty: 8)")
function(airseg_test_code target)
  target_link_libraries(${target} PRIVATE airseg_test_flags)
  if(NOT AIRSEG_TEST_UNITY_BATCH_SIZE STREQUAL "")
    set_target_properties(${target} PROPERTIES UNITY_BUILD_BATCH_SIZE ${AIRSEG_TEST_UNITY_BATCH_SIZE})
  endif()
endfunction()

# airseg_add_library(NAME SOURCES... [LIBS ...])
function(airseg_add_library name)
  cmake_parse_arguments(A "" "" "SOURCES;LIBS" ${ARGN})
  add_library(${name} STATIC ${A_SOURCES})
  target_link_libraries(${name} PUBLIC airseg_options ${A_LIBS})
endfunction()

# airseg_add_test(NAME SOURCES... [LIBS ...] [LABELS ...] [TIMEOUT seconds] [RESOURCE_LOCK name]
#                  [ALONE gtest-filter])
# One GoogleTest executable whose cases ctest discovers one by one. The cases ALONE matches run with nothing
# else of the suite beside them (RUN_SERIAL, and the label "alone"): measurements of real-time pace, which a
# starved process spoils.
function(airseg_add_test name)
  cmake_parse_arguments(A "" "TIMEOUT;RESOURCE_LOCK;ALONE" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT AIRSEG_BUILD_TESTS)
    return()
  endif()
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 60)
  endif()
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE airseg_options GTest::gtest GTest::gtest_main GTest::gmock ${A_LIBS})
  airseg_test_code(${name})
  set(_lock)
  set(_labels ${A_LABELS})
  if(A_RESOURCE_LOCK)
    # Cases that must not run beside each other (they share a scarce resource, e.g. real-time radio links).
    # The lock's name is also a label: tools/run-ctest.sh runs such cases apart from the rest of the suite.
    set(_lock RESOURCE_LOCK ${A_RESOURCE_LOCK})
    list(APPEND _labels ${A_RESOURCE_LOCK})
  endif()
  # One label of the names joined by "/" (e.g. integration/simulated_rover_chains): gtest_discover_tests
  # (CMake 3.25) flattens PROPERTIES, so a list of labels would become property names.
  list(JOIN _labels "/" _labels)
  set(_properties TIMEOUT ${A_TIMEOUT} LABELS "${_labels}" ${_lock})
  if(A_ALONE)
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 TEST_FILTER "-${A_ALONE}"
                         PROPERTIES ${_properties})
    # Labelled ".../alone" too: tools/run-ctest.sh runs them with no other suite's cases beside them either.
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 TEST_FILTER "${A_ALONE}"
                         PROPERTIES TIMEOUT ${A_TIMEOUT} LABELS "${_labels}/alone" ${_lock} RUN_SERIAL TRUE)
  else()
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 PROPERTIES ${_properties})
  endif()
endfunction()
