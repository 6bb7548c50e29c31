#pragma once
// Catch2 for tests that use Ceres. Ceres pulls in glog, whose CHECK macro (abort on failure) would replace
// Catch's CHECK if glog came second, or be redefined by it silently in a system header if it came first.
// Include Ceres (and so glog) first, drop glog's CHECK, then Catch: CHECK is Catch's from here on, and the
// include guards keep glog from defining it again.
#include <ceres/ceres.h>
#undef CHECK
#include <catch2/catch.hpp>
