#include "liftoff/synth/campaign.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <nlohmann/json.hpp>

#include "liftoff/core/file.h"
#include "liftoff/core/random.h"
#include "liftoff/core/robot.h"
#include "liftoff/fit/tension_fit.h"

namespace liftoff::synth {
namespace {

using nlohmann::json;

constexpr double kRampAngleRad = std::numbers::pi / 3;  // the simulation's 60 degrees
constexpr uint64_t kCameraStream = 0xC0FFEE0000000001ull;

Status OutOfRange(const char* field, double value, double low, double high) {
  char message[160];
  std::snprintf(message, sizeof message, "campaign: %s: expected a number in [%g, %g], got %g",
                field, low, high, value);
  return InvalidArgumentError(message);
}

// Each trial's offset from the hidden point: its Monte Carlo draw's offset from the
// materials' means, less the mean offset of its foot's trials, so that every foot's trials
// average to the hidden point exactly (a few random draws would otherwise move the
// campaign's own tension away from the one it is said to hide). Draws come per foot in
// runs of `per_foot`.
std::vector<TensionPoint> CentredOffsets(const std::vector<TensionPoint>& draws,
                                         const Calibration& calibration, int per_foot) {
  const auto mean = [&](const char* material) {
    return calibration.FindMaterial(material)->stiffness_n_per_m;
  };
  std::vector<TensionPoint> offsets;
  for (const TensionPoint& draw : draws) {
    TensionPoint& offset = offsets.emplace_back();
    offset.silicone_n_per_m = draw.silicone_n_per_m - mean("silicone");
    offset.buna_n_n_per_m = draw.buna_n_n_per_m - mean("buna_n");
    offset.spring_n_per_m = draw.spring_n_per_m - mean("spring");
  }
  for (size_t first = 0; first < offsets.size(); first += static_cast<size_t>(per_foot)) {
    const size_t last = std::min(offsets.size(), first + static_cast<size_t>(per_foot));
    TensionPoint centre;
    for (size_t i = first; i < last; ++i) {
      centre.silicone_n_per_m += offsets[i].silicone_n_per_m / static_cast<double>(last - first);
      centre.buna_n_n_per_m += offsets[i].buna_n_n_per_m / static_cast<double>(last - first);
      centre.spring_n_per_m += offsets[i].spring_n_per_m / static_cast<double>(last - first);
    }
    for (size_t i = first; i < last; ++i) {
      offsets[i].silicone_n_per_m -= centre.silicone_n_per_m;
      offsets[i].buna_n_n_per_m -= centre.buna_n_n_per_m;
      offsets[i].spring_n_per_m -= centre.spring_n_per_m;
    }
  }
  return offsets;
}

// the hidden point plus the trial's offset
TensionPoint TrialTension(const TensionPoint& hidden, const TensionPoint& offset,
                          const std::string& name) {
  TensionPoint point = hidden;
  point.name = name;
  point.silicone_n_per_m += offset.silicone_n_per_m;
  point.buna_n_n_per_m += offset.buna_n_n_per_m;
  point.spring_n_per_m += offset.spring_n_per_m;
  return point;
}

// the camera and clip of trial `k` of a foot, drawn from `random`: feet A and C face the
// side camera, alternately side and oblique views; B is seen obliquely, D from the side
void VaryCamera(Trial3dSpec& spec, int k, SplitMix64& random) {
  Scene3dOptions& scene = spec.scene;
  const bool alternate = spec.foot == Foot::kA || spec.foot == Foot::kC;
  scene.view = spec.foot == Foot::kB || (alternate && k % 2 == 1) ? CameraView::kOblique
                                                                  : CameraView::kSide;
  scene.camera_distance_m = 0.66 + 0.10 * random.Uniform();
  scene.camera_height_m = 0.32 + 0.08 * random.Uniform();
  scene.light_elevation_deg = 35 + 40 * random.Uniform();
  scene.light_azimuth_deg = -150 + 120 * random.Uniform();
  scene.light_level = 0.8 + 0.4 * random.Uniform();
  scene.clutter_count = static_cast<int>(random.Next() % 7);
  spec.led_on_s = 0.8 + 0.4 * random.Uniform();
  spec.noise_sigma = 2.0 * random.Uniform();
}

json TensionJson(const TensionPoint& point) {
  return {{"name", point.name},
          {"sigma", point.sigma},
          {"silicone_n_per_m", point.silicone_n_per_m},
          {"buna_n_n_per_m", point.buna_n_n_per_m},
          {"spring_n_per_m", point.spring_n_per_m}};
}

json Optional(const std::optional<double>& value) { return value ? json(*value) : json(nullptr); }

json TruthJson(const CampaignOptions& options, const Calibration& calibration,
               const std::vector<Trial3dSpec>& specs, const Set3dSummary& summary) {
  json trials = json::array();
  for (size_t i = 0; i < specs.size(); ++i) {
    const WrittenTrial3d& written = summary.trials[i];
    trials.push_back({{"id", specs[i].id},
                      {"foot", std::string(FootName(specs[i].foot))},
                      {"tension", TensionJson(*specs[i].tension)},
                      {"expect", written.expect},
                      {"t_led_on", Optional(written.t_led_on_s)},
                      {"t_lift_1mm", Optional(written.t_lift_1mm_s)},
                      {"theta_at_lift_1mm_rad", Optional(written.theta_at_lift_1mm_rad)},
                      {"truth", specs[i].id + "/truth.json"}});
  }
  return {{"format", "liftoff-synth-campaign-truth"},
          {"version", 1},
          {"calibration", calibration.Brief()},
          {"tension_sigma", options.tension_sigma},
          {"hidden_tension", TensionJson(fit::TensionAtSigma(calibration.tension_points,
                                                             options.tension_sigma, "hidden"))},
          {"stiffness_sd_scale", options.stiffness_sd_scale},
          {"ramp_s", options.ramp_s},
          {"theta_rate_rad_s", kRampAngleRad / options.ramp_s},
          {"report_flags", CampaignReportFlags(options)},
          {"seed", options.seed},
          {"trials", trials}};
}

}  // namespace

Status CampaignOptions::Validate() const {
  if (trials_per_foot < 1 || trials_per_foot > 20)
    return OutOfRange("trials_per_foot", trials_per_foot, 1, 20);
  if (!(tension_sigma >= -2 && tension_sigma <= 4))
    return OutOfRange("tension_sigma", tension_sigma, -2, 4);
  if (!(stiffness_sd_scale >= 0 && stiffness_sd_scale <= 1))
    return OutOfRange("stiffness_sd_scale", stiffness_sd_scale, 0, 1);
  if (!(ramp_s >= 2 && ramp_s <= 60)) return OutOfRange("ramp_s", ramp_s, 2, 60);
  Scene3dOptions scene;
  scene.width_px = width_px;
  scene.height_px = height_px;
  return scene.Validate().WithContext("campaign");
}

std::string CampaignReportFlags(const CampaignOptions& options) {
  char flags[64];
  std::snprintf(flags, sizeof flags, "--ramp-s %g", options.ramp_s);
  return flags;
}

Result<std::vector<Trial3dSpec>> CampaignSpecs(const Calibration& calibration,
                                               const CampaignOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  if (calibration.tension_points.size() < 2) {
    return InvalidArgumentError(calibration.Brief() + ": campaign: needs two tension points");
  }
  const int count = 4 * options.trials_per_foot;
  fit::MonteCarloOptions spread;
  spread.samples = count;
  spread.seed = options.seed;
  spread.stddev_scale = options.stiffness_sd_scale;
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<TensionPoint> draws,
                           fit::MonteCarloDraws(calibration, spread));
  const std::vector<TensionPoint> offsets =
      CentredOffsets(draws, calibration, options.trials_per_foot);
  const TensionPoint hidden =
      fit::TensionAtSigma(calibration.tension_points, options.tension_sigma, "hidden");
  SplitMix64 random(options.seed ^ kCameraStream);
  std::vector<Trial3dSpec> specs;
  for (int i = 0; i < count; ++i) {
    const Foot foot = kAllFeet[static_cast<size_t>(i / options.trials_per_foot)];
    const int k = i % options.trials_per_foot;
    Trial3dSpec& spec = specs.emplace_back();
    spec.id = std::string(FootName(foot)) + std::to_string(k + 1);
    spec.seed = options.seed * 1000 + static_cast<uint64_t>(i) + 1;
    spec.scene.seed = spec.seed;
    spec.scene.width_px = options.width_px;
    spec.scene.height_px = options.height_px;
    spec.foot = foot;
    spec.tension = TrialTension(hidden, offsets[static_cast<size_t>(i)], "campaign-" + spec.id);
    spec.theta_rate_rad_s = kRampAngleRad / options.ramp_s;
    spec.max_rotation_rad = kRampAngleRad;
    spec.after_lift_s = 0.25;
    spec.max_duration_s = 1.5 + options.ramp_s;
    spec.codec = VideoCodec::kFfv1;  // lossless: H.264's lag costs frames at this ramp rate
    VaryCamera(spec, k, random);
  }
  return specs;
}

Result<Set3dSummary> WriteCampaign(const CampaignOptions& options, const Calibration& calibration,
                                   const std::filesystem::path& output_dir,
                                   const Set3dProgress& progress) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<Trial3dSpec> specs,
                           CampaignSpecs(calibration, options));
  const std::string description = "liftoff synth --set campaign (" + calibration.name +
                                  "): simulate with `liftoff report MANIFEST " +
                                  CampaignReportFlags(options) + "`";
  LIFTOFF_ASSIGN_OR_RETURN(
      Set3dSummary summary,
      WriteSpecs3d("campaign", specs, output_dir, calibration, description, progress));
  const json truth = TruthJson(options, calibration, specs, summary);
  LIFTOFF_RETURN_IF_ERROR(
      WriteFileAtomically(output_dir / "campaign-truth.json", truth.dump(1) + "\n"));
  return summary;
}

}  // namespace liftoff::synth
