// The synthetic campaign's trials (campaign.h) without rendering them: the layout, the
// hidden tension and the trials' spread around it, the procedure the report must simulate.
#include "liftoff/synth/campaign.h"

#include <cmath>
#include <numbers>
#include <set>

#include <gtest/gtest.h>

#include "liftoff/core/calibration.h"
#include "liftoff/fit/tension_fit.h"
#include "support/test_support.h"

namespace liftoff::synth {
namespace {

Calibration Laika2018() {
  auto calibration = LoadCalibration(liftoff::testing::SourceDir() / "calib" / "laika-2018.json");
  EXPECT_TRUE(calibration.ok()) << calibration.status().ToString();
  return *calibration;
}

TEST(Campaign, TwentyTrialsFivePerFootOnTheFastRampAsDocumented) {
  const CampaignOptions options;
  EXPECT_EQ(options.trials_per_foot, 5);
  EXPECT_DOUBLE_EQ(options.tension_sigma, 0.7);
  EXPECT_DOUBLE_EQ(options.stiffness_sd_scale, 0.25);
  EXPECT_EQ(CampaignReportFlags(options), "--ramp-s 7");
  auto specs = CampaignSpecs(Laika2018(), options);
  ASSERT_TRUE(specs.ok()) << specs.status().ToString();
  ASSERT_EQ(specs->size(), 20u);
  std::set<std::string> ids;
  for (size_t i = 0; i < specs->size(); ++i) {
    const Trial3dSpec& spec = (*specs)[i];
    SCOPED_TRACE(spec.id);
    EXPECT_TRUE(spec.Validate().ok()) << spec.Validate().ToString();
    EXPECT_EQ(spec.foot, kAllFeet[i / 5]);
    EXPECT_EQ(spec.id, std::string(FootName(spec.foot)) + std::to_string(i % 5 + 1));
    ids.insert(spec.id);
    EXPECT_EQ(spec.scene.width_px, 480);
    EXPECT_EQ(spec.scene.height_px, 360);
    EXPECT_EQ(spec.codec, VideoCodec::kFfv1);
    EXPECT_DOUBLE_EQ(spec.theta_rate_rad_s, (std::numbers::pi / 3) / 7);
    EXPECT_GE(spec.led_on_s, 0.8);
    EXPECT_LE(spec.led_on_s, 1.2);
    EXPECT_GE(spec.scene.camera_distance_m, 0.66);
    EXPECT_LE(spec.scene.camera_distance_m, 0.76);
    EXPECT_GE(spec.scene.camera_height_m, 0.32);
    EXPECT_LE(spec.scene.camera_height_m, 0.40);
    EXPECT_GE(spec.noise_sigma, 0.0);
    EXPECT_LE(spec.noise_sigma, 2.0);
    EXPECT_DOUBLE_EQ(spec.after_lift_s, 0.25);
    const bool alternate = spec.foot == Foot::kA || spec.foot == Foot::kC;
    EXPECT_EQ(spec.scene.view, spec.foot == Foot::kB || (alternate && i % 2 == 1)
                                   ? CameraView::kOblique
                                   : CameraView::kSide);
    ASSERT_TRUE(spec.tension.has_value());
    EXPECT_EQ(spec.tension->name, "campaign-" + spec.id);
  }
  EXPECT_EQ(ids.size(), 20u);
}

// The trials' stiffnesses scatter around the hidden point on the calibration's line, none
// of them on it, with a quarter of Table I's standard deviations (silicone 11 N/m, Buna-N
// 132 N/m; the spring has none).
TEST(Campaign, StiffnessesScatterAroundTheHiddenTension) {
  const Calibration calibration = Laika2018();
  const CampaignOptions options;
  const TensionPoint hidden = fit::TensionAtSigma(calibration.tension_points, 0.7, "hidden");
  EXPECT_NEAR(hidden.silicone_n_per_m, 244.7, 1e-9);
  EXPECT_NEAR(hidden.buna_n_n_per_m, 901.7, 1e-9);
  auto specs = CampaignSpecs(calibration, options);
  ASSERT_TRUE(specs.ok()) << specs.status().ToString();
  double silicone_sum = 0, buna_sum = 0, silicone_sq = 0, buna_sq = 0;
  for (const Trial3dSpec& spec : *specs) {
    const double ds = spec.tension->silicone_n_per_m - hidden.silicone_n_per_m;
    const double db = spec.tension->buna_n_n_per_m - hidden.buna_n_n_per_m;
    EXPECT_NE(ds, 0.0) << spec.id;
    EXPECT_DOUBLE_EQ(spec.tension->spring_n_per_m, hidden.spring_n_per_m) << spec.id;
    silicone_sum += ds;
    buna_sum += db;
    silicone_sq += ds * ds;
    buna_sq += db * db;
  }
  const double n = static_cast<double>(specs->size());
  // 20 draws: the sample SD within 40 % of 0.25 x Table I's, the mean within 1 SD / sqrt(n) x 3
  EXPECT_NEAR(std::sqrt(silicone_sq / n), 0.25 * 11, 0.4 * 0.25 * 11);
  EXPECT_NEAR(std::sqrt(buna_sq / n), 0.25 * 132, 0.4 * 0.25 * 132);
  EXPECT_LT(std::abs(silicone_sum / n), 3 * 0.25 * 11 / std::sqrt(n));
  EXPECT_LT(std::abs(buna_sum / n), 3 * 0.25 * 132 / std::sqrt(n));
  // seeded: the same trials again
  auto again = CampaignSpecs(calibration, options);
  ASSERT_TRUE(again.ok());
  EXPECT_DOUBLE_EQ((*again)[7].tension->buna_n_n_per_m, (*specs)[7].tension->buna_n_n_per_m);
  EXPECT_DOUBLE_EQ((*again)[7].led_on_s, (*specs)[7].led_on_s);
}

TEST(Campaign, RefusesBadOptions) {
  CampaignOptions options;
  options.trials_per_foot = 0;
  EXPECT_NE(options.Validate().message().find("trials_per_foot"), std::string::npos);
  options = {};
  options.tension_sigma = 5;
  EXPECT_NE(options.Validate().message().find("tension_sigma"), std::string::npos);
  options = {};
  options.width_px = 100;
  EXPECT_FALSE(options.Validate().ok());
  Calibration one_point = Laika2018();
  one_point.tension_points.resize(1);
  EXPECT_FALSE(CampaignSpecs(one_point, {}).ok());
}

}  // namespace
}  // namespace liftoff::synth
