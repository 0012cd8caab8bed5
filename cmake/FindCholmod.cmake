# CHOLMOD from SuiteSparse (Debian: libsuitesparse-dev) and METIS, linked against the system BLAS (OpenBLAS).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
find_library(SUITESPARSE_CONFIG_LIBRARY suitesparseconfig REQUIRED)
# METIS (Debian: libmetis-dev), which CHOLMOD also uses: the solver orders the vertices' graph
# with it directly (solver/CholmodSolver.cpp).
find_path(METIS_INCLUDE_DIR metis.h REQUIRED)
find_library(METIS_LIBRARY metis REQUIRED)
add_library(tp_cholmod INTERFACE)
target_include_directories(tp_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR} ${METIS_INCLUDE_DIR})
# BLAS and LAPACK themselves (Debian: libopenblas-dev through the alternatives): the solver's
# single-precision factorisation calls them directly (solver/CholmodSolver.cpp).
find_package(BLAS REQUIRED)
find_package(LAPACK REQUIRED)
target_link_libraries(tp_cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSE_CONFIG_LIBRARY}
                      ${METIS_LIBRARY} LAPACK::LAPACK BLAS::BLAS)
message(STATUS "CHOLMOD: ${CHOLMOD_LIBRARY}")
