// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#ifdef RAWGMENT_OPENCV_TEST_FRAMEWORK
CV_TEST_MAIN("rawgment")
#else
int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
#endif
