// Synthetic trials in 3D: a simplified Laika rendered with perspective, lights, shadows
// and materials by MuJoCo's offscreen renderer (headless through EGL, egl_context.h).
//
// World frame: metres, z up, the floor at z = 0; the robot's front towards +x, its left
// towards +y. Feet (foot centres at rest): A front right (+0.324, -0.0755), B front left
// (+0.324, +0.0755), C back right (-0.324, -0.0755), D back left (-0.324, +0.0755); the
// spine axis 0.191 above the floor with five vertebrae 0.099 apart (laika-model.md).
//
// The scene (an MJCF model built as text, Scene3dMjcf): a floor plane (a textured
// plywood-like checker, or a dark glossy one with reflectance), a backdrop wall behind
// the robot as seen from the camera, clutter (boxes and cylinders drawn from the seed, kept
// away from the robot and the camera's line of sight), one key light casting shadows
// (plus a dim fill light), the robot (end boxes, four vertebra "X"s of rods, the centre
// vertebra as a disc with a white marker on a hinge about the spine axis, four legs with a
// tape band, four feet of one shape) and the sync LED: a small sphere on a post, emissive
// when on.
//
// Pose: the robot is two rigid ends (box, cross piece, two vertebrae, two legs and feet
// each) and the centre vertebra. A lifting foot of height h is shown by rolling its end
// about the line along the spine through the floor contact of the other foot at that end,
// by the angle that raises the lifting foot's centre by exactly h (the spine's twist; the
// other end and its feet stay down). The centre vertebra turns by its signed angle about
// the spine axis.
//
// Pixels: row-major, BGR, pixel centres at integer coordinates (pixel (0, 0) covers
// [-0.5, 0.5)^2); ProjectPx follows the same convention.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"

namespace liftoff::synth {

/// Where the camera looks from.
enum class CameraView {
  kSide,     ///< from the robot's right (-y), looking at its side
  kOblique,  ///< from front right, 45 degrees between side and front
  kFront,    ///< from in front (+x), looking back along the spine
};
std::string_view CameraViewName(CameraView view);  ///< "side", "oblique", "front"

/// Shape of the four feet.
enum class FootShape {
  kSphere,     ///< a ball, radius 12.5 mm (the model's)
  kBlock,      ///< a box 40 x 30 x 25 mm (x along the spine, y across, z up)
  kRubberTip,  ///< a capsule along z, radius 12.5 mm, 16 mm of straight part
};
std::string_view FootShapeName(FootShape shape);  ///< "sphere", "block", "rubber-tip"

/// How the feet are coloured.
enum class FootColouring {
  kTape,     ///< each foot in its tape colour (A blue, B orange, C purple, D red)
  kUntaped,  ///< dark grey rubber feet; the tape colour only on the band around each leg
  kBlack,    ///< black feet and black bands: no colour to go by
};

/// Floor material.
enum class FloorKind {
  kTextured,  ///< plywood-like checker with grain-like random marks, matte (reflectance 0)
  kGlossy,    ///< dark grey, mirror-like (reflectance floor_reflectance)
};

/// Everything that fixes one 3D scene and camera.
struct Scene3dOptions {
  /// Image size, px: 320 .. 1920 by 240 .. 1080, even.
  int width_px = 640;
  int height_px = 480;
  CameraView view = CameraView::kSide;
  /// Camera centre's height above the floor, m (0.05 .. 1.5).
  double camera_height_m = 0.35;
  /// Horizontal distance from the robot's centre to the camera, m (0.4 .. 3).
  double camera_distance_m = 0.85;
  /// Vertical field of view, degrees (20 .. 90).
  double fovy_deg = 45.0;
  /// Sideways shift of the camera's aim from the robot's centre, m (-0.5 .. 0.5; +
  /// moves the robot left in the image).
  double aim_offset_m = 0.0;

  FootShape foot_shape = FootShape::kSphere;
  FootColouring colouring = FootColouring::kTape;

  FloorKind floor = FloorKind::kTextured;
  /// kGlossy: MuJoCo material reflectance (0 .. 1).
  double floor_reflectance = 0.45;
  /// Clutter objects on the floor (0 .. 12), placed from the seed.
  int clutter_count = 4;

  /// Key light: elevation above the horizon and azimuth (0: from +x, 90: from +y),
  /// degrees; elevation 5 .. 90 (low: long hard shadows).
  double light_elevation_deg = 60.0;
  double light_azimuth_deg = -60.0;
  /// Overall light level, relative (0.05 .. 2; 1: a well-lit bench).
  double light_level = 1.0;
  /// Shadow map size, px (256 .. 8192; larger: sharper, slower).
  int shadow_map_px = 1024;
  /// Multisample anti-aliasing samples per pixel (0, 2, 4 or 8). 0 by default: on Mesa's
  /// CPU renderer (llvmpipe) 4 samples cost 2-3 times the frame; trial3d's default lens
  /// blur smooths the edges instead.
  int msaa_samples = 0;

  /// LED sphere radius, m (0.001 .. 0.02), and its colour when on (RGB 0 .. 1).
  double led_radius_m = 0.005;
  std::array<double, 3> led_rgb = {1.0, 0.1, 0.05};
  /// Image-space glow of the lit LED: Gaussian sigma as a multiple of its image radius
  /// (0 .. 6) and peak strength added, 8-bit levels (0 .. 255).
  double led_glow_sigma = 2.0;
  double led_glow_level = 120.0;

  /// Texture noise and clutter placement.
  uint64_t seed = 1;

  Status Validate() const;
};

/// The robot's pose in one frame.
struct RobotPose3d {
  /// Height of the lifting foot's centre above its rest, m (>= 0).
  double lift_m = 0.0;
  /// Signed angle of the centre vertebra about the spine axis, rad.
  double vertebra_rad = 0.0;
};

/// The scene as MJCF text (deterministic: same options, same text).
std::string Scene3dMjcf(const Scene3dOptions& options, Foot lifting_foot);

/// Renders frames of one scene. Needs a current OpenGL context on the calling thread (an
/// EglContext) for its whole life: create, render and destroy on that thread.
class SceneRenderer3d {
 public:
  /// Compiles the scene and makes MuJoCo's GPU context. kInvalidArgument for bad
  /// options; kUnsupported when MuJoCo cannot make its offscreen buffer (no context).
  static Result<std::unique_ptr<SceneRenderer3d>> Create(const Scene3dOptions& options,
                                                         Foot lifting_foot);

  /// The scene at `pose` with the LED on or off, BGR 8-bit, no image effects: the light
  /// glow of a lit LED is not in it (AddLedGlow).
  cv::Mat Render(const RobotPose3d& pose, bool led_on);

  /// Adds the LED's glow, scaled by `fraction` (0 .. 1), to `bgr` in place, centred on
  /// led_center_px() shifted by `offset_px`.
  void AddLedGlow(cv::Mat& bgr, double fraction, cv::Point2d offset_px = {0, 0}) const;

  /// A world point (m) in the image, px (pixel centres at integers).
  cv::Point2d ProjectPx(const cv::Vec3d& world_m) const;
  /// Distance from the camera's centre along its view axis, m.
  double DepthM(const cv::Vec3d& world_m) const;

  /// The lifting foot's centre, world m, at `pose` (roll applied).
  cv::Vec3d FootCenterM(const RobotPose3d& pose) const;
  /// Image displacement of the lifting foot's centre per mm it rises from rest, px/mm:
  /// |ProjectPx(centre + 1 mm up) - ProjectPx(centre)|.
  double PixelsPerMm() const;
  /// The resting lifting foot: centre, px; apparent width (the foot's largest horizontal
  /// extent, through the camera at its depth), px.
  cv::Point2d FootCenterPx() const;
  double FootDiameterPx() const;
  /// The LED sphere: centre and radius in the image, px.
  cv::Point2d LedCenterPx() const;
  double LedRadiusPx() const;

  const Scene3dOptions& options() const { return options_; }
  Foot lifting_foot() const { return lifting_foot_; }

  ~SceneRenderer3d();
  SceneRenderer3d(const SceneRenderer3d&) = delete;
  SceneRenderer3d& operator=(const SceneRenderer3d&) = delete;

 private:
  struct Impl;
  explicit SceneRenderer3d(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  Scene3dOptions options_;
  Foot lifting_foot_ = Foot::kA;
};

}  // namespace liftoff::synth
