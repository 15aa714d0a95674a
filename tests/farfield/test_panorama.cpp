// Tests arrive with this module's work.
#include <gtest/gtest.h>
