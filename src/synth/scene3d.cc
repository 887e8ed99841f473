#include "liftoff/synth/scene3d.h"

#include <EGL/egl.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "liftoff/core/random.h"

namespace liftoff::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;

// laika-model.md, in this file's frame (x forward, y left, z up)
constexpr double kFootX = 0.324, kFootY = 0.0755;
constexpr double kSpineZ = 0.191;
constexpr double kVertebraSpacing = 0.099;
constexpr double kFootRadius = 0.0125;
constexpr double kBlockHalf[3] = {0.020, 0.015, 0.0125};
constexpr double kTipHalfLength = 0.008;
// the camera aims at this height above the robot's centre
constexpr double kAimZ = 0.12;

cv::Vec3d FootRestCenter(Foot foot, FootShape shape) {
  const bool front = foot == Foot::kA || foot == Foot::kB;
  const bool right = foot == Foot::kA || foot == Foot::kC;
  const double z = shape == FootShape::kRubberTip ? kFootRadius + kTipHalfLength
                   : shape == FootShape::kBlock   ? kBlockHalf[2]
                                                  : kFootRadius;
  return {front ? kFootX : -kFootX, right ? -kFootY : kFootY, z};
}

double FootWidthM(FootShape shape) {
  return shape == FootShape::kBlock ? 2 * kBlockHalf[0] : 2 * kFootRadius;
}

std::array<double, 3> TapeRgb(Foot foot) {
  switch (foot) {
    case Foot::kA: return {0.10, 0.25, 0.85};  // blue
    case Foot::kB: return {0.95, 0.50, 0.08};  // orange
    case Foot::kC: return {0.50, 0.18, 0.65};  // purple
    case Foot::kD: return {0.85, 0.10, 0.10};  // red
  }
  return {0.5, 0.5, 0.5};
}

// horizontal unit vector from the robot's centre towards the camera
cv::Vec3d ViewDirection(CameraView view) {
  switch (view) {
    case CameraView::kSide: return {0, -1, 0};
    case CameraView::kOblique: return {std::sqrt(0.5), -std::sqrt(0.5), 0};
    case CameraView::kFront: return {1, 0, 0};
  }
  return {0, -1, 0};
}

struct CameraPose {
  cv::Vec3d position, right, up, forward;  // forward: the viewing direction
  cv::Vec3d aim;                           // the point looked at
};

CameraPose MakeCameraPose(const Scene3dOptions& options) {
  CameraPose pose;
  const cv::Vec3d towards_camera = ViewDirection(options.view);
  const cv::Vec3d right0 = cv::Vec3d(0, 0, 1).cross(towards_camera);  // horizontal right
  pose.aim = cv::Vec3d(0, 0, kAimZ) + options.aim_offset_m * right0;
  pose.position = cv::Vec3d(0, 0, 0) + options.camera_distance_m * towards_camera +
                  options.aim_offset_m * right0;
  pose.position[2] = options.camera_height_m;
  pose.forward = cv::normalize(pose.aim - pose.position);
  pose.right = cv::normalize(pose.forward.cross(cv::Vec3d(0, 0, 1)));
  pose.up = pose.right.cross(pose.forward);
  return pose;
}

// the LED: beside the robot on the camera's right, a little behind it
cv::Vec3d LedPosition(const Scene3dOptions& options) {
  const cv::Vec3d towards_camera = ViewDirection(options.view);
  const cv::Vec3d right = cv::Vec3d(0, 0, 1).cross(towards_camera);
  cv::Vec3d led = 0.36 * right - 0.18 * towards_camera;
  led[2] = 0.30;
  return led;
}

// ---------------------------------------------------------------------------------------
// MJCF text

struct Mjcf {
  std::ostringstream text;
  Mjcf() { text.precision(9); }
  Mjcf& operator<<(const cv::Vec3d& v) {
    text << v[0] << ' ' << v[1] << ' ' << v[2];
    return *this;
  }
  template <typename T>
  Mjcf& operator<<(const T& value) {
    text << value;
    return *this;
  }
};

std::string Rgba(const std::array<double, 3>& rgb, double alpha = 1.0) {
  std::ostringstream out;
  out.precision(6);
  out << rgb[0] << ' ' << rgb[1] << ' ' << rgb[2] << ' ' << alpha;
  return out.str();
}

void WriteAssets(const Scene3dOptions& options, Foot lifting_foot, Mjcf& m) {
  m << "<asset>\n";
  if (options.floor == FloorKind::kTextured) {
    m << "<texture name='floor' type='2d' builtin='checker' rgb1='0.62 0.49 0.34' "
         "rgb2='0.57 0.44 0.30' mark='random' random='0.06' markrgb='0.42 0.31 0.20' "
         "width='512' height='512'/>\n"
      << "<material name='floor' texture='floor' texrepeat='1 1' texuniform='true' "
         "specular='0.1' shininess='0.1' reflectance='0'/>\n";
  } else {
    m << "<texture name='floor' type='2d' builtin='flat' rgb1='0.16 0.16 0.17' "
         "mark='random' random='0.02' markrgb='0.25 0.25 0.26' width='256' height='256'/>\n"
      << "<material name='floor' texture='floor' texrepeat='4 4' texuniform='true' "
         "specular='0.9' shininess='0.9' reflectance='"
      << options.floor_reflectance << "'/>\n";
  }
  m << "<texture name='wall' type='2d' builtin='flat' rgb1='0.20 0.21 0.24' mark='random' "
       "random='0.15' markrgb='0.15 0.16 0.18' width='256' height='256'/>\n"
    << "<material name='wall' texture='wall' texrepeat='3 3' texuniform='true' "
       "specular='0' shininess='0'/>\n"
    << "<material name='body' rgba='0.80 0.66 0.46 1' specular='0.2'/>\n"
    << "<material name='rod' rgba='0.70 0.72 0.75 1' specular='0.6' shininess='0.6'/>\n"
    << "<material name='disc' rgba='0.15 0.15 0.16 1' specular='0.3'/>\n"
    << "<material name='marker' rgba='0.95 0.95 0.95 1'/>\n"
    << "<material name='leg' rgba='0.35 0.36 0.38 1' specular='0.4'/>\n"
    << "<material name='post' rgba='0.12 0.12 0.12 1'/>\n"
    << "<material name='led' rgba='" << Rgba(options.led_rgb) << "' emission='1'/>\n";
  (void)lifting_foot;
  for (const Foot foot : {Foot::kA, Foot::kB, Foot::kC, Foot::kD}) {
    const std::string letter(FootName(foot));
    const std::array<double, 3> tape = TapeRgb(foot);
    const std::array<double, 3> black = {0.06, 0.06, 0.06};
    const std::array<double, 3> rubber = {0.22, 0.22, 0.23};
    const std::array<double, 3> foot_rgb = options.colouring == FootColouring::kTape ? tape
                                           : options.colouring == FootColouring::kUntaped
                                               ? rubber
                                               : black;
    const std::array<double, 3> band_rgb =
        options.colouring == FootColouring::kBlack ? black : tape;
    m << "<material name='foot" << letter << "' rgba='" << Rgba(foot_rgb)
      << "' specular='0.3' shininess='0.3'/>\n"
      << "<material name='band" << letter << "' rgba='" << Rgba(band_rgb) << "'/>\n";
  }
  m << "</asset>\n";
}

void WriteFoot(const Scene3dOptions& options, Foot foot, Mjcf& m) {
  const std::string letter(FootName(foot));
  const cv::Vec3d centre = FootRestCenter(foot, options.foot_shape);
  const cv::Vec3d top(centre[0], centre[1], kSpineZ);
  double foot_top_z = centre[2] + kFootRadius;
  m << "<geom name='foot" << letter << "' material='foot" << letter << "' pos='" << centre;
  switch (options.foot_shape) {
    case FootShape::kSphere: m << "' type='sphere' size='" << kFootRadius << "'/>\n"; break;
    case FootShape::kBlock:
      m << "' type='box' size='" << kBlockHalf[0] << ' ' << kBlockHalf[1] << ' ' << kBlockHalf[2]
        << "'/>\n";
      foot_top_z = centre[2] + kBlockHalf[2];
      break;
    case FootShape::kRubberTip:
      m << "' type='capsule' size='" << kFootRadius << ' ' << kTipHalfLength << "'/>\n";
      foot_top_z = centre[2] + kTipHalfLength + 0.5 * kFootRadius;
      break;
  }
  // the leg down to the foot, with a band of tape above it
  m << "<geom name='leg" << letter << "' type='capsule' material='leg' size='0.005' fromto='"
    << top << ' ' << cv::Vec3d(centre[0], centre[1], foot_top_z) << "'/>\n"
    << "<geom name='band" << letter << "' type='cylinder' material='band" << letter
    << "' size='0.0085 0.009' pos='" << cv::Vec3d(centre[0], centre[1], foot_top_z + 0.03)
    << "'/>\n";
}

// a passive vertebra: four rods from its centre (laika-model.md's tips, in this frame)
void WriteVertebraRods(const cv::Vec3d& centre, const std::string& name, bool front_pair,
                       bool back_pair, Mjcf& m) {
  const cv::Vec3d tips[4] = {{0.065, 0, 0.096}, {0.065, 0, -0.096},   // top, bottom
                             {-0.065, -0.096, 0}, {-0.065, 0.096, 0}};  // right, left
  for (int i = 0; i < 4; ++i) {
    if ((i < 2 && !front_pair) || (i >= 2 && !back_pair)) continue;
    m << "<geom name='" << name << "_rod" << i << "' type='capsule' material='rod' "
      << "size='0.0064' fromto='" << centre << ' ' << (centre + tips[i]) << "'/>\n";
  }
}

// the other foot at the same end (the lifting foot's half rolls about its contact)
Foot SameEndPartner(Foot foot) {
  switch (foot) {
    case Foot::kA: return Foot::kB;
    case Foot::kB: return Foot::kA;
    case Foot::kC: return Foot::kD;
    case Foot::kD: return Foot::kC;
  }
  return Foot::kB;
}

bool IsFront(Foot foot) { return foot == Foot::kA || foot == Foot::kB; }

// one end of the robot: its box and cross piece, its two vertebrae with the cables between
// them, its two legs and feet; the lifting foot's end on a hinge along the spine through
// the other foot's floor contact
void WriteHalf(const Scene3dOptions& options, bool front, Foot lifting_foot, Mjcf& m) {
  const double sign = front ? 1.0 : -1.0;
  m << "<body name='" << (front ? "front" : "rear") << "'>\n";
  if (IsFront(lifting_foot) == front) {
    cv::Vec3d pivot = FootRestCenter(SameEndPartner(lifting_foot), options.foot_shape);
    pivot[2] = 0;
    m << "<joint name='roll' type='hinge' axis='1 0 0' pos='" << pivot << "'/>\n";
  }
  const double end_x = sign * 2 * kVertebraSpacing;
  m << "<geom type='box' material='body' size='0.063 0.035 0.03' pos='"
    << cv::Vec3d(end_x + sign * 0.063, 0, kSpineZ) << "'/>\n"
    << "<geom type='box' material='body' size='0.006 0.0905 0.03' pos='"
    << cv::Vec3d(sign * kFootX, 0, kSpineZ) << "'/>\n";
  for (const int index : {1, 2}) {
    const cv::Vec3d centre(sign * index * kVertebraSpacing, 0, kSpineZ);
    WriteVertebraRods(centre, "v" + std::to_string(3 + static_cast<int>(sign) * index), true, true,
                      m);
  }
  const cv::Vec3d a(sign * kVertebraSpacing, 0, kSpineZ),
      b(sign * 2 * kVertebraSpacing, 0, kSpineZ);
  const cv::Vec3d tips[4] = {{0.065, 0, 0.096}, {0.065, 0, -0.096}, {-0.065, -0.096, 0},
                             {-0.065, 0.096, 0}};
  for (const cv::Vec3d& tip : tips) {
    m << "<geom type='capsule' material='leg' size='0.0012' fromto='" << (a + tip) << ' '
      << (b + tip) << "'/>\n";
  }
  for (const Foot foot : {Foot::kA, Foot::kB, Foot::kC, Foot::kD}) {
    if (IsFront(foot) == front) WriteFoot(options, foot, m);
  }
  m << "</body>\n";
}

void WriteRobot(const Scene3dOptions& options, Foot lifting_foot, Mjcf& m) {
  m << "<body name='robot'>\n";
  WriteHalf(options, false, lifting_foot, m);
  WriteHalf(options, true, lifting_foot, m);
  // the centre vertebra: a disc with a white marker, on a hinge about the spine axis
  m << "<body name='vertebra' pos='0 0 " << kSpineZ << "'>\n"
    << "<joint name='vertebra' type='hinge' axis='1 0 0'/>\n"
    << "<geom type='cylinder' material='disc' size='0.045 0.008' euler='0 90 0'/>\n"
    << "<geom type='box' material='marker' size='0.0085 0.003 0.018' pos='0.0095 0 0.022'/>\n";
  WriteVertebraRods(cv::Vec3d(0, 0, 0), "v3", true, true, m);
  m << "</body>\n</body>\n";
}

void WriteClutter(const Scene3dOptions& options, const CameraPose& camera, Mjcf& m) {
  SplitMix64 random(options.seed ^ 0x3D5CE7E0C1A77E5ull);
  const cv::Vec3d led = LedPosition(options);
  int placed = 0;
  for (int attempt = 0; placed < options.clutter_count && attempt < 400; ++attempt) {
    const double angle = 2 * kPi * random.Uniform();
    const double radius = 0.5 + 0.7 * random.Uniform();
    const cv::Vec3d p(radius * std::cos(angle), radius * std::sin(angle), 0);
    const double size = 0.02 + 0.035 * random.Uniform();
    const bool box = random.Uniform() < 0.5;
    const std::array<double, 3> rgb = {0.2 + 0.6 * random.Uniform(), 0.2 + 0.5 * random.Uniform(),
                                       0.2 + 0.5 * random.Uniform()};
    // keep the robot, the LED and the camera's line of sight to the robot clear
    if (std::abs(p[0]) < 0.5 && std::abs(p[1]) < 0.3) continue;
    if (cv::norm(cv::Vec2d(p[0] - led[0], p[1] - led[1])) < 0.15) continue;
    const cv::Vec3d to_camera(camera.position[0], camera.position[1], 0);
    const double along = p.dot(to_camera) / to_camera.dot(to_camera);
    const cv::Vec3d nearest = std::clamp(along, 0.0, 1.2) * to_camera;
    if (along > -0.2 && cv::norm(p - nearest) < 0.55) continue;
    m << "<geom type='" << (box ? "box" : "cylinder") << "' rgba='" << Rgba(rgb)
      << "' pos='" << cv::Vec3d(p[0], p[1], box ? size : size * 1.5) << "' size='" << size;
    if (box) m << ' ' << size * 0.8 << ' ' << size << "' euler='0 0 " << angle * 57.29578;
    else m << ' ' << size * 1.5;
    m << "'/>\n";
    ++placed;
  }
}

}  // namespace

std::string_view CameraViewName(CameraView view) {
  switch (view) {
    case CameraView::kSide: return "side";
    case CameraView::kOblique: return "oblique";
    case CameraView::kFront: return "front";
  }
  return "?";
}

std::string_view FootShapeName(FootShape shape) {
  switch (shape) {
    case FootShape::kSphere: return "sphere";
    case FootShape::kBlock: return "block";
    case FootShape::kRubberTip: return "rubber-tip";
  }
  return "?";
}

Status Scene3dOptions::Validate() const {
  const auto out_of = [](const char* field, double value, double low, double high) {
    std::ostringstream message;
    message << "scene3d: " << field << ": expected a number in [" << low << ", " << high
            << "], got " << value;
    return InvalidArgumentError(message.str());
  };
  if (width_px < 320 || width_px > 1920 || width_px % 2 != 0)
    return out_of("width_px (even)", width_px, 320, 1920);
  if (height_px < 240 || height_px > 1080 || height_px % 2 != 0)
    return out_of("height_px (even)", height_px, 240, 1080);
  if (!(camera_height_m >= 0.05 && camera_height_m <= 1.5))
    return out_of("camera_height_m", camera_height_m, 0.05, 1.5);
  if (!(camera_distance_m >= 0.4 && camera_distance_m <= 3))
    return out_of("camera_distance_m", camera_distance_m, 0.4, 3);
  if (!(fovy_deg >= 20 && fovy_deg <= 90)) return out_of("fovy_deg", fovy_deg, 20, 90);
  if (!(std::abs(aim_offset_m) <= 0.5)) return out_of("aim_offset_m", aim_offset_m, -0.5, 0.5);
  if (!(floor_reflectance >= 0 && floor_reflectance <= 1))
    return out_of("floor_reflectance", floor_reflectance, 0, 1);
  if (clutter_count < 0 || clutter_count > 12) return out_of("clutter_count", clutter_count, 0, 12);
  if (!(light_elevation_deg >= 5 && light_elevation_deg <= 90))
    return out_of("light_elevation_deg", light_elevation_deg, 5, 90);
  if (!std::isfinite(light_azimuth_deg))
    return out_of("light_azimuth_deg", light_azimuth_deg, -360, 360);
  if (!(light_level >= 0.05 && light_level <= 2))
    return out_of("light_level", light_level, 0.05, 2);
  if (shadow_map_px < 256 || shadow_map_px > 8192)
    return out_of("shadow_map_px", shadow_map_px, 256, 8192);
  if (msaa_samples != 0 && msaa_samples != 2 && msaa_samples != 4 && msaa_samples != 8)
    return out_of("msaa_samples (0, 2, 4 or 8)", msaa_samples, 0, 8);
  if (!(led_radius_m >= 0.001 && led_radius_m <= 0.02))
    return out_of("led_radius_m", led_radius_m, 0.001, 0.02);
  for (const double channel : led_rgb) {
    if (!(channel >= 0 && channel <= 1)) return out_of("led_rgb", channel, 0, 1);
  }
  if (!(led_glow_sigma >= 0 && led_glow_sigma <= 6))
    return out_of("led_glow_sigma", led_glow_sigma, 0, 6);
  if (!(led_glow_level >= 0 && led_glow_level <= 255))
    return out_of("led_glow_level", led_glow_level, 0, 255);
  return Status::Ok();
}

std::string Scene3dMjcf(const Scene3dOptions& options, Foot lifting_foot) {
  const CameraPose camera = MakeCameraPose(options);
  Mjcf m;
  m << "<mujoco model='liftoff-synth3d'>\n"
    << "<compiler angle='degree'/>\n"
    << "<option><flag contact='disable' gravity='disable'/></option>\n"
    << "<statistic extent='1' center='0 0 0.1'/>\n"
    << "<visual>\n<global offwidth='" << options.width_px << "' offheight='" << options.height_px
    << "'/>\n<quality shadowsize='" << options.shadow_map_px << "' offsamples='"
    << options.msaa_samples << "'/>\n"
    << "<map znear='0.02' zfar='20' shadowclip='1.2' shadowscale='0.5'/>\n"
    << "<headlight ambient='" << 0.12 * options.light_level << ' ' << 0.12 * options.light_level
    << ' ' << 0.12 * options.light_level << "' diffuse='" << 0.15 * options.light_level << ' '
    << 0.15 * options.light_level << ' ' << 0.15 * options.light_level
    << "' specular='0.05 0.05 0.05'/>\n</visual>\n";
  WriteAssets(options, lifting_foot, m);

  // the key light (casts shadows) and a fill light
  const double elevation = options.light_elevation_deg * kPi / 180;
  const double azimuth = options.light_azimuth_deg * kPi / 180;
  const cv::Vec3d towards_light(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  const double key = 0.75 * options.light_level, fill = 0.25 * options.light_level;
  m << "<worldbody>\n"
    << "<light name='key' directional='true' castshadow='true' pos='" << 2.0 * towards_light
    << "' dir='" << -towards_light << "' diffuse='" << key << ' ' << key << ' ' << key
    << "' specular='0.3 0.3 0.3'/>\n"
    << "<light name='fill' directional='true' castshadow='false' pos='0 0 3' dir='"
    << cv::normalize(cv::Vec3d(-towards_light[0], -towards_light[1], -1.5)) << "' diffuse='"
    << fill << ' ' << fill << ' ' << fill << "' specular='0 0 0'/>\n"
    << "<geom name='floor' type='plane' size='4 4 0.1' material='floor'/>\n";

  // backdrop: a wall beyond the robot, facing the camera
  const cv::Vec3d towards_camera = ViewDirection(options.view);
  const double wall_yaw = std::atan2(towards_camera[1], towards_camera[0]) * 180 / kPi + 90;
  m << "<geom name='wall' type='box' material='wall' size='3 0.01 1.5' pos='"
    << cv::Vec3d(-1.6 * towards_camera[0], -1.6 * towards_camera[1], 1.5) << "' euler='0 0 "
    << wall_yaw << "'/>\n";
  WriteClutter(options, camera, m);

  // the LED on its post
  const cv::Vec3d led = LedPosition(options);
  m << "<geom name='led_post' type='cylinder' material='post' size='0.004 "
    << 0.5 * (led[2] - options.led_radius_m) << "' pos='"
    << cv::Vec3d(led[0], led[1], 0.5 * (led[2] - options.led_radius_m)) << "'/>\n"
    << "<geom name='led_base' type='cylinder' material='post' size='0.03 0.004' pos='"
    << cv::Vec3d(led[0], led[1], 0.004) << "'/>\n"
    << "<geom name='led' type='sphere' material='led' size='" << options.led_radius_m
    << "' pos='" << led << "'/>\n";

  // the camera: MuJoCo's looks along its -z; x right, y up
  m << "<camera name='camera' fovy='" << options.fovy_deg << "' pos='" << camera.position
    << "' xyaxes='" << camera.right << ' ' << camera.up << "'/>\n";
  WriteRobot(options, lifting_foot, m);
  m << "</worldbody>\n</mujoco>\n";
  return m.text.str();
}

// ---------------------------------------------------------------------------------------
// the renderer

struct SceneRenderer3d::Impl {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  mjvScene scene;
  mjvOption option;
  mjvCamera camera;
  mjrContext context;
  bool have_scene = false, have_context = false;
  int led_material = -1;
  int vertebra_qpos = -1, roll_qpos = -1;
  CameraPose pose;
  double focal_px = 0;
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;

  ~Impl() {
    if (have_context) mjr_freeContext(&context);
    if (have_scene) mjv_freeScene(&scene);
    if (data != nullptr) mj_deleteData(data);
    if (model != nullptr) mj_deleteModel(model);
  }
};

namespace {

Result<mjModel*> CompileMjcf(const std::string& mjcf) {
  constexpr const char* kFileName = "liftoff_synth3d.xml";
  auto vfs = std::make_unique<mjVFS>();  // 2 MB: on the heap
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), kFileName, static_cast<int>(mjcf.size())) != 0) {
    mj_deleteVFS(vfs.get());
    return IoError("scene3d: MuJoCo cannot make a virtual file for the scene");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), kFileName)], mjcf.data(), mjcf.size());
  char error[1024] = "";
  mjModel* model = mj_loadXML(kFileName, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (model == nullptr)
    return InvalidArgumentError(std::string("scene3d: MuJoCo rejected the scene: ") + error);
  return model;
}

cv::Vec3d Rotate(const cv::Vec3d& u, double angle, const cv::Vec3d& v) {
  // Rodrigues
  return v * std::cos(angle) + u.cross(v) * std::sin(angle) +
         u * (u.dot(v)) * (1 - std::cos(angle));
}

struct Tip {
  cv::Vec3d pivot, axis;  // a point on the axis (on the floor) and its unit direction
  double angle = 0;       // rad, right-handed about axis
};

// the roll of the lifting foot's end that raises the foot's centre by `lift_m`: about the
// line along the spine through the other foot's floor contact at that end
Tip TipFor(Foot foot, FootShape shape, double lift_m) {
  Tip tip;
  tip.pivot = FootRestCenter(SameEndPartner(foot), shape);
  tip.pivot[2] = 0;
  tip.axis = cv::Vec3d(1, 0, 0);
  const cv::Vec3d offset = FootRestCenter(foot, shape) - tip.pivot;
  // the positive sense must raise the foot
  if (tip.axis.cross(offset)[2] < 0) tip.axis = -tip.axis;
  const cv::Vec3d radial = offset - tip.axis * tip.axis.dot(offset);
  const double d = std::hypot(radial[0], radial[1]), r0 = radial[2];
  const double reach = std::hypot(d, r0);
  tip.angle = std::asin(std::min(1.0, (r0 + lift_m) / reach)) - std::atan2(r0, d);
  return tip;
}

}  // namespace

SceneRenderer3d::SceneRenderer3d(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SceneRenderer3d::~SceneRenderer3d() = default;

Result<std::unique_ptr<SceneRenderer3d>> SceneRenderer3d::Create(const Scene3dOptions& options,
                                                                 Foot lifting_foot) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  // MuJoCo's renderer ends the process when it has no context: check first
  if (eglGetCurrentContext() == EGL_NO_CONTEXT) {
    return UnsupportedError(
        "scene3d: no current OpenGL context on this thread (make an EglContext)");
  }
  auto impl = std::make_unique<Impl>();
  LIFTOFF_ASSIGN_OR_RETURN(impl->model, CompileMjcf(Scene3dMjcf(options, lifting_foot)));
  impl->data = mj_makeData(impl->model);
  impl->led_material = mj_name2id(impl->model, mjOBJ_MATERIAL, "led");
  const int hinge = mj_name2id(impl->model, mjOBJ_JOINT, "vertebra");
  impl->vertebra_qpos = impl->model->jnt_qposadr[hinge];
  impl->roll_qpos = impl->model->jnt_qposadr[mj_name2id(impl->model, mjOBJ_JOINT, "roll")];
  impl->pose = MakeCameraPose(options);
  impl->width = options.width_px;
  impl->height = options.height_px;
  impl->focal_px = 0.5 * options.height_px / std::tan(0.5 * options.fovy_deg * kPi / 180);

  mjv_defaultScene(&impl->scene);
  mjv_defaultOption(&impl->option);
  mjv_defaultCamera(&impl->camera);
  mjr_defaultContext(&impl->context);
  mjv_makeScene(impl->model, &impl->scene, 2000);
  impl->have_scene = true;
  mjr_makeContext(impl->model, &impl->context, mjFONTSCALE_100);
  impl->have_context = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &impl->context);
  if (impl->context.currentBuffer != mjFB_OFFSCREEN || impl->context.offWidth < options.width_px ||
      impl->context.offHeight < options.height_px) {
    return UnsupportedError("scene3d: MuJoCo could not make its offscreen buffer");
  }
  impl->camera.type = mjCAMERA_FIXED;
  impl->camera.fixedcamid = mj_name2id(impl->model, mjOBJ_CAMERA, "camera");
  impl->rgb.resize(static_cast<size_t>(options.width_px) * static_cast<size_t>(options.height_px) *
                   3);

  std::unique_ptr<SceneRenderer3d> renderer(new SceneRenderer3d(std::move(impl)));
  renderer->options_ = options;
  renderer->lifting_foot_ = lifting_foot;
  return renderer;
}

cv::Mat SceneRenderer3d::Render(const RobotPose3d& pose, bool led_on) {
  Impl& impl = *impl_;
  // the robot: the lifting foot's end rolled, the vertebra turned
  const Tip tip = TipFor(lifting_foot_, options_.foot_shape, std::max(0.0, pose.lift_m));
  impl.data->qpos[impl.roll_qpos] = tip.axis[0] > 0 ? tip.angle : -tip.angle;
  impl.data->qpos[impl.vertebra_qpos] = pose.vertebra_rad;
  mj_kinematics(impl.model, impl.data);
  mj_camlight(impl.model, impl.data);

  // the LED: emissive in its colour when on, a dull dark glass when off
  float* rgba = impl.model->mat_rgba + 4 * impl.led_material;
  for (int i = 0; i < 3; ++i) {
    const double on = options_.led_rgb[static_cast<size_t>(i)];
    rgba[i] = static_cast<float>(led_on ? on : 0.12 + 0.2 * on);
  }
  impl.model->mat_emission[impl.led_material] = led_on ? 1.0f : 0.0f;

  // bind this renderer's framebuffer: another renderer on the context may have bound its own
  mjr_setBuffer(mjFB_OFFSCREEN, &impl.context);
  const mjrRect viewport = {0, 0, impl.width, impl.height};
  mjv_updateScene(impl.model, impl.data, &impl.option, nullptr, &impl.camera, mjCAT_ALL,
                  &impl.scene);
  mjr_render(viewport, &impl.scene, &impl.context);
  mjr_readPixels(impl.rgb.data(), nullptr, viewport, &impl.context);

  // OpenGL's rows run bottom-up, RGB
  const cv::Mat rgb(impl.height, impl.width, CV_8UC3, impl.rgb.data());
  cv::Mat flipped, bgr;
  cv::flip(rgb, flipped, 0);
  cv::cvtColor(flipped, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

void SceneRenderer3d::AddLedGlow(cv::Mat& bgr, double fraction, cv::Point2d offset_px) const {
  const double sigma = std::max(1.0, options_.led_glow_sigma * LedRadiusPx());
  if (fraction <= 0 || options_.led_glow_sigma <= 0 || options_.led_glow_level <= 0) return;
  const cv::Point2d centre = LedCenterPx() + offset_px;
  const int reach = static_cast<int>(std::ceil(4 * sigma));
  const int x0 = std::max(0, static_cast<int>(centre.x) - reach);
  const int x1 = std::min(bgr.cols - 1, static_cast<int>(centre.x) + reach);
  const int y0 = std::max(0, static_cast<int>(centre.y) - reach);
  const int y1 = std::min(bgr.rows - 1, static_cast<int>(centre.y) + reach);
  // the glow: the LED's colour, whitened towards the core
  const double level = fraction * options_.led_glow_level;
  for (int y = y0; y <= y1; ++y) {
    auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = x0; x <= x1; ++x) {
      const double r2 = (x - centre.x) * (x - centre.x) + (y - centre.y) * (y - centre.y);
      const double g = level * std::exp(-r2 / (2 * sigma * sigma));
      for (int c = 0; c < 3; ++c) {
        const double tint = 0.35 + 0.65 * options_.led_rgb[static_cast<size_t>(2 - c)];
        row[x][c] = cv::saturate_cast<uint8_t>(row[x][c] + g * tint);
      }
    }
  }
}

double SceneRenderer3d::DepthM(const cv::Vec3d& world_m) const {
  return (world_m - impl_->pose.position).dot(impl_->pose.forward);
}

cv::Point2d SceneRenderer3d::ProjectPx(const cv::Vec3d& world_m) const {
  const CameraPose& pose = impl_->pose;
  const cv::Vec3d d = world_m - pose.position;
  const double depth = d.dot(pose.forward);
  // OpenGL's pixel (column j) spans [j, j + 1): its centre at j + 0.5 is our j
  return {0.5 * impl_->width + impl_->focal_px * d.dot(pose.right) / depth - 0.5,
          0.5 * impl_->height - impl_->focal_px * d.dot(pose.up) / depth - 0.5};
}

cv::Vec3d SceneRenderer3d::FootCenterM(const RobotPose3d& pose) const {
  const Tip tip = TipFor(lifting_foot_, options_.foot_shape, std::max(0.0, pose.lift_m));
  const cv::Vec3d centre = FootRestCenter(lifting_foot_, options_.foot_shape);
  return tip.pivot + Rotate(tip.axis, tip.angle, centre - tip.pivot);
}

double SceneRenderer3d::PixelsPerMm() const {
  const cv::Vec3d centre = FootRestCenter(lifting_foot_, options_.foot_shape);
  const cv::Point2d moved = ProjectPx(centre + cv::Vec3d(0, 0, 0.001)) - ProjectPx(centre);
  return std::hypot(moved.x, moved.y);
}

cv::Point2d SceneRenderer3d::FootCenterPx() const {
  return ProjectPx(FootRestCenter(lifting_foot_, options_.foot_shape));
}

double SceneRenderer3d::FootDiameterPx() const {
  const cv::Vec3d centre = FootRestCenter(lifting_foot_, options_.foot_shape);
  return FootWidthM(options_.foot_shape) * impl_->focal_px / DepthM(centre);
}

cv::Point2d SceneRenderer3d::LedCenterPx() const { return ProjectPx(LedPosition(options_)); }

double SceneRenderer3d::LedRadiusPx() const {
  return options_.led_radius_m * impl_->focal_px / DepthM(LedPosition(options_));
}

}  // namespace liftoff::synth
