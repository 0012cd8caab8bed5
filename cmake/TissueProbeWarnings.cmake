# Warnings as an INTERFACE target that every project target links PRIVATE.
add_library(tp_warnings INTERFACE)
target_compile_options(tp_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor)
