// One short synthetic clip for tests that need a real video: a CI-baseline-like trial,
// 640x480, 60 fps, H.264, the LED on at 0.61 s (between two exposures), a 0.4 rad/s ramp
// from 0.2 s, foot A lifting at 0.47 rad (1 mm at about 2.05 s), 2.4 s long (about a second
// to render with synth::WriteTrial).
#pragma once

#include <string>

#include "liftoff/core/robot.h"
#include "liftoff/synth/spec.h"

namespace liftoff::testing {

inline synth::TrialSpec ShortClipSpec(const std::string& id) {
  synth::TrialSpec spec;
  spec.id = id;
  spec.seed = 77;
  spec.duration_s = 2.4;
  spec.camera.width_px = 640;
  spec.camera.height_px = 480;
  spec.camera.fps = 60.0;
  spec.camera.exposure_s = 1.0 / 120.0;
  spec.camera.codec = synth::VideoCodec::kH264;
  spec.led.on_video_s = 0.61;
  spec.motion.foot = Foot::kA;
  spec.motion.height.liftoff_rad = 0.47;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.15;
  spec.motion.ramp_start_s = 0.2;
  spec.motion.ramp_rate_rad_per_s = 0.4;
  return spec;
}

}  // namespace liftoff::testing
