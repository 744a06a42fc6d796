// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "perf_precomp.hpp"

CV_PERF_TEST_MAIN(rawgment)
