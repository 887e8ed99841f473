// Figures, liftoff's one plotting path (`liftoff report`, `liftoff table --plot`): each
// figure is its data (NAME.dat) and a generated gnuplot script (NAME.gp) beside it that
// draws NAME.png and NAME.svg, so a user can restyle a figure for a paper and rerun
// `gnuplot NAME.gp` in its folder. The scripts and data are written whether or not gnuplot
// is there; drawing needs gnuplot 5 with its cairo terminals (Debian: gnuplot-nox).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/status.h"
#include "liftoff/stats/sim_results.h"
#include "liftoff/stats/table.h"
#include "liftoff/video/clip_analysis.h"

namespace liftoff::cli {

/// One figure.
struct Figure {
  /// File stem: NAME.dat, NAME.gp, NAME.png, NAME.svg (letters, digits, '.', '_', '-').
  std::string name;
  /// One line for people: the image's caption and alt text, the script's first comment.
  std::string title;
  /// NAME.dat: blocks of whitespace-separated columns, each after a comment naming them.
  std::string data;
  /// The plot commands, which read NAME.dat; the script around them sets the terminals.
  std::string body;
};

/// A string gnuplot reads as one field of a data file: quoted, inner quotes made '.
std::string FigureDataText(std::string_view text);

/// NAME.gp: `figure.body` drawn once as PNG (1200 x 800) and once as SVG, beside the script.
std::string FigureScript(const Figure& figure);

/// Runs `PROGRAM -e "cd 'DIR'" DIR/NAME.gp`, its output into DIR/NAME.log (removed when
/// empty). kNotFound when the program cannot be run (naming the Debian package); kIo when
/// it fails (naming the log).
Status DrawFigure(const std::string& program, const std::filesystem::path& dir,
                  const std::string& name);

/// Writes DIR/NAME.dat and DIR/NAME.gp, then, while `drawn` is OK, draws NAME.png and
/// NAME.svg with `gnuplot` (the program); gnuplot missing or failing comes back in `drawn`
/// (later figures are then not drawn), a file that cannot be written as the error.
Status WriteFigure(const Figure& figure, const std::filesystem::path& dir,
                   const std::string& gnuplot, Status& drawn);

/// The four files WriteFigure makes of a figure called `name` in `dir`.
std::vector<std::filesystem::path> FigureFiles(const std::filesystem::path& dir,
                                               const std::string& name);

/// Each trial's liftoff rotation with its uncertainty interval, in `values`' order, beside
/// the simulated values of its foot (one short line per tension point that stood, or the
/// range's min and max where `sim` holds only a summary for the foot; `sim` may be null).
/// Trials whose liftoff_rad is NaN are left out.
Figure TrialsFigure(const std::string& name, const std::vector<stats::TrialValue>& values,
                    const stats::SimResults* sim);

/// A string gnuplot reads as one double-quoted string in a script, shown as typed (to be
/// used with `noenhanced`): quotes made ', backslashes made /.
std::string FigureScriptText(std::string_view text);

/// One trial's traces from its video analysis, against the video clock, s: the LED's
/// brightness (its region's mean, grey levels; left out when the LED was located
/// automatically and has no trace) above the foot's height above rest (mm with a scale,
/// else px) with the threshold and the rest window; the detected instants (LED switch-on,
/// onset of rise, liftoff) drawn as lines in both panels with their uncertainty intervals
/// shaded, and as points with their intervals on the height curve. Data blocks: 0 the
/// instants (name t_s lower_s upper_s height), then the LED's (t_s brightness_levels) when
/// traced, then the foot's (t_s height_mm or height_px) when tracked. nullopt when the
/// analysis holds neither trace.
std::optional<Figure> TraceFigure(const std::string& name, const std::string& trial_id,
                                  const video::ClipAnalysis& clip);

}  // namespace liftoff::cli
