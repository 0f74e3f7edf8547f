#include "common/closest_name.hpp"

#include <gtest/gtest.h>

namespace talus {
namespace {

TEST(ClosestName, OnlySuggestsCloseNames) {
  EXPECT_EQ(ClosestName("sead", {"seed", "rocks"}), "seed");
  EXPECT_EQ(ClosestName("trajectory", {"trajectories", "rasters"}), "trajectories");
  EXPECT_EQ(ClosestName("xyz", {"seed", "rocks"}), "");
}

}  // namespace
}  // namespace talus
