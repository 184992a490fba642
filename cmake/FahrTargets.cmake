# Helpers that give every fahr target the same warnings, sanitizers and
# namespaced alias, so the folder CMakeLists stay a few lines each.

# Warnings apply to fahr's own code only; generated bindings get none.
function(fahr_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
      -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wnull-dereference>)
  if(FAHR_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

function(fahr_sanitize target)
  if(FAHR_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
    target_compile_definitions(${target} PRIVATE FAHR_SANITIZE_BUILD)
  endif()
endfunction()

# fahr_library(<name> [STATIC] SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# Creates fahr_<name> with alias fahr::<name>; headers live in include/ of the
# folder (include/fahr/<namespace>/). STATIC forces a static archive whatever
# BUILD_SHARED_LIBS says: a service's core, linked into its own main and into
# the tests and tools that step it in one process.
function(fahr_library name)
  cmake_parse_arguments(ARG "STATIC" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  if(ARG_STATIC)
    add_library(fahr_${name} STATIC ${ARG_SOURCES})
  else()
    add_library(fahr_${name} ${ARG_SOURCES})
  endif()
  add_library(fahr::${name} ALIAS fahr_${name})
  set_target_properties(fahr_${name} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(fahr_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(fahr_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  fahr_warnings(fahr_${name})
  fahr_sanitize(fahr_${name})
  install(TARGETS fahr_${name} EXPORT fahrTargets)
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# fahr_executable(<name> SOURCES ... [DEPS ...])
function(fahr_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  fahr_warnings(${name})
  fahr_sanitize(${name})
endfunction()

# fahr_test(<name> SOURCES ... [DEPS ...] [LABELS ...] [TIMEOUT s] [SHARDS n]
#           [ENVIRONMENT ...])
# A GoogleTest executable registered with CTest, one CTest entry per binary so
# multi-process tests keep their own process tree. SHARDS n > 1 registers n
# entries <name>_0 .. <name>_<n-1>, each running its share of the tests
# (GoogleTest's GTEST_TOTAL_SHARDS / GTEST_SHARD_INDEX), so ctest -j runs a
# long suite on several cores.
function(fahr_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT;SHARDS" "SOURCES;DEPS;LABELS;ENVIRONMENT" ${ARGN})
  fahr_executable(${name} SOURCES ${ARG_SOURCES} DEPS ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  if(NOT ARG_SHARDS OR ARG_SHARDS LESS 2)
    add_test(NAME ${name} COMMAND ${name})
    set_tests_properties(${name} PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}")
    if(ARG_ENVIRONMENT)
      set_tests_properties(${name} PROPERTIES ENVIRONMENT "${ARG_ENVIRONMENT}")
    endif()
    return()
  endif()
  math(EXPR last "${ARG_SHARDS} - 1")
  foreach(shard RANGE ${last})
    add_test(NAME ${name}_${shard} COMMAND ${name})
    set_tests_properties(${name}_${shard} PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}"
      ENVIRONMENT "GTEST_TOTAL_SHARDS=${ARG_SHARDS};GTEST_SHARD_INDEX=${shard};${ARG_ENVIRONMENT}")
  endforeach()
endfunction()
