// The report's per-trial evidence (liftoff report, docs/cli.md): for every trial analysed
// from its video, its traces figure (DIR/figures/trial-<stem>.gp, .dat, .png, .svg:
// TraceFigure) and its verification image (DIR/trials/<stem>.png: the image of `liftoff
// video --verify`), <stem> the trial id as a safe, unique file name (TrialFileStems); and
// the Trials section of both pages, each trial with its status, notes and evidence.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli_common.h"
#include "liftoff/cli/figures.h"
#include "liftoff/core/status.h"

namespace liftoff::cli {

/// One trial's evidence.
struct TrialEvidence {
  /// Its traces figure (in DIR/figures), when it has one.
  std::optional<Figure> traces;
  /// Its verification image, relative to DIR ("trials/<stem>.png"); empty when none.
  std::filesystem::path image;
  /// Why there is no figure or no image, for the pages (empty when there is).
  std::string no_traces;
  std::string no_image;
};

/// Writes every video trial's traces figure into DIR/figures (drawn while `drawn` is OK,
/// with `gnuplot`) and its verification image into DIR/trials. One entry per outcome, in
/// order. An image that fails is a warning on `err` and a note on the pages; a file that
/// cannot be written is the error.
Result<std::vector<TrialEvidence>> WriteTrialEvidence(const CampaignAnalysis& campaign,
                                                      const std::filesystem::path& dir,
                                                      const std::string& gnuplot, Status& drawn,
                                                      std::ostream& err);

/// "## Trials": one item per trial, its notes, links to its figure, data and image.
std::string TrialsMarkdown(const CampaignAnalysis& campaign,
                           const std::vector<TrialEvidence>& evidence, bool drawn);

/// "<h2>Trials</h2>": the same, the figure and image inline side by side.
Result<std::string> TrialsHtml(const CampaignAnalysis& campaign,
                               const std::vector<TrialEvidence>& evidence, bool drawn,
                               const std::filesystem::path& dir);

/// "ok: 0.412 rad in [0.405, 0.419]" or "failed: " and the status.
std::string TrialStatus(const sync::TrialOutcome& outcome);

/// `bytes` in base64 (RFC 4648, padded).
std::string Base64(std::string_view bytes);

/// <img alt="ALT" src="data:image/png;base64,..."> of the PNG at `path`.
Result<std::string> InlinePng(const std::filesystem::path& path, const std::string& alt);

}  // namespace liftoff::cli
