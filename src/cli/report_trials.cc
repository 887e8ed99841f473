#include "report_trials.h"

#include <cstdint>
#include <ostream>

#include "liftoff/cli/video_commands.h"
#include "liftoff/core/file.h"
#include "liftoff/core/markup.h"
#include "liftoff/core/text.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;

// why a trial has no evidence from its video
std::string WithoutVideo(const sync::TrialOutcome& outcome) {
  if (outcome.trial.times) return "times given by hand (no video analysed)";
  if (!outcome.trial.video_path) return "no video";
  return "its video analysis failed";
}

// the figure's files in Markdown, relative to the page
std::string FigureLinks(const Figure& figure) {
  const std::string stem = "figures/" + figure.name;
  return "script [" + stem + ".gp](" + stem + ".gp), data [" + stem + ".dat](" + stem + ".dat)";
}

std::string EvidenceMarkdown(const TrialEvidence& evidence, bool drawn) {
  std::string text;
  if (evidence.traces) {
    text += "  - traces: ";
    if (drawn) {
      text += "![" + evidence.traces->title + "](figures/" + evidence.traces->name + ".png) ";
    }
    text += FigureLinks(*evidence.traces) + "\n";
  } else {
    text += "  - no traces figure: " + evidence.no_traces + "\n";
  }
  if (!evidence.image.empty()) {
    text += "  - verification image: [" + evidence.image.generic_string() + "](" +
            evidence.image.generic_string() + ")\n";
  } else {
    text += "  - no verification image: " + evidence.no_image + "\n";
  }
  return text;
}

Result<std::string> EvidenceHtml(const TrialEvidence& evidence, bool drawn, const fs::path& dir) {
  std::string html = "<div class=\"evidence\">";
  if (evidence.traces && drawn) {
    LIFTOFF_ASSIGN_OR_RETURN(
        const std::string img,
        InlinePng(dir / "figures" / (evidence.traces->name + ".png"), evidence.traces->title));
    html += "<figure>" + img + "<figcaption>traces: LED brightness, foot height and the "
            "detected instants</figcaption></figure>";
  } else {
    html += "<p>no traces figure: " +
            EscapeMarkup(evidence.traces ? "not drawn (see Figures)" : evidence.no_traces) +
            "</p>";
  }
  if (!evidence.image.empty()) {
    LIFTOFF_ASSIGN_OR_RETURN(const std::string img,
                             InlinePng(dir / evidence.image, "verification image"));
    html += "<figure>" + img + "<figcaption>verification image (" +
            EscapeMarkup(evidence.image.generic_string()) + "): what was tracked</figcaption>"
            "</figure>";
  } else {
    html += "<p>no verification image: " + EscapeMarkup(evidence.no_image) + "</p>";
  }
  return html + "</div>";
}

}  // namespace

Result<std::vector<TrialEvidence>> WriteTrialEvidence(const CampaignAnalysis& campaign,
                                                      const fs::path& dir,
                                                      const std::string& gnuplot, Status& drawn,
                                                      std::ostream& err) {
  const auto& outcomes = campaign.analysis.outcomes;
  std::vector<std::string> ids;
  for (const sync::TrialOutcome& outcome : outcomes) ids.push_back(outcome.trial.id);
  const std::vector<std::string> stems = TrialFileStems(ids);

  // the verification images (a second decode of each video, up to the frames they need)
  const TrialVerifications images =
      WriteTrialVerifications(campaign.analysis, stems, dir / "trials", err);
  if (!images.written.empty()) {
    err << "wrote " << Plural(static_cast<int64_t>(images.written.size()), "verification image")
        << " in " << (dir / "trials").string() << '\n';
  }
  std::vector<TrialEvidence> evidence(outcomes.size());
  for (size_t i = 0; i < outcomes.size(); ++i) {
    TrialEvidence& trial = evidence[i];
    if (!outcomes[i].video) {
      trial.no_traces = trial.no_image = WithoutVideo(outcomes[i]);
      continue;
    }
    if (images.image_paths[i].empty()) {
      trial.no_image = images.errors[i].ToString();
    } else {
      trial.image = fs::path("trials") / images.image_paths[i].filename();
    }
    trial.traces = TraceFigure("trial-" + stems[i], outcomes[i].trial.id, *outcomes[i].video);
    if (!trial.traces) {
      trial.no_traces = "its video analysis kept no trace (LED located automatically, no foot)";
      continue;
    }
    LIFTOFF_RETURN_IF_ERROR(WriteFigure(*trial.traces, dir / "figures", gnuplot, drawn));
  }
  return evidence;
}

std::string TrialsMarkdown(const CampaignAnalysis& campaign,
                           const std::vector<TrialEvidence>& evidence, bool drawn) {
  std::string text = "## Trials\n\n";
  const auto& outcomes = campaign.analysis.outcomes;
  for (size_t i = 0; i < outcomes.size(); ++i) {
    text += "- " + outcomes[i].trial.id + " (foot " +
            std::string(FootName(outcomes[i].trial.foot)) + "): " + TrialStatus(outcomes[i]) + "\n";
    for (const std::string& note : campaign.notes[i]) text += "  - " + note + "\n";
    if (i < evidence.size()) text += EvidenceMarkdown(evidence[i], drawn);
  }
  return text;
}

Result<std::string> TrialsHtml(const CampaignAnalysis& campaign,
                               const std::vector<TrialEvidence>& evidence, bool drawn,
                               const fs::path& dir) {
  std::string html = "<h2>Trials</h2>\n<ul>\n";
  const auto& outcomes = campaign.analysis.outcomes;
  for (size_t i = 0; i < outcomes.size(); ++i) {
    html += "<li>" + EscapeMarkup(outcomes[i].trial.id) + " (foot " +
            std::string(FootName(outcomes[i].trial.foot)) + "): " +
            EscapeMarkup(TrialStatus(outcomes[i]));
    if (!campaign.notes[i].empty()) html += "<ul>";
    for (const std::string& note : campaign.notes[i]) html += "<li>" + EscapeMarkup(note) + "</li>";
    if (!campaign.notes[i].empty()) html += "</ul>";
    if (i < evidence.size() && outcomes[i].video) {
      LIFTOFF_ASSIGN_OR_RETURN(const std::string shown, EvidenceHtml(evidence[i], drawn, dir));
      html += shown;
    } else if (i < evidence.size()) {
      html += "<p>no traces figure, no verification image: " +
              EscapeMarkup(evidence[i].no_traces) + "</p>";
    }
    html += "</li>\n";
  }
  return html + "</ul>\n";
}

std::string TrialStatus(const sync::TrialOutcome& outcome) {
  if (!outcome.status.ok()) return "failed: " + outcome.status.ToString();
  const sync::LiftoffMeasurement& measured = *outcome.measurement;
  return "ok: " + FormatFixed(measured.liftoff_rad, 3) + " rad in [" +
         FormatFixed(measured.lower_rad, 3) + ", " + FormatFixed(measured.upper_rad, 3) + "]";
}

std::string Base64(std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string encoded;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const auto byte = [&](size_t at) {
      return at < bytes.size() ? static_cast<uint32_t>(static_cast<unsigned char>(bytes[at])) : 0u;
    };
    const uint32_t group = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    encoded += kDigits[(group >> 18) & 63];
    encoded += kDigits[(group >> 12) & 63];
    encoded += i + 1 < bytes.size() ? kDigits[(group >> 6) & 63] : '=';
    encoded += i + 2 < bytes.size() ? kDigits[group & 63] : '=';
  }
  return encoded;
}

Result<std::string> InlinePng(const fs::path& path, const std::string& alt) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::string png, ReadWholeFile(path));
  return "<img alt=\"" + EscapeMarkup(alt) + "\" src=\"data:image/png;base64," + Base64(png) +
         "\">";
}

}  // namespace liftoff::cli
