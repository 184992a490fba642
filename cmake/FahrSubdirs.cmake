# fahr_add_subdirectories(): add every direct subfolder that has a
# CMakeLists.txt, in name order, so adding a library, test group or tool is
# one new folder and no edit to a shared list.
# -DFAHR_ONLY="common;geometry" restricts the build to folders of those
# names (in libs/, services/, sim/, bench/, tests/ and tools/), for working
# on one part alone.
set(FAHR_ONLY "" CACHE STRING "Only add subfolders with these names (empty: all)")
function(fahr_add_subdirectories)
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT children)
  foreach(child ${children})
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${child} AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${child}/CMakeLists.txt)
      # "support" folders hold helpers other folders use: always added.
      if(FAHR_ONLY AND NOT child IN_LIST FAHR_ONLY AND NOT child STREQUAL "support")
        continue()
      endif()
      add_subdirectory(${child})
    endif()
  endforeach()
endfunction()
