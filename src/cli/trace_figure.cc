// A trial's traces from its video analysis (TraceFigure, figures.h): what the LED detector
// and the foot tracker measured frame by frame, with the instants found in them.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "liftoff/cli/figures.h"
#include "liftoff/core/time.h"
#include "liftoff/core/text.h"

namespace liftoff::cli {
namespace {

// one detected instant: its interval and where it sits on the height curve
struct Instant {
  std::string name;
  std::string label;
  std::string colour;
  int64_t t_ns = 0;
  int64_t uncertainty_ns = 0;
  double height = 0.0;  // the foot panel's unit
};

std::string Seconds(int64_t t_ns) { return FormatFixed(SecondsFromNs(t_ns), 6); }

// the foot's height in the figure's unit: mm with a scale, else px
double HeightUnitsPerPx(const video::FootTrack& foot) {
  return foot.px_per_mm > 0 ? 1.0 / foot.px_per_mm : 1.0;
}

std::vector<Instant> Instants(const video::ClipAnalysis& clip) {
  std::vector<Instant> instants;
  const video::LedPulse& led = clip.led_on();
  instants.push_back({"led_on", "LED on", "#2ca02c", led.on_ns, led.on_uncertainty_ns, 0.0});
  if (!clip.foot) return instants;
  const video::FootTrack& foot = *clip.foot;
  const double threshold = foot.threshold_px * HeightUnitsPerPx(foot);
  const bool onset_is_liftoff = clip.liftoff_instant == video::LiftoffInstant::kOnset;
  const video::TimedEvent& liftoff = onset_is_liftoff ? foot.onset : foot.above_threshold;
  instants.push_back({"liftoff", onset_is_liftoff ? "liftoff (onset of rise)" : "liftoff",
                      "#d62728", liftoff.t_ns, liftoff.uncertainty_ns,
                      onset_is_liftoff ? 0.0 : threshold});
  if (onset_is_liftoff) {
    instants.push_back({"above_threshold", "above the threshold", "#9467bd",
                        foot.above_threshold.t_ns, foot.above_threshold.uncertainty_ns,
                        threshold});
  } else {
    instants.push_back({"onset", "onset of rise", "#ff7f0e", foot.onset.t_ns,
                        foot.onset.uncertainty_ns, 0.0});
  }
  return instants;
}

std::string InstantsBlock(const std::vector<Instant>& instants) {
  std::string block =
      "# block 0: the detected instants, video clock: name t_s lower_s upper_s height "
      "(lower, upper: the uncertainty interval; height: where it is drawn on the foot's "
      "curve)\n";
  for (const Instant& instant : instants) {
    block += instant.name + " " + Seconds(instant.t_ns) + " " +
             Seconds(instant.t_ns - instant.uncertainty_ns) + " " +
             Seconds(instant.t_ns + instant.uncertainty_ns) + " " +
             FormatFixed(instant.height, 4) + "\n";
  }
  return block;
}

std::string LedBlock(const video::LedResult& led) {
  std::string block =
      "# block: the LED's brightness, its region's mean of B, G and R: t_s brightness_levels\n";
  for (size_t i = 0; i < led.trace_t_ns.size() && i < led.trace_brightness_levels.size(); ++i) {
    block += Seconds(led.trace_t_ns[i]) + " " + FormatFixed(led.trace_brightness_levels[i], 2) +
             "\n";
  }
  return block;
}

std::string FootBlock(const video::FootTrack& foot) {
  const double per_px = HeightUnitsPerPx(foot);
  std::string block = std::string("# block: the foot's height above its rest: t_s ") +
                      (foot.px_per_mm > 0 ? "height_mm" : "height_px") + "\n";
  for (const video::HeightSample& sample : foot.samples) {
    block += Seconds(sample.t_ns + foot.exposure_offset_ns) + " " +
             FormatFixed((sample.rise_px - foot.rest_rise_px) * per_px, 4) + "\n";
  }
  return block;
}

// every instant as a line across the panel, its interval shaded
std::string InstantMarks(const std::vector<Instant>& instants) {
  std::string marks = "  unset arrow\n  unset object\n";
  int tag = 1;
  for (const Instant& instant : instants) {
    const std::string at = Seconds(instant.t_ns);
    marks += "  set object " + std::to_string(tag) + " rect from " +
             Seconds(instant.t_ns - instant.uncertainty_ns) + ", graph 0 to " +
             Seconds(instant.t_ns + instant.uncertainty_ns) + ", graph 1 fc rgb \"" +
             instant.colour + "\" fs transparent solid 0.3 noborder behind\n";
    marks += "  set arrow " + std::to_string(tag) + " from " + at + ", graph 0 to " + at +
             ", graph 1 nohead lw 1.5 lc rgb \"" + instant.colour + "\"\n";
    ++tag;
  }
  return marks;
}

// both panels over the clip's frames (the traces' first and last times)
std::string XRange(const video::ClipAnalysis& clip) {
  int64_t first_ns = clip.led_on().on_ns, last_ns = first_ns;
  const auto cover = [&](int64_t t_ns) {
    first_ns = std::min(first_ns, t_ns);
    last_ns = std::max(last_ns, t_ns);
  };
  for (const int64_t t_ns : clip.led.trace_t_ns) cover(t_ns);
  if (clip.foot) {
    for (const video::HeightSample& sample : clip.foot->samples) {
      cover(sample.t_ns + clip.foot->exposure_offset_ns);
    }
  }
  return "  set xrange [" + Seconds(first_ns) + ":" + Seconds(last_ns) + "]\n";
}

std::string Body(const std::string& name, const std::string& trial_id,
                 const video::ClipAnalysis& clip, const std::vector<Instant>& instants,
                 bool led_traced) {
  const std::string data = "\"" + name + ".dat\"";
  std::string body = "  set multiplot layout " + std::string(led_traced && clip.foot ? "2" : "1") +
                     ",1 title \"" +
                     FigureScriptText("trial " + trial_id + ": " +
                                      clip.video_path.filename().string() +
                                      (led_traced ? "" : " (LED located automatically: its "
                                                         "brightness is not traced)")) +
                     "\" noenhanced\n  set xlabel \"video time (s)\"\n  set grid\n"
                     "  set key top center opaque\n" + XRange(clip);
  if (led_traced) {
    body += InstantMarks(instants) +
            "  set title \"LED brightness (mean of its region)\"\n"
            "  set ylabel \"grey level (0..255)\"\n"
            "  plot " + data + " index 1 using 1:2 with lines lw 1.5 lc rgb \"#e6b800\" "
            "title \"LED\"\n";
  }
  if (clip.foot) {
    const video::FootTrack& foot = *clip.foot;
    const std::string unit = foot.px_per_mm > 0 ? "mm" : "px";
    const double threshold_units = foot.threshold_px * HeightUnitsPerPx(foot);
    const std::string threshold = FormatFixed(threshold_units, 4);
    body += InstantMarks(instants) + "  set object 9 rect from " + Seconds(clip.rest_from_ns) +
            ", graph 0 to " + Seconds(clip.rest_to_ns) +
            ", graph 1 fc rgb \"#808080\" fs transparent solid 0.15 noborder behind\n"
            "  set arrow 9 from graph 0, first " +
            threshold + " to graph 1, first " + threshold +
            " nohead dt 2 lc rgb \"#d62728\"\n"
            "  set title \"Foot height above rest (grey: rest window; dashed: threshold " +
            FormatFixed(threshold_units, 2) + " " + unit + ")\"\n  set ylabel \"height (" + unit +
            ")\"\n  plot " + data + " index " + (led_traced ? "2" : "1") +
            " using 1:2 with lines lw 1.5 lc rgb \"#1f77b4\" title \"foot\"";
    for (size_t row = 0; row < instants.size(); ++row) {
      body += ", \\\n       " + data + " index 0 every ::" + std::to_string(row) +
              "::" + std::to_string(row) + " using 2:5:3:4 with xerrorbars pt 7 lc rgb \"" +
              instants[row].colour + "\" title \"" + instants[row].label + "\"";
    }
    body += "\n";
  }
  return body + "  unset multiplot\n";
}

}  // namespace

std::string FigureScriptText(std::string_view text) {
  std::string safe(text);
  for (char& c : safe) {
    if (c == '"') c = '\'';
    if (c == '\\') c = '/';
  }
  return safe;
}

std::optional<Figure> TraceFigure(const std::string& name, const std::string& trial_id,
                                  const video::ClipAnalysis& clip) {
  if (clip.led.pulses.empty()) return std::nullopt;  // no analysis holds none; defensive
  const bool led_traced = !clip.led.trace_t_ns.empty();
  if (!led_traced && !clip.foot) return std::nullopt;
  const std::vector<Instant> instants = Instants(clip);
  Figure figure{name, "trial " + trial_id + ": LED brightness and foot height with the detected "
                      "instants", "", ""};
  figure.data = "# trial " + trial_id + ", " + clip.video_path.string() +
                "; video clock, s\n# rest window: " + Seconds(clip.rest_from_ns) + " " +
                Seconds(clip.rest_to_ns) + "\n" + InstantsBlock(instants);
  if (led_traced) figure.data += "\n\n" + LedBlock(clip.led);
  if (clip.foot) figure.data += "\n\n" + FootBlock(*clip.foot);
  figure.body = Body(name, trial_id, clip, instants, led_traced);
  return figure;
}

}  // namespace liftoff::cli
