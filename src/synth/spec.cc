#include "liftoff/synth/spec.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "liftoff/core/field_checker.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"

namespace liftoff::synth {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr std::string_view kTruthFormat = "liftoff-synth-truth";
constexpr int64_t kTruthVersion = 1;
constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------
// range checks, named by the struct's field path ("camera.fps")

NumberRange Closed(double min, double max) { return {.min = min, .max = max}; }

bool IsIdCharacter(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
         c == '_' || c == '-';
}

// the camera: frame size, rate, exposure, drops, codec quality
void CheckCamera(const CameraSpec& camera, FieldChecker& check) {
  check.Integer("camera.width_px", camera.width_px, Closed(320, 1920));
  check.Integer("camera.height_px", camera.height_px, Closed(240, 1080));
  if (camera.width_px % 2 != 0) {
    check.Fail("camera.width_px",
               "expected an even width (4:2:0 chroma), got " + std::to_string(camera.width_px));
  }
  if (camera.height_px % 2 != 0) {
    check.Fail("camera.height_px",
               "expected an even height (4:2:0 chroma), got " + std::to_string(camera.height_px));
  }
  check.Number("camera.fps", camera.fps, Closed(1, 1000));
  if (check.ok()) {
    // a hair of slack so that exposure_s = 1 / fps computed elsewhere passes
    const double frame_s = 1.0 / camera.fps;
    check.Number("camera.exposure_s", camera.exposure_s,
                 {.min = 0, .max = frame_s * (1 + 1e-12), .min_exclusive = true});
    check.Number("camera.timestamp_jitter_s", camera.timestamp_jitter_s, Closed(0, 0.4 * frame_s));
  }
  check.Number("camera.drop_probability", camera.drop_probability, Closed(0, 0.5));
  if (camera.codec == VideoCodec::kH264) {
    check.Integer("camera.quality", camera.quality, Closed(0, 51));
  } else if (camera.codec == VideoCodec::kMjpeg) {
    check.Integer("camera.quality", camera.quality, Closed(2, 31));
  }
}

// the nuisances: noise, blur, flicker, shake
void CheckNuisance(const NuisanceSpec& nuisance, FieldChecker& check) {
  check.Number("nuisance.noise_sigma", nuisance.noise_sigma, Closed(0, 30));
  check.Integer("nuisance.motion_blur_samples", nuisance.motion_blur_samples, Closed(1, 16));
  check.Number("nuisance.flicker_amplitude", nuisance.flicker_amplitude, Closed(0, 0.5));
  if (nuisance.flicker_hz != 100.0 && nuisance.flicker_hz != 120.0) {
    check.Fail("nuisance.flicker_hz",
               "expected 100 or 120 (50 or 60 Hz mains), got " + FormatNumber(nuisance.flicker_hz));
  }
  check.Number("nuisance.shake_px", nuisance.shake_px, Closed(0, 2));
}

// the LED: place, size, colour, brightness, switch-on
void CheckLed(const LedSpec& led, FieldChecker& check) {
  check.Number("led.x_frac", led.x_frac, Closed(0, 1));
  check.Number("led.y_frac", led.y_frac, Closed(0, 1));
  check.Number("led.radius_px", led.radius_px, Closed(1, 40));
  check.Integer("led.blue", led.blue, Closed(0, 255));
  check.Integer("led.green", led.green, Closed(0, 255));
  check.Integer("led.red", led.red, Closed(0, 255));
  check.Number("led.intensity", led.intensity, Closed(0.1, 4));
  check.Number("led.bloom", led.bloom, Closed(0, 6));
  check.Number("led.on_video_s", led.on_video_s, Closed(-3600, 7200));
}

// the motion: the height curve, bend and ramp
void CheckMotion(const MotionSpec& motion, FieldChecker& check) {
  const HeightCurveSpec& height = motion.height;
  if (height.kind == "parametric") {
    check.Number("motion.height.liftoff_rad", height.liftoff_rad, Closed(0, kPi));
    check.Number("motion.height.gain_m", height.gain_m,
                 {.min = 0, .max = 10, .min_exclusive = true});
    check.Number("motion.height.exponent", height.exponent,
                 {.min = 0, .max = 5, .min_exclusive = true});
  } else if (height.kind == "csv") {
    if (height.csv_path.empty()) {
      check.Fail("motion.height.csv_path",
                 "expected the path of a height CSV when kind is \"csv\"");
    }
  } else {
    check.Fail("motion.height.kind",
               "expected one of parametric, csv, got \"" + height.kind + "\"");
  }
  check.Number("motion.bend_start_s", motion.bend_start_s, Closed(0, 3600));
  check.Number("motion.bend_end_s", motion.bend_end_s, Closed(0, 3600));
  if (check.ok() && motion.bend_end_s < motion.bend_start_s) {
    check.Fail("motion.bend_end_s", "expected at least bend_start_s (" +
                                        FormatNumber(motion.bend_start_s) + "), got " +
                                        FormatNumber(motion.bend_end_s));
  }
  check.Number("motion.ramp_start_s", motion.ramp_start_s, Closed(0, 3600));
  check.Number("motion.ramp_rate_rad_per_s", motion.ramp_rate_rad_per_s,
               {.min = 0, .max = 10, .min_exclusive = true});
  check.Number("motion.diagonal_lag_rad", motion.diagonal_lag_rad, Closed(-kPi, kPi));
}

// the controller log: LED event, clock, rate, bursts, margins
void CheckLog(const LogSpec& log, FieldChecker& check) {
  check.Integer("log.led_on_device_ns", static_cast<double>(log.led_on_device_ns), Closed(0, 1e15));
  if (!log.led_event && log.led_on_device_ns != 0) {
    check.Fail("log.led_on_device_ns",
               "expected 0 when log.led_event is false (the log's device clock then starts at "
               "the LED switch-on), got " +
                   std::to_string(log.led_on_device_ns));
  }
  check.Number("log.clock_drift_ppm", log.clock_drift_ppm, Closed(-1000, 1000));
  check.Number("log.rate_hz", log.rate_hz, Closed(1, 10000));
  if (check.ok()) check.Number("log.jitter_s", log.jitter_s, Closed(0, 0.5 / log.rate_hz));
  check.Number("log.burst_period_s", log.burst_period_s, Closed(0, 60));
  if (check.ok() && log.burst_period_s > 0) {
    check.Number("log.burst_length_s", log.burst_length_s,
                 {.min = 0, .max = log.burst_period_s, .min_exclusive = true});
  }
  check.Number("log.lead_s", log.lead_s, Closed(0, 60));
  check.Number("log.tail_s", log.tail_s, Closed(0, 60));
}

void CheckSpec(const TrialSpec& spec, FieldChecker& check) {
  // the trial
  if (spec.id.empty() || spec.id.size() > 100 || spec.id.front() == '.' ||
      !std::all_of(spec.id.begin(), spec.id.end(), IsIdCharacter)) {
    check.Fail("id", "expected 1 to 100 of A-Z a-z 0-9 . _ - (not starting with '.'), got \"" +
                         spec.id + "\"");
  }
  check.Number("duration_s", spec.duration_s, {.min = 0, .max = 3600, .min_exclusive = true});
  CheckCamera(spec.camera, check);
  CheckNuisance(spec.nuisance, check);
  CheckLed(spec.led, check);
  CheckMotion(spec.motion, check);
  CheckLog(spec.log, check);
}

// The JSON pointer of a struct field path: "camera.fps" -> "/camera/fps".
std::string JsonPointerOfField(std::string_view field) {
  if (field == "led.blue") return "/led/color_bgr/0";
  if (field == "led.green") return "/led/color_bgr/1";
  if (field == "led.red") return "/led/color_bgr/2";
  if (field == "motion.height.csv_path") return "/motion/height/csv";
  std::string pointer = "/" + std::string(field);
  std::replace(pointer.begin(), pointer.end(), '.', '/');
  return pointer;
}

// ---------------------------------------------------------------------------------------
// JSON field readers: keep the default when the key is absent

void Read(JsonReader& reader, std::string_view key, double& out) {
  if (auto value = reader.OptionalNumber(key)) out = *value;
}
void Read(JsonReader& reader, std::string_view key, int& out) {
  constexpr NumberRange kInt{.min = std::numeric_limits<int>::min(),
                             .max = std::numeric_limits<int>::max()};
  if (auto value = reader.OptionalInteger(key, kInt)) out = static_cast<int>(*value);
}
void Read(JsonReader& reader, std::string_view key, int64_t& out) {
  if (auto value = reader.OptionalInteger(key)) out = *value;
}
void Read(JsonReader& reader, std::string_view key, bool& out) {
  if (auto value = reader.OptionalBoolean(key)) out = *value;
}
void Read(JsonReader& reader, std::string_view key, std::string& out) {
  if (auto value = reader.OptionalString(key)) out = *value;
}

json RegionToJson(const RegionPx& region) {
  return {{"x_px", region.x_px},
          {"y_px", region.y_px},
          {"width_px", region.width_px},
          {"height_px", region.height_px}};
}

RegionPx ReadRegion(JsonReader& reader, std::string_view key) {
  RegionPx region;
  JsonReader object = reader.Object(key);
  constexpr NumberRange kPixels{.min = -1e6, .max = 1e6};
  region.x_px = static_cast<int>(object.Integer("x_px", kPixels));
  region.y_px = static_cast<int>(object.Integer("y_px", kPixels));
  region.width_px = static_cast<int>(object.Integer("width_px", {.min = 0, .max = 1e6}));
  region.height_px = static_cast<int>(object.Integer("height_px", {.min = 0, .max = 1e6}));
  return region;
}

json OptionalToJson(const std::optional<int64_t>& value) {
  return value ? json(*value) : json(nullptr);
}
json OptionalToJson(const std::optional<double>& value) {
  return value ? json(*value) : json(nullptr);
}

// An instant written as "<name>_ns" and "<name>_s": reads the ns, checks the seconds.
std::optional<int64_t> ReadInstant(JsonReader& reader, const std::string& name) {
  const std::optional<int64_t> ns = reader.OptionalInteger(name + "_ns");
  const std::optional<double> seconds = reader.OptionalNumber(name + "_s");
  if (ns && seconds && std::abs(SecondsFromNs(*ns) - *seconds) > 1e-6) {
    reader.Fail(name + "_s", "disagrees with " + name + "_ns (" + FormatSeconds(*ns, 9) +
                                 " s), got " + FormatNumber(*seconds));
  }
  return ns;
}

// ---------------------------------------------------------------------------------------
// CSV height curves

std::string_view Trim(std::string_view text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string_view::npos) return {};
  const size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

std::vector<std::string_view> SplitCommas(std::string_view line) {
  std::vector<std::string_view> cells;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    cells.push_back(Trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

std::optional<double> ParseNumber(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() ||
      !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

struct HeightCurve {
  std::vector<double> rotation_rad, height_m;
};

Result<HeightCurve> LoadHeightCurve(const fs::path& path, Foot foot) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::string text, ReadWholeFile(path));
  const std::string name = DisplayPath(path);
  const std::string height_column = std::string(FootName(foot)) + "_height_m";
  HeightCurve curve;
  std::optional<size_t> rotation_index, height_index;
  size_t columns = 0;
  size_t line_number = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    const std::string_view trimmed = Trim(line);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    const std::vector<std::string_view> cells = SplitCommas(trimmed);
    const std::string where = name + ":" + std::to_string(line_number) + ": ";

    // the header names the columns
    if (!rotation_index) {
      columns = cells.size();
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == "rotation_rad") rotation_index = i;
        if (cells[i] == height_column) height_index = i;
      }
      if (!rotation_index || !height_index) {
        return ParseError(where + "expected a header with columns rotation_rad and " +
                          height_column + ", got \"" + std::string(trimmed) + "\"");
      }
      continue;
    }

    // a row: |rotation| strictly increasing
    if (cells.size() != columns) {
      return ParseError(where + "expected " + std::to_string(columns) + " columns, got " +
                        std::to_string(cells.size()));
    }
    const std::optional<double> rotation = ParseNumber(cells[*rotation_index]);
    if (!rotation) {
      return ParseError(where + "rotation_rad: expected a number, got \"" +
                        std::string(cells[*rotation_index]) + "\"");
    }
    const std::optional<double> height = ParseNumber(cells[*height_index]);
    if (!height) {
      return ParseError(where + height_column + ": expected a number, got \"" +
                        std::string(cells[*height_index]) + "\"");
    }
    const double abs_rotation = std::abs(*rotation);
    if (!curve.rotation_rad.empty() && !(abs_rotation > curve.rotation_rad.back())) {
      return ParseError(where +
                        "rotation_rad: expected |rotation| to increase from row to row, "
                        "got " +
                        FormatNumber(*rotation) + " after " +
                        FormatNumber(curve.rotation_rad.back()));
    }
    curve.rotation_rad.push_back(abs_rotation);
    curve.height_m.push_back(*height);
  }
  if (!rotation_index) return ParseError(name + ": expected a header line, got an empty file");
  if (curve.rotation_rad.size() < 2) {
    return ParseError(name + ": expected at least two rows of rotation_rad and " + height_column +
                      ", got " + std::to_string(curve.rotation_rad.size()));
  }
  return curve;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// codecs

std::string_view VideoCodecName(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264: return "h264";
    case VideoCodec::kMjpeg: return "mjpeg";
    case VideoCodec::kFfv1: return "ffv1";
  }
  return "?";
}

std::optional<VideoCodec> ParseVideoCodec(std::string_view text) {
  for (VideoCodec codec : {VideoCodec::kH264, VideoCodec::kMjpeg, VideoCodec::kFfv1}) {
    if (text == VideoCodecName(codec)) return codec;
  }
  return std::nullopt;
}

std::string_view VideoCodecExtension(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264: return ".mp4";
    case VideoCodec::kMjpeg: return ".avi";
    case VideoCodec::kFfv1: return ".mkv";
  }
  return "";
}

// ---------------------------------------------------------------------------------------
// trial specs

Status TrialSpec::Validate() const {
  FieldChecker check;
  CheckSpec(*this, check);
  return check.status();
}

namespace {

// The sections of a trial spec's JSON, each into its struct; a missing key keeps the
// default, a bad one is reported through the reader.

// the seed is unsigned 64-bit, beyond what JsonReader's integers hold
void ReadSeed(JsonReader& root, uint64_t& out) {
  const json* seed = root.Raw("seed");
  if (seed == nullptr || seed->is_null()) return;
  if (seed->is_number_unsigned()) {
    out = seed->get<uint64_t>();
  } else if (seed->is_number_integer() && seed->get<int64_t>() >= 0) {
    out = static_cast<uint64_t>(seed->get<int64_t>());
  } else {
    root.Fail("seed", "expected an integer in [0, 2^64), got " + seed->dump());
  }
}

void ReadCamera(JsonReader& camera, CameraSpec& out) {
  Read(camera, "width_px", out.width_px);
  Read(camera, "height_px", out.height_px);
  Read(camera, "fps", out.fps);
  Read(camera, "exposure_s", out.exposure_s);
  Read(camera, "drop_probability", out.drop_probability);
  Read(camera, "timestamp_jitter_s", out.timestamp_jitter_s);
  if (auto codec = camera.OptionalEnum("codec", {"h264", "mjpeg", "ffv1"})) {
    out.codec = static_cast<VideoCodec>(*codec);
  }
  Read(camera, "quality", out.quality);
}

void ReadNuisance(JsonReader& nuisance, NuisanceSpec& out) {
  Read(nuisance, "noise_sigma", out.noise_sigma);
  Read(nuisance, "motion_blur_samples", out.motion_blur_samples);
  Read(nuisance, "flicker_amplitude", out.flicker_amplitude);
  Read(nuisance, "flicker_hz", out.flicker_hz);
  Read(nuisance, "shake_px", out.shake_px);
  Read(nuisance, "shadow", out.shadow);
}

void ReadLed(JsonReader& led, LedSpec& out) {
  Read(led, "x_frac", out.x_frac);
  Read(led, "y_frac", out.y_frac);
  Read(led, "radius_px", out.radius_px);
  if (auto bgr = led.OptionalNumberArray("color_bgr", 3)) {
    for (size_t i = 0; i < 3; ++i) {
      if ((*bgr)[i] != std::floor((*bgr)[i])) {
        led.Fail("color_bgr", "expected 3 integers (blue, green, red), got " +
                                  FormatNumber((*bgr)[i]) + " at index " + std::to_string(i));
      }
    }
    // out-of-range values are left to the range check, which names the element
    const auto channel = [](double value) {
      return static_cast<int>(std::clamp(value, -1e6, 1e6));
    };
    out.blue = channel((*bgr)[0]);
    out.green = channel((*bgr)[1]);
    out.red = channel((*bgr)[2]);
  }
  Read(led, "intensity", out.intensity);
  Read(led, "bloom", out.bloom);
  Read(led, "on_video_s", out.on_video_s);
}

// a CSV curve's path is relative to the spec's folder
void ReadHeightCurve(JsonReader& height, const fs::path& base_dir, HeightCurveSpec& curve) {
  if (auto kind = height.OptionalEnum("kind", {"parametric", "csv"})) {
    curve.kind = *kind == 0 ? "parametric" : "csv";
  }
  Read(height, "liftoff_rad", curve.liftoff_rad);
  Read(height, "gain_m", curve.gain_m);
  Read(height, "exponent", curve.exponent);
  if (auto csv = height.OptionalString("csv")) {
    if (csv->empty()) {
      height.Fail("csv", "expected a non-empty path");
    } else {
      curve.csv_path = (base_dir / fs::path(*csv)).lexically_normal();
    }
  }
}

void ReadMotion(JsonReader& motion, const fs::path& base_dir, MotionSpec& out) {
  if (auto foot = motion.OptionalEnum("foot", {"A", "B", "C", "D"})) {
    out.foot = static_cast<Foot>(*foot);
  }
  if (auto rotation = motion.OptionalEnum("rotation", {"+", "-"})) {
    out.rotation = *rotation == 0 ? RotationSense::kPositive : RotationSense::kNegative;
  }
  if (auto height = motion.OptionalObject("height")) ReadHeightCurve(*height, base_dir, out.height);
  Read(motion, "bend_start_s", out.bend_start_s);
  Read(motion, "bend_end_s", out.bend_end_s);
  Read(motion, "ramp_start_s", out.ramp_start_s);
  Read(motion, "ramp_rate_rad_per_s", out.ramp_rate_rad_per_s);
  Read(motion, "diagonal_lag_rad", out.diagonal_lag_rad);
}

void ReadLog(JsonReader& log, LogSpec& out) {
  Read(log, "led_on_device_ns", out.led_on_device_ns);
  Read(log, "clock_drift_ppm", out.clock_drift_ppm);
  Read(log, "rate_hz", out.rate_hz);
  Read(log, "jitter_s", out.jitter_s);
  Read(log, "burst_period_s", out.burst_period_s);
  Read(log, "burst_length_s", out.burst_length_s);
  Read(log, "led_event", out.led_event);
  Read(log, "lead_s", out.lead_s);
  Read(log, "tail_s", out.tail_s);
}

}  // namespace

Result<TrialSpec> TrialSpecFromJson(const json& document, const std::string& source,
                                    const fs::path& base_dir) {
  TrialSpec spec;
  JsonReader root(document, source);

  // the trial, then its sections
  Read(root, "id", spec.id);
  ReadSeed(root, spec.seed);
  Read(root, "duration_s", spec.duration_s);
  if (auto camera = root.OptionalObject("camera")) ReadCamera(*camera, spec.camera);
  if (auto nuisance = root.OptionalObject("nuisance")) ReadNuisance(*nuisance, spec.nuisance);
  if (auto led = root.OptionalObject("led")) ReadLed(*led, spec.led);
  if (auto motion = root.OptionalObject("motion")) ReadMotion(*motion, base_dir, spec.motion);
  if (auto log = root.OptionalObject("log")) ReadLog(*log, spec.log);
  LIFTOFF_RETURN_IF_ERROR(root.Finish());

  // values: the same checks as Validate(), named by JSON pointer
  FieldChecker check;
  CheckSpec(spec, check);
  if (!check.ok()) {
    return InvalidArgumentError(source + ": " + JsonPointerOfField(check.field()) + ": " +
                                check.message());
  }
  return spec;
}

json TrialSpecToJson(const TrialSpec& spec) {
  const CameraSpec& camera = spec.camera;
  const NuisanceSpec& nuisance = spec.nuisance;
  const LedSpec& led = spec.led;
  const MotionSpec& motion = spec.motion;
  const LogSpec& log = spec.log;
  json height = {{"kind", motion.height.kind},
                 {"liftoff_rad", motion.height.liftoff_rad},
                 {"gain_m", motion.height.gain_m},
                 {"exponent", motion.height.exponent}};
  if (!motion.height.csv_path.empty()) height["csv"] = motion.height.csv_path.generic_string();
  return {
      {"id", spec.id},
      {"seed", spec.seed},
      {"duration_s", spec.duration_s},
      {"camera",
       {{"width_px", camera.width_px},
        {"height_px", camera.height_px},
        {"fps", camera.fps},
        {"exposure_s", camera.exposure_s},
        {"drop_probability", camera.drop_probability},
        {"timestamp_jitter_s", camera.timestamp_jitter_s},
        {"codec", VideoCodecName(camera.codec)},
        {"quality", camera.quality}}},
      {"nuisance",
       {{"noise_sigma", nuisance.noise_sigma},
        {"motion_blur_samples", nuisance.motion_blur_samples},
        {"flicker_amplitude", nuisance.flicker_amplitude},
        {"flicker_hz", nuisance.flicker_hz},
        {"shake_px", nuisance.shake_px},
        {"shadow", nuisance.shadow}}},
      {"led",
       {{"x_frac", led.x_frac},
        {"y_frac", led.y_frac},
        {"radius_px", led.radius_px},
        {"color_bgr", {led.blue, led.green, led.red}},
        {"intensity", led.intensity},
        {"bloom", led.bloom},
        {"on_video_s", led.on_video_s}}},
      {"motion",
       {{"foot", FootName(motion.foot)},
        {"rotation", RotationSenseName(motion.rotation)},
        {"height", height},
        {"bend_start_s", motion.bend_start_s},
        {"bend_end_s", motion.bend_end_s},
        {"ramp_start_s", motion.ramp_start_s},
        {"ramp_rate_rad_per_s", motion.ramp_rate_rad_per_s},
        {"diagonal_lag_rad", motion.diagonal_lag_rad}}},
      {"log",
       {{"led_on_device_ns", log.led_on_device_ns},
        {"clock_drift_ppm", log.clock_drift_ppm},
        {"rate_hz", log.rate_hz},
        {"jitter_s", log.jitter_s},
        {"burst_period_s", log.burst_period_s},
        {"burst_length_s", log.burst_length_s},
        {"led_event", log.led_event},
        {"lead_s", log.lead_s},
        {"tail_s", log.tail_s}}},
  };
}

// ---------------------------------------------------------------------------------------
// ground truth

json GroundTruth::ToJson() const {
  const auto seconds = [](const std::optional<int64_t>& ns) {
    return ns ? json(SecondsFromNs(*ns)) : json(nullptr);
  };
  return {
      {"format", kTruthFormat},
      {"version", kTruthVersion},
      {"trial_id", trial_id},
      {"foot", FootName(foot)},
      {"led_on_video_ns", OptionalToJson(led_on_video_ns)},
      {"led_on_video_s", seconds(led_on_video_ns)},
      {"led_first_frame", OptionalToJson(led_first_frame)},
      {"led_first_frame_fraction", led_first_frame_fraction},
      {"liftoff_0mm_video_ns", OptionalToJson(liftoff_0mm_video_ns)},
      {"liftoff_0mm_video_s", seconds(liftoff_0mm_video_ns)},
      {"liftoff_0mm_rad", OptionalToJson(liftoff_0mm_rad)},
      {"liftoff_1mm_video_ns", OptionalToJson(liftoff_1mm_video_ns)},
      {"liftoff_1mm_video_s", seconds(liftoff_1mm_video_ns)},
      {"liftoff_1mm_rad", OptionalToJson(liftoff_1mm_rad)},
      {"px_per_mm", px_per_mm},
      {"foot_rest_bottom_px", foot_rest_bottom_px},
      {"led_roi_px", RegionToJson(led_roi_px)},
      {"foot_roi_px", RegionToJson(foot_roi_px)},
      {"frame_count", frame_times_ns.size()},
      {"frame_times_ns", frame_times_ns},
  };
}

Result<GroundTruth> GroundTruthFromJson(const json& document, const std::string& source) {
  GroundTruth truth;
  JsonReader root(document, source);
  root.Enum("format", {kTruthFormat});
  if (const int64_t version = root.Integer("version"); !root.failed() && version != kTruthVersion) {
    root.Fail("version",
              "expected " + std::to_string(kTruthVersion) + ", got " + std::to_string(version));
  }
  truth.trial_id = root.String("trial_id");
  truth.foot = static_cast<Foot>(root.Enum("foot", {"A", "B", "C", "D"}));
  truth.led_on_video_ns = ReadInstant(root, "led_on_video");
  truth.led_first_frame = root.OptionalInteger("led_first_frame", {.min = 0});
  truth.led_first_frame_fraction = root.Number("led_first_frame_fraction", Closed(0, 1));
  truth.liftoff_0mm_video_ns = ReadInstant(root, "liftoff_0mm_video");
  truth.liftoff_0mm_rad = root.OptionalNumber("liftoff_0mm_rad");
  truth.liftoff_1mm_video_ns = ReadInstant(root, "liftoff_1mm_video");
  truth.liftoff_1mm_rad = root.OptionalNumber("liftoff_1mm_rad");
  truth.px_per_mm = root.Number("px_per_mm", {.min = 0});
  truth.foot_rest_bottom_px = root.Number("foot_rest_bottom_px");
  truth.led_roi_px = ReadRegion(root, "led_roi_px");
  truth.foot_roi_px = ReadRegion(root, "foot_roi_px");

  // frame times: integers, strictly increasing, as many as frame_count says
  const std::optional<int64_t> frame_count = root.OptionalInteger("frame_count", {.min = 0});
  if (const json* times = root.Raw("frame_times_ns"); times == nullptr || !times->is_array()) {
    root.Fail("frame_times_ns", "expected an array of integer ns");
  } else {
    for (size_t i = 0; i < times->size(); ++i) {
      const json& time = (*times)[i];
      if (!time.is_number_integer()) {
        root.Fail("frame_times_ns",
                  "expected integer ns, got " + time.dump() + " at index " + std::to_string(i));
        break;
      }
      const int64_t ns = time.get<int64_t>();
      if (!truth.frame_times_ns.empty() && ns <= truth.frame_times_ns.back()) {
        root.Fail("frame_times_ns", "expected strictly increasing times, got " +
                                        std::to_string(ns) + " after " +
                                        std::to_string(truth.frame_times_ns.back()) + " at index " +
                                        std::to_string(i));
        break;
      }
      truth.frame_times_ns.push_back(ns);
    }
    if (frame_count && !root.failed() &&
        static_cast<size_t>(*frame_count) != truth.frame_times_ns.size()) {
      root.Fail("frame_count", "expected the number of frame_times_ns (" +
                                   std::to_string(truth.frame_times_ns.size()) + "), got " +
                                   std::to_string(*frame_count));
    }
  }
  LIFTOFF_RETURN_IF_ERROR(root.Finish());
  return truth;
}

// ---------------------------------------------------------------------------------------
// the timeline

Result<Timeline> Timeline::Create(const TrialSpec& spec) {
  LIFTOFF_RETURN_IF_ERROR(spec.Validate());
  Timeline timeline;
  timeline.spec_ = spec;
  if (spec.motion.height.kind == "csv") {
    LIFTOFF_ASSIGN_OR_RETURN(HeightCurve curve,
                             LoadHeightCurve(spec.motion.height.csv_path, spec.motion.foot));
    timeline.curve_rotation_rad_ = std::move(curve.rotation_rad);
    timeline.curve_height_m_ = std::move(curve.height_m);
  }

  // clocks: the test clock starts at the LED switch-on, the device clock runs with drift
  timeline.led_on_video_ns_ = NsFromSeconds(spec.led.on_video_s);
  timeline.duration_ns_ = NsFromSeconds(spec.duration_s);
  const double scale = 1.0 + spec.log.clock_drift_ppm * 1e-6;
  timeline.device_from_video_ = {timeline.led_on_video_ns_, spec.log.led_on_device_ns, scale};
  timeline.video_from_device_ = {spec.log.led_on_device_ns, timeline.led_on_video_ns_, 1.0 / scale};
  return timeline;
}

int64_t ExposureNs(const CameraSpec& camera) {
  return std::max<int64_t>(1, NsFromSeconds(camera.exposure_s));
}

int64_t ExposureStartNs(const CameraSpec& camera, int64_t t_frame_ns) {
  return t_frame_ns - ExposureNs(camera) / 2;
}

std::optional<int64_t> LedOnVideoNs(const TrialSpec& spec) {
  const int64_t led_ns = NsFromSeconds(spec.led.on_video_s);
  if (spec.led.on_video_s < 0 || led_ns >= NsFromSeconds(spec.duration_s)) return std::nullopt;
  return led_ns;
}

double LedOnFractionOfExposure(const TrialSpec& spec, int64_t t_frame_ns) {
  const std::optional<int64_t> led_ns = LedOnVideoNs(spec);
  if (!led_ns) return 0.0;
  const int64_t exposure_ns = ExposureNs(spec.camera);
  const int64_t end_ns = ExposureStartNs(spec.camera, t_frame_ns) + exposure_ns;
  const int64_t on_ns = std::clamp(end_ns - *led_ns, int64_t{0}, exposure_ns);
  return static_cast<double>(on_ns) / static_cast<double>(exposure_ns);
}

std::optional<int64_t> Timeline::LedOnVideoNs() const { return synth::LedOnVideoNs(spec_); }

double Timeline::TestSecondsFromVideoNs(int64_t t_video_ns) const {
  return SecondsFromNs(t_video_ns - led_on_video_ns_);
}

int64_t Timeline::DeviceNsFromVideoNs(int64_t t_video_ns) const {
  return device_from_video_(t_video_ns);
}

int64_t Timeline::VideoNsFromDeviceNs(int64_t t_device_ns) const {
  return video_from_device_(t_device_ns);
}

double Timeline::VertebraRadAt(double test_s) const {
  const MotionSpec& motion = spec_.motion;
  if (test_s <= motion.ramp_start_s) return 0.0;
  return static_cast<double>(static_cast<int>(motion.rotation)) * motion.ramp_rate_rad_per_s *
         (test_s - motion.ramp_start_s);
}

double Timeline::BendSpoolRadAt(double test_s, double target_spool_rad) const {
  const MotionSpec& motion = spec_.motion;
  if (test_s <= motion.bend_start_s) return 0.0;
  if (test_s >= motion.bend_end_s) return target_spool_rad;
  return target_spool_rad * (test_s - motion.bend_start_s) /
         (motion.bend_end_s - motion.bend_start_s);
}

double Timeline::CurveHeightM(double abs_rotation_rad) const {
  const HeightCurveSpec& height = spec_.motion.height;
  if (curve_rotation_rad_.empty()) {
    if (!(abs_rotation_rad > height.liftoff_rad)) return 0.0;
    return height.gain_m * std::pow(abs_rotation_rad - height.liftoff_rad, height.exponent);
  }
  // linear between rows, held beyond the ends, never below the ground
  const std::vector<double>& rotation = curve_rotation_rad_;
  const std::vector<double>& value = curve_height_m_;
  if (abs_rotation_rad <= rotation.front()) return std::max(0.0, value.front());
  if (abs_rotation_rad >= rotation.back()) return std::max(0.0, value.back());
  const size_t i = static_cast<size_t>(
      std::upper_bound(rotation.begin(), rotation.end(), abs_rotation_rad) - rotation.begin());
  const double fraction = (abs_rotation_rad - rotation[i - 1]) / (rotation[i] - rotation[i - 1]);
  return std::max(0.0, value[i - 1] + fraction * (value[i] - value[i - 1]));
}

double Timeline::HeightAtRotation(double abs_rotation_rad, bool diagonal) const {
  if (!diagonal) return CurveHeightM(abs_rotation_rad);
  const double lag_rad = spec_.motion.diagonal_lag_rad;
  if (!(lag_rad > 0) || abs_rotation_rad <= lag_rad) return 0.0;
  return CurveHeightM(abs_rotation_rad - lag_rad);
}

double Timeline::FootHeightMAt(Foot foot, int64_t t_video_ns) const {
  const double abs_rotation_rad = std::abs(VertebraRadAt(TestSecondsFromVideoNs(t_video_ns)));
  if (foot == spec_.motion.foot) return HeightAtRotation(abs_rotation_rad, false);
  if (foot == DiagonalPartner(spec_.motion.foot)) return HeightAtRotation(abs_rotation_rad, true);
  return 0.0;
}

bool Timeline::LedOnAt(int64_t t_video_ns) const {
  const std::optional<int64_t> on_ns = LedOnVideoNs();
  return on_ns && t_video_ns >= *on_ns;
}

std::optional<double> Timeline::FirstRotationAbove(double height_m) const {
  const HeightCurveSpec& height = spec_.motion.height;
  if (curve_rotation_rad_.empty()) {
    if (height_m < 0) return 0.0;
    return height.liftoff_rad + std::pow(height_m / height.gain_m, 1.0 / height.exponent);
  }
  // walk the segments to the first one that rises above the height
  const std::vector<double>& rotation = curve_rotation_rad_;
  const std::vector<double>& value = curve_height_m_;
  if (std::max(0.0, value.front()) > height_m) return 0.0;
  for (size_t i = 1; i < rotation.size(); ++i) {
    if (value[i] > height_m) {
      const double fraction = (height_m - value[i - 1]) / (value[i] - value[i - 1]);
      return rotation[i - 1] + fraction * (rotation[i] - rotation[i - 1]);
    }
  }
  return std::nullopt;
}

std::optional<int64_t> Timeline::FirstVideoNsAbove(double height_m) const {
  const Foot foot = spec_.motion.foot;
  const auto above = [&](int64_t t_video_ns) { return FootHeightMAt(foot, t_video_ns) > height_m; };
  if (above(0)) return 0;
  const std::optional<double> rotation_rad = FirstRotationAbove(height_m);
  if (!rotation_rad) return std::nullopt;

  // invert the ramp for a first guess, within a few ns of the answer
  const double test_s =
      spec_.motion.ramp_start_s + *rotation_rad / spec_.motion.ramp_rate_rad_per_s;
  const double guess_ns = static_cast<double>(led_on_video_ns_) + test_s * 1e9;
  if (!(guess_ns <= static_cast<double>(duration_ns_) + 1e6)) return std::nullopt;
  const int64_t guess =
      std::clamp(static_cast<int64_t>(std::llround(guess_ns)), int64_t{0}, duration_ns_);

  // bracket: not above at `low`, above at `high`
  int64_t low = std::max<int64_t>(0, guess - 16);
  int64_t high = std::min(duration_ns_, guess + 16);
  for (int64_t step = 32; above(low); step *= 2) low = std::max<int64_t>(0, low - step);
  for (int64_t step = 32; !above(high); step *= 2) {
    if (high == duration_ns_) return std::nullopt;
    high = std::min(duration_ns_, high + step);
  }
  // bisect to the first ns above
  while (high - low > 1) {
    const int64_t middle = low + (high - low) / 2;
    (above(middle) ? high : low) = middle;
  }
  return high;
}

}  // namespace liftoff::synth
