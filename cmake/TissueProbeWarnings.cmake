# Warnings as an INTERFACE target that every project target links PRIVATE (gcc, or clang for
# the sanitizer and fuzzing build).
add_library(tp_warnings INTERFACE)
target_compile_options(tp_warnings INTERFACE -Wall -Wextra -Wpedantic -Wnon-virtual-dtor
  $<$<CXX_COMPILER_ID:GNU>:-Wshadow=local> $<$<CXX_COMPILER_ID:Clang>:-Wshadow-uncaptured-local>)
