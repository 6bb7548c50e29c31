# find_package(dynavins) for programs that subscribe to DynaVINS' LCM outputs (or feed it sensors):
#   dynavins::lcm_types   the generated C++ message types (dynavins_lcm/pose_t.hpp, ...) and LCM itself
# Channel names and message fields are listed in the project's README ("LCM interface").
include(CMakeFindDependencyMacro)
list(APPEND CMAKE_MODULE_PATH ${CMAKE_CURRENT_LIST_DIR})  # FindLCM.cmake, installed beside this file
find_dependency(LCM)
include(${CMAKE_CURRENT_LIST_DIR}/dynavinsTargets.cmake)
