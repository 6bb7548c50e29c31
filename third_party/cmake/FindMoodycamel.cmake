# Finds Debian's header-only moodycamel queues:
#   libreaderwriterqueue-dev (SPSC BlockingReaderWriterCircularBuffer) and
#   libconcurrentqueue-dev  (MPMC ConcurrentQueue, LightweightSemaphore).
# Defines the interface target Moodycamel::queues; include as <readerwritercircularbuffer.h>
# and <concurrentqueue/blockingconcurrentqueue.h>.

find_path(MOODYCAMEL_RWQ_INCLUDE_DIR readerwritercircularbuffer.h PATH_SUFFIXES readerwriterqueue)
find_path(MOODYCAMEL_CQ_INCLUDE_DIR concurrentqueue/blockingconcurrentqueue.h)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Moodycamel REQUIRED_VARS MOODYCAMEL_RWQ_INCLUDE_DIR MOODYCAMEL_CQ_INCLUDE_DIR)

if(Moodycamel_FOUND AND NOT TARGET Moodycamel::queues)
  add_library(Moodycamel::queues INTERFACE IMPORTED)
  set_target_properties(Moodycamel::queues PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${MOODYCAMEL_RWQ_INCLUDE_DIR};${MOODYCAMEL_CQ_INCLUDE_DIR}")
endif()
mark_as_advanced(MOODYCAMEL_RWQ_INCLUDE_DIR MOODYCAMEL_CQ_INCLUDE_DIR)
