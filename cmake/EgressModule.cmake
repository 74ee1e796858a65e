# Helpers shared by the module CMakeLists: warnings, sanitizers and the per-module library target.
include_guard(GLOBAL)

add_library(egress_warnings INTERFACE)
target_compile_options(egress_warnings INTERFACE -Wall -Wextra -Wpedantic
                       $<$<BOOL:${EGRESS_WERROR}>:-Werror>)

# egress_module(<name> SOURCES ... PUBLIC_DEPS ... PRIVATE_DEPS ...)
# Creates the library `egress_<name>` with alias `egress::<name>`, public headers under
# <name>/include/egress/<name>/.
function(egress_module name)
  cmake_parse_arguments(_m "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(egress_${name} ${_m_SOURCES})
  add_library(egress::${name} ALIAS egress_${name})
  target_include_directories(egress_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
  target_compile_features(egress_${name} PUBLIC cxx_std_20)
  target_link_libraries(egress_${name} PUBLIC ${_m_PUBLIC_DEPS} PRIVATE ${_m_PRIVATE_DEPS}
                        egress_warnings)
endfunction()

# egress_add_test(<name> SOURCES ... DEPS ...): one GoogleTest executable, registered with ctest.
# RESOURCE_LOCK: ctest runs no two tests holding the same lock at once.
function(egress_add_test name)
  cmake_parse_arguments(_t "" "RESOURCE_LOCK" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${_t_SOURCES})
  target_link_libraries(${name} PRIVATE ${_t_DEPS} GTest::gtest GTest::gmock GTest::gtest_main
                        egress_warnings)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_compile_definitions(${name} PRIVATE EGRESS_OFFICE_MAP="${EGRESS_OFFICE_MAP}")
  set(_lock)
  if(_t_RESOURCE_LOCK)
    set(_lock RESOURCE_LOCK ${_t_RESOURCE_LOCK})
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES ENVIRONMENT "EGRESS_REFERENCE_DIR=${EGRESS_REFERENCE_DIR}" ${_lock})
endfunction()
