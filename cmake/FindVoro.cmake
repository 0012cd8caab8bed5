# voro++ 0.4.6 (Debian: voro++-dev) ships no CMake config.
find_path(VORO_INCLUDE_DIR voro++.hh PATH_SUFFIXES voro++ REQUIRED)
find_library(VORO_LIBRARY voro++ REQUIRED)
add_library(tp_voro INTERFACE)
target_include_directories(tp_voro SYSTEM INTERFACE ${VORO_INCLUDE_DIR})
target_link_libraries(tp_voro INTERFACE ${VORO_LIBRARY})
message(STATUS "voro++: ${VORO_LIBRARY}")
