# Finds Debian's ROS 1 bag library (librosbag-storage-dev) and the roscpp serialization core it
# needs, plus the sensor_msgs / nav_msgs headers, without catkin: the packages' catkin-generated
# CMake configs expect a ROS workspace, so plain find_path/find_library is simpler and enough here.
# rosbag/bag.h includes pluginlib, which Debian ships ROS 2 style under /usr/include/<pkg>/<pkg>/,
# so those five directories are found too.
#
# Defines:
#   RosbagStorage::RosbagStorage  imported library: rosbag_storage + roscpp_serialization + rostime
#                                 + cpp_common + console_bridge, and roslz4 + bz2 (the chunk
#                                 codecs, for checking chunks before rosbag reads them)
#   RosbagStorage_FOUND

find_path(RosbagStorage_INCLUDE_DIR rosbag/bag.h)
find_path(RosbagStorage_ROSCPP_INCLUDE_DIR ros/serialization.h)
find_path(RosbagStorage_SENSOR_MSGS_INCLUDE_DIR sensor_msgs/Image.h)
find_path(RosbagStorage_NAV_MSGS_INCLUDE_DIR nav_msgs/Odometry.h)
find_path(RosbagStorage_ROSLZ4_INCLUDE_DIR roslz4/lz4s.h)
find_path(RosbagStorage_BZ2_INCLUDE_DIR bzlib.h)
# <package>:<a header it has>, each found under its nested include directory.
set(_rosbag_nested
  pluginlib:pluginlib/class_loader.hpp
  class_loader:class_loader/multi_library_class_loader.hpp
  rcutils:rcutils/shared_library.h
  rcpputils:rcpputils/shared_library.hpp
  ament_index_cpp:ament_index_cpp/get_package_prefix.hpp)
set(_rosbag_nested_dirs)
foreach(_entry ${_rosbag_nested})
  string(REPLACE ":" ";" _entry "${_entry}")
  list(GET _entry 0 _pkg)
  list(GET _entry 1 _header)
  string(TOUPPER ${_pkg} _PKG)
  find_path(RosbagStorage_${_PKG}_INCLUDE_DIR ${_header} PATH_SUFFIXES ${_pkg})
  list(APPEND _rosbag_nested_dirs RosbagStorage_${_PKG}_INCLUDE_DIR)
endforeach()
find_library(RosbagStorage_LIBRARY rosbag_storage)
find_library(RosbagStorage_SERIALIZATION_LIBRARY roscpp_serialization)
find_library(RosbagStorage_ROSTIME_LIBRARY rostime)
find_library(RosbagStorage_CPP_COMMON_LIBRARY cpp_common)
find_library(RosbagStorage_CONSOLE_BRIDGE_LIBRARY console_bridge)
find_library(RosbagStorage_ROSLZ4_LIBRARY roslz4)
find_library(RosbagStorage_BZ2_LIBRARY bz2)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(RosbagStorage
  REQUIRED_VARS
    RosbagStorage_LIBRARY RosbagStorage_SERIALIZATION_LIBRARY RosbagStorage_ROSTIME_LIBRARY
    RosbagStorage_CPP_COMMON_LIBRARY RosbagStorage_CONSOLE_BRIDGE_LIBRARY
    RosbagStorage_ROSLZ4_LIBRARY RosbagStorage_BZ2_LIBRARY
    RosbagStorage_ROSLZ4_INCLUDE_DIR RosbagStorage_BZ2_INCLUDE_DIR
    RosbagStorage_INCLUDE_DIR RosbagStorage_ROSCPP_INCLUDE_DIR
    RosbagStorage_SENSOR_MSGS_INCLUDE_DIR RosbagStorage_NAV_MSGS_INCLUDE_DIR ${_rosbag_nested_dirs})

if(RosbagStorage_FOUND AND NOT TARGET RosbagStorage::RosbagStorage)
  set(_rosbag_incs ${RosbagStorage_INCLUDE_DIR} ${RosbagStorage_ROSCPP_INCLUDE_DIR}
    ${RosbagStorage_SENSOR_MSGS_INCLUDE_DIR} ${RosbagStorage_NAV_MSGS_INCLUDE_DIR}
    ${RosbagStorage_ROSLZ4_INCLUDE_DIR} ${RosbagStorage_BZ2_INCLUDE_DIR})
  foreach(_var ${_rosbag_nested_dirs})
    list(APPEND _rosbag_incs ${${_var}})
  endforeach()
  list(REMOVE_DUPLICATES _rosbag_incs)
  add_library(RosbagStorage::RosbagStorage UNKNOWN IMPORTED)
  set_target_properties(RosbagStorage::RosbagStorage PROPERTIES
    IMPORTED_LOCATION "${RosbagStorage_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${_rosbag_incs}"
    INTERFACE_LINK_LIBRARIES
      "${RosbagStorage_SERIALIZATION_LIBRARY};${RosbagStorage_ROSTIME_LIBRARY};${RosbagStorage_CPP_COMMON_LIBRARY};${RosbagStorage_CONSOLE_BRIDGE_LIBRARY};${RosbagStorage_ROSLZ4_LIBRARY};${RosbagStorage_BZ2_LIBRARY}")
endif()
mark_as_advanced(
  RosbagStorage_INCLUDE_DIR RosbagStorage_ROSCPP_INCLUDE_DIR RosbagStorage_SENSOR_MSGS_INCLUDE_DIR
  RosbagStorage_NAV_MSGS_INCLUDE_DIR RosbagStorage_LIBRARY RosbagStorage_SERIALIZATION_LIBRARY
  RosbagStorage_ROSTIME_LIBRARY RosbagStorage_CPP_COMMON_LIBRARY RosbagStorage_CONSOLE_BRIDGE_LIBRARY
  RosbagStorage_ROSLZ4_LIBRARY RosbagStorage_BZ2_LIBRARY RosbagStorage_ROSLZ4_INCLUDE_DIR RosbagStorage_BZ2_INCLUDE_DIR
  ${_rosbag_nested_dirs})
