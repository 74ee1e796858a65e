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
  set(_lock)
  if(_t_RESOURCE_LOCK)
    set(_lock RESOURCE_LOCK ${_t_RESOURCE_LOCK})
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES ENVIRONMENT "EGRESS_REFERENCE_DIR=${EGRESS_REFERENCE_DIR}" ${_lock})
endfunction()

# egress_path_definitions(<source>... DEFINITIONS <NAME="path">...): definitions that hold this
# checkout's absolute paths go on the files that use them, never on a whole target. ccache
# (CCACHE_BASEDIR, set by egress.sh) then shares every other object with a checkout in another
# folder: CI's clean clone builds from the cache the developer's builds filled, instead of
# compiling three configurations from nothing.
function(egress_path_definitions)
  cmake_parse_arguments(_p "" "" "DEFINITIONS" ${ARGN})
  set_property(SOURCE ${_p_UNPARSED_ARGUMENTS} APPEND PROPERTY COMPILE_DEFINITIONS
               ${_p_DEFINITIONS})
endfunction()
