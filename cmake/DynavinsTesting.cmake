# dynavins_add_test(NAME <exe> SOURCES <files...> LIBS <targets...> [LABELS <labels...>])
# One Catch2 executable per area (one test file per class inside it), registered with CTest
# test-case by test-case so `ctest -R` and `ctest -j` work at the granularity of a TEST_CASE.
function(dynavins_add_test)
  if(NOT DYNAVINS_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(T "" "NAME" "SOURCES;LIBS;LABELS" ${ARGN})
  # Heavy tests (long single-threaded renders) are not even built where they would not run (TSan pass).
  if("heavy" IN_LIST T_LABELS AND NOT DYNAVINS_HEAVY_TESTS)
    return()
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE dynavins_catch_main ${T_LIBS})
  target_compile_definitions(${T_NAME} PRIVATE
    DYNAVINS_SOURCE_DIR="${CMAKE_SOURCE_DIR}"
    DYNAVINS_SHARED_DIR="${CMAKE_SOURCE_DIR}/../shared")
  # A hang fails the test instead of stalling CI; ThreadSanitizer builds run ~10x slower.
  catch_discover_tests(${T_NAME} TEST_PREFIX "${T_NAME}: " PROPERTIES LABELS "${T_LABELS}" TIMEOUT 600)
endfunction()
