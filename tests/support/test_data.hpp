// Where the shared real test data lives: $AVATARMAP_TEST_DATA (../shared/data in CI).
#pragma once

#include <string>

namespace avatarmap::test {

/// The data folder, or "" when AVATARMAP_TEST_DATA is unset or empty.
std::string test_data_dir();

/// $AVATARMAP_TEST_DATA/relative, or "" when the variable is unset.
std::string test_data_path(const std::string& relative);

/// Message for GTEST_SKIP() when the data folder is not set.
inline const char* k_no_test_data =
    "AVATARMAP_TEST_DATA is not set: point it at the shared data folder (../shared/data) "
    "to run this test on real data";

}  // namespace avatarmap::test
