// The discretisation self-check: a paired subsample at dt and dt/2, each headline statistic's
// difference with a bootstrap standard error, and the verdict.

#include "ensemble/self_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "tests/ensemble/fixtures.hpp"

namespace talus::ensemble {
namespace {

// 60 rocks of a 0.4 m cube, uniformly oriented, released 1 m above a 35 deg, 40 m slope with a
// 30 m runout, stopped after 8 s.
struct Checked {
  SelfCheckReport report;
  SolverOptions after;
};
Checked CheckAt(double dt_s) {
  Scene scene = testing::SmallPlane(45, 60, 60);
  scene.options.max_time_s = 15;
  scene.options.dt_s = dt_s;
  ReleaseSpec release = testing::PointRelease({{5, 0}}, 60);
  release.height_m = 1.0;
  SelfCheckOptions options;
  options.rocks = 60;
  options.threads = 2;
  Checked c;
  c.report = RunSelfCheck(scene, release, options);
  c.after = scene.options;
  std::printf("dt %g s:\n%s", dt_s, c.report.BriefReport().c_str());
  return c;
}

TEST(SelfCheck, ACoarseStepIsReportedAsBiasedAndTheDefaultAsConverged) {
  // At 50 ms (25 x the default) a 0.4 m cube moves up to its own size per step: the run-outs of
  // the subsample differ from those at 25 ms by far more than their paired standard error; at the
  // default 2 ms no statistic differs beyond two standard errors from 1 ms.
  const Checked coarse = CheckAt(0.05);
  EXPECT_FALSE(coarse.report.converged);
  EXPECT_NE(coarse.report.Verdict().find("use --preset accurate"), std::string::npos)
      << coarse.report.Verdict();
  EXPECT_EQ(coarse.report.refined_dt_s, 0.025);
  EXPECT_NEAR(coarse.report.threshold, 2.5758, 1e-4);  // z of 0.01 two-sided (5 % / 5)
  EXPECT_EQ(coarse.after.dt_s, 0.05);  // the scene's options are restored
  const Checked fine = CheckAt(SolverOptions{}.dt_s);
  EXPECT_TRUE(fine.report.converged) << fine.report.BriefReport();
  EXPECT_EQ(fine.report.Verdict().rfind("converged within the sampling noise", 0), 0u);
  EXPECT_EQ(fine.after.tolerance_m_s, SolverOptions{}.tolerance_m_s);
  for (const SelfCheckStatistic& s : fine.report.statistics) {
    EXPECT_TRUE(std::isfinite(s.difference)) << s.name;
    EXPECT_GE(s.standard_error, 0) << s.name;
  }
}

TEST(SelfCheck, OptionsAreCheckedByName) {
  SelfCheckOptions options;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));  // rocks = 0
  options.rocks = 10;
  EXPECT_TRUE(options.IsValid(&why)) << why;
  options.dt_divisor = 1;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("dt_divisor"), std::string::npos) << why;
}

}  // namespace
}  // namespace talus::ensemble
