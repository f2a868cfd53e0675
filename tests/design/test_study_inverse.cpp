// placeholder, replaced below
#include <gtest/gtest.h>
TEST(StudyInverse, Placeholder) {}
