# Helpers that give every liftoff target the same shape.

# Warnings on, clean: -Wall -Wextra -Wpedantic (and -Werror with LIFTOFF_WERROR).
function(liftoff_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
    -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual
    -Wconversion -Wsign-conversion -Wnull-dereference -Wdouble-promotion)
  if(LIFTOFF_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(LIFTOFF_SANITIZE)
    # undefined behaviour fails the test that meets it (not only a printed message)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined
      -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # GCC 12 with -fsanitize warns inside libstdc++'s std::regex (a false positive)
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
  endif()
endfunction()

# liftoff_add_module(NAME SOURCES ... DEPS ... PRIVATE_DEPS ...)
# Makes the library liftoff_<name> with the alias liftoff::<name>.
function(liftoff_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(liftoff_${name} ${ARG_SOURCES})
  add_library(liftoff::${name} ALIAS liftoff_${name})
  target_include_directories(liftoff_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(liftoff_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  liftoff_set_warnings(liftoff_${name})
endfunction()

# liftoff_add_test(NAME SOURCES ... DEPS ... [RESOURCE_LOCK name] [FIXTURE name] [ONE_PROCESS]):
# one GoogleTest executable per module.
# Tests sharing a RESOURCE_LOCK never run at the same time under `ctest -j`
# (pseudo-terminal numbers are reused across processes); FIXTURE names a CTest fixture
# every test of the executable requires (its setup runs once per ctest run). ONE_PROCESS
# registers the executable as one ctest test instead of one per GoogleTest test (a
# GTEST_SKIP inside it then shows as passed).
function(liftoff_add_test name)
  cmake_parse_arguments(ARG "ONE_PROCESS" "RESOURCE_LOCK;FIXTURE" "SOURCES;DEPS" ${ARGN})
  set(extra_properties "")
  if(ARG_RESOURCE_LOCK)
    list(APPEND extra_properties RESOURCE_LOCK ${ARG_RESOURCE_LOCK})
  endif()
  if(ARG_FIXTURE)
    list(APPEND extra_properties FIXTURES_REQUIRED ${ARG_FIXTURE})
  endif()
  add_executable(${name}_test ${ARG_SOURCES})
  target_link_libraries(${name}_test PRIVATE ${ARG_DEPS} liftoff_test_support GTest::gtest_main GTest::gmock)
  liftoff_set_warnings(${name}_test)
  if(ARG_ONE_PROCESS)
    # one ctest test for the whole executable: its tests share one costly analysis (a
    # function-local static), which one process per test would repeat for each
    add_test(NAME ${name} COMMAND ${name}_test WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(${name} PROPERTIES
      ENVIRONMENT "LIFTOFF_SOURCE_DIR=${PROJECT_SOURCE_DIR}" ${extra_properties})
  else()
    gtest_discover_tests(${name}_test
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
      PROPERTIES ENVIRONMENT "LIFTOFF_SOURCE_DIR=${PROJECT_SOURCE_DIR}" ${extra_properties}
      DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
