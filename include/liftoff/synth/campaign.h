// A synthetic hardware campaign: 3D trials (trial3d.h) of every foot, made from liftoff's
// own simulation at a tension the campaign's inputs do not reveal, with a trial-to-trial
// spread like hardware's, for `liftoff report` to analyse and calibrate against.
//
//   <output_dir>/<id>/...              each trial as WriteTrial3d writes it
//   <output_dir>/manifest.json         the trials (the report's input)
//   <output_dir>/set.json              the index (WriteSpecs3d)
//   <output_dir>/campaign-truth.json   the answer: the hidden tension scale and stiffnesses,
//                                      each trial's stiffnesses and liftoff rotation, and the
//                                      report flags that simulate the same procedure
//
// The tension. The hidden tension scale `tension_sigma` is a point on the calibration's
// tension line (fit::TensionAtSigma, the line the report's fit searches). Each trial's
// stiffnesses are that point plus a draw of fit::MonteCarloDraws (Table I's standard
// deviations times `stiffness_sd_scale`, seeded) minus the materials' means: the trials of
// a foot differ as hardware trials of one robot do, around the hidden tension.
//
// The procedure. The ramp turns the vertebra by the simulation's 60 degrees in `ramp_s`
// (the paper's is 40 s; a fast ramp keeps the clips short); the simulated liftoff
// rotation depends a little on the rate, so the report must simulate the same ramp:
// `liftoff report MANIFEST --ramp-s <ramp_s>` (ReportFlags, also in the truth file).
//
// The cameras. Each foot in a view that shows it clearly (A and C: side and oblique in
// turn; B: oblique; D: side); camera distance and height, light,
// clutter, the LED switch-on (0.8 .. 1.2 s in), sensor noise and every seed vary per trial.
// Spherical feet (the block and the rubber tip failed more often at this scale). Lossless
// FFV1 video, 480x360, 30 fps: H.264's lag costs frames on this fast ramp. Each clip ends
// 0.25 s after the 1 mm instant.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/status.h"
#include "liftoff/synth/trial3d.h"

namespace liftoff::synth {

struct CampaignOptions {
  /// Trials per foot (1 .. 20), ids "A1" .. "D<n>".
  int trials_per_foot = 5;
  /// The hidden tension scale, calibration sigma (-2 .. 4).
  double tension_sigma = 0.7;
  /// Per-trial spread: a factor on Table I's standard deviations (0 .. 1).
  double stiffness_sd_scale = 0.25;
  /// The ramp's duration over its 60 degrees, s (2 .. 60).
  double ramp_s = 7.0;
  /// Frame size, px (as Scene3dOptions).
  int width_px = 480;
  int height_px = 360;
  /// Every draw (stiffnesses, cameras, clips).
  uint64_t seed = 2026;

  Status Validate() const;
};

/// The campaign's trials (A..D, trials_per_foot each). kInvalidArgument for bad options or
/// a calibration without two tension points or Table I's materials (silicone, buna_n,
/// spring).
Result<std::vector<Trial3dSpec>> CampaignSpecs(const Calibration& calibration,
                                               const CampaignOptions& options);

/// The flags that make `liftoff report` simulate the campaign's procedure: "--ramp-s 7".
std::string CampaignReportFlags(const CampaignOptions& options);

/// Renders the campaign into `output_dir` (WriteSpecs3d, set name "campaign"), then writes
/// campaign-truth.json last. Errors as WriteSpecs3d's.
Result<Set3dSummary> WriteCampaign(const CampaignOptions& options, const Calibration& calibration,
                                   const std::filesystem::path& output_dir,
                                   const Set3dProgress& progress = {});

}  // namespace liftoff::synth
