# FindSuiteSparse: Debian's libsuitesparse-dev ships neither a CMake config nor pkg-config files.
# Defines SuiteSparse_FOUND and the imported target SuiteSparse::KLU (klu + amd + colamd + btf + config).
find_path(SuiteSparse_INCLUDE_DIR klu.h PATH_SUFFIXES suitesparse)
foreach(lib klu amd colamd btf suitesparseconfig)
  find_library(SuiteSparse_${lib}_LIBRARY NAMES ${lib})
  list(APPEND _ss_libs SuiteSparse_${lib}_LIBRARY)
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparse REQUIRED_VARS SuiteSparse_INCLUDE_DIR ${_ss_libs})
if(SuiteSparse_FOUND AND NOT TARGET SuiteSparse::KLU)
  add_library(SuiteSparse::KLU INTERFACE IMPORTED)
  set_target_properties(SuiteSparse::KLU PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${SuiteSparse_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${SuiteSparse_klu_LIBRARY};${SuiteSparse_amd_LIBRARY};${SuiteSparse_colamd_LIBRARY};${SuiteSparse_btf_LIBRARY};${SuiteSparse_suitesparseconfig_LIBRARY}")
endif()
mark_as_advanced(SuiteSparse_INCLUDE_DIR ${_ss_libs})
