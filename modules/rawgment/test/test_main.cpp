// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include <gtest/gtest.h>

int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
