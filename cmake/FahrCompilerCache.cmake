# Use ccache when present: rebuilds after a branch switch or a clean CI cache
# directory then cost seconds, not minutes, on a 2-core machine.
find_program(FAHR_CCACHE ccache)
if(FAHR_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_C_COMPILER_LAUNCHER ${FAHR_CCACHE})
  set(CMAKE_CXX_COMPILER_LAUNCHER ${FAHR_CCACHE})
endif()
