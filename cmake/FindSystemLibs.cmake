# Libraries Debian ships without a CMake or pkg-config file.

# mrcal 2.2: headers in <mrcal/...>, no extern "C" guards (see
# calib/core/mrcal_c.h), link -lmrcal.
find_path(MRCAL_INCLUDE_DIR mrcal/mrcal.h REQUIRED)
find_library(MRCAL_LIBRARY mrcal REQUIRED)
add_library(mrcal::mrcal UNKNOWN IMPORTED)
set_target_properties(mrcal::mrcal PROPERTIES
  IMPORTED_LOCATION "${MRCAL_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${MRCAL_INCLUDE_DIR}/mrcal;${MRCAL_INCLUDE_DIR}")

# AprilTag 3: -lapriltag -lapriltag-utils.
find_path(APRILTAG_INCLUDE_DIR apriltag/apriltag.h REQUIRED)
find_library(APRILTAG_LIBRARY apriltag REQUIRED)
find_library(APRILTAG_UTILS_LIBRARY apriltag-utils)
add_library(apriltag::apriltag UNKNOWN IMPORTED)
set_target_properties(apriltag::apriltag PROPERTIES
  IMPORTED_LOCATION "${APRILTAG_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${APRILTAG_INCLUDE_DIR}")
if(APRILTAG_UTILS_LIBRARY)
  set_property(TARGET apriltag::apriltag APPEND PROPERTY INTERFACE_LINK_LIBRARIES "${APRILTAG_UTILS_LIBRARY}")
endif()

# CHOLMOD (SuiteSparse), for mrcal's projection uncertainty.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
add_library(suitesparse::cholmod UNKNOWN IMPORTED)
set_target_properties(suitesparse::cholmod PROPERTIES
  IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}")
