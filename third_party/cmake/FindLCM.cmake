# Finds Debian's LCM (liblcm-dev, liblcm-bin, liblcm-java) without going through lcm.pc,
# whose `Requires: glib-2.0 gthread-2.0` would drag glib's pkg-config files into every consumer.
#
# Defines:
#   LCM::lcm            imported library (C and C++ API)
#   LCM_GEN_EXECUTABLE  lcm-gen
#   LCM_JAR             lcm.jar (Java bindings, for lcm-spy), if installed
#   LCM_FOUND

find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp)
find_library(LCM_LIBRARY lcm)
find_program(LCM_GEN_EXECUTABLE lcm-gen)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LCM REQUIRED_VARS LCM_LIBRARY LCM_INCLUDE_DIR LCM_GEN_EXECUTABLE)

if(LCM_FOUND AND NOT TARGET LCM::lcm)
  add_library(LCM::lcm UNKNOWN IMPORTED)
  set_target_properties(LCM::lcm PROPERTIES
    IMPORTED_LOCATION "${LCM_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LCM_INCLUDE_DIR}")
endif()
mark_as_advanced(LCM_INCLUDE_DIR LCM_LIBRARY LCM_GEN_EXECUTABLE LCM_JAR)
