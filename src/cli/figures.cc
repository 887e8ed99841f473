#include "liftoff/cli/figures.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/text.h"

extern char** environ;

namespace liftoff::cli {

namespace fs = std::filesystem;

std::string FigureDataText(std::string_view text) {
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? '\'' : c;
  return quoted + "\"";
}

std::string FigureScript(const Figure& figure) {
  return "# liftoff: " + figure.title +
         ".\n# Data: " + figure.name + ".dat. Restyle here and rerun `gnuplot " + figure.name +
         ".gp` in this folder.\n"
         "do for [format in \"png svg\"] {\n"
         "  if (format eq \"png\") {\n"
         "    set terminal pngcairo size 1200,800 font \",11\"\n"
         "  } else {\n"
         "    set terminal svg size 1200,800 font \"sans,11\"\n"
         "  }\n"
         "  set output \"" + figure.name + ".\".format\n" +
         figure.body + "  unset output\n}\n";
}

Status DrawFigure(const std::string& program, const fs::path& dir, const std::string& name) {
  const std::string cd = "cd '" + dir.string() + "'";
  // the script by its name in `dir`, where gnuplot runs (a relative `dir` would not
  // resolve after the cd)
  const std::string script = name + ".gp";
  const std::string log = (dir / (name + ".log")).string();
  std::vector<std::string> arguments = {program, "-e", cd, script};
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    return NotFoundError(program + ": cannot run it (" + std::strerror(spawned) +
                         "); install gnuplot (Debian: gnuplot-nox)");
  }
  int wait_status = 0;
  if (waitpid(pid, &wait_status, 0) != pid || !WIFEXITED(wait_status) ||
      WEXITSTATUS(wait_status) != 0) {
    return IoError(program + " failed on " + (dir / script).string() + "; its messages are in " +
                   log);
  }
  std::error_code error;
  if (fs::file_size(log, error) == 0) fs::remove(log, error);
  return Status::Ok();
}

Status WriteFigure(const Figure& figure, const fs::path& dir, const std::string& gnuplot,
                   Status& drawn) {
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(dir / (figure.name + ".dat"), figure.data));
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(dir / (figure.name + ".gp"), FigureScript(figure)));
  if (drawn.ok()) drawn = DrawFigure(gnuplot, dir, figure.name);
  return Status::Ok();
}

std::vector<fs::path> FigureFiles(const fs::path& dir, const std::string& name) {
  return {dir / (name + ".dat"), dir / (name + ".gp"), dir / (name + ".png"),
          dir / (name + ".svg")};
}

Figure TrialsFigure(const std::string& name, const std::vector<stats::TrialValue>& values,
                    const stats::SimResults* sim) {
  Figure figure{name, "liftoff rotation per trial beside the simulation", "", ""};
  std::string& data = figure.data;
  data = "# block 0: index rotation_rad lower_rad upper_rad trial foot\n";
  std::map<Foot, std::pair<size_t, size_t>> span_by_foot;
  for (size_t i = 0; i < values.size(); ++i) {
    const stats::TrialValue& value = values[i];
    if (!std::isfinite(value.liftoff_rad)) continue;
    const bool interval = std::isfinite(value.lower_rad) && std::isfinite(value.upper_rad);
    data += std::to_string(i) + " " + FormatNumber(value.liftoff_rad) + " " +
            FormatNumber(interval ? value.lower_rad : value.liftoff_rad) + " " +
            FormatNumber(interval ? value.upper_rad : value.liftoff_rad) + " " +
            FigureDataText(value.trial_id) + " " + std::string(FootName(value.foot)) + "\n";
    auto [entry, added] = span_by_foot.try_emplace(value.foot, i, i);
    if (!added) entry->second.second = i;
  }
  data +=
      "\n\n# block 1: from_index to_index liftoff_rad tension_point (simulation; min and max "
      "where the results hold only a foot's range)\n";
  bool any_sim = false;
  for (const stats::SimRun& run : sim ? sim->runs : std::vector<stats::SimRun>()) {
    const auto span = span_by_foot.find(run.foot);
    if (!run.stood || !run.liftoff_rad || span == span_by_foot.end()) continue;
    data += FormatFixed(static_cast<double>(span->second.first) - 0.4, 1) + " " +
            FormatFixed(static_cast<double>(span->second.second) + 0.4, 1) + " " +
            FormatNumber(*run.liftoff_rad) + " " + FigureDataText(run.tension_point) + "\n";
    any_sim = true;
  }
  // a foot whose range comes from a summary alone: its min and max
  for (const auto& [foot, range] : sim ? sim->ranges : std::map<Foot, stats::SimFootRange>()) {
    const auto span = span_by_foot.find(foot);
    if (!range.from_summary || span == span_by_foot.end()) continue;
    for (const auto& [value, label] :
         {std::pair{range.min_rad, "min"}, std::pair{range.max_rad, "max"}}) {
      data += FormatFixed(static_cast<double>(span->second.first) - 0.4, 1) + " " +
              FormatFixed(static_cast<double>(span->second.second) + 0.4, 1) + " " +
              FormatNumber(value) + " " + FigureDataText(label) + "\n";
    }
    any_sim = true;
  }
  if (!any_sim) data += "-1 -1 0 \"\"\n";  // an empty block would stop gnuplot
  figure.body =
      "  set title \"Rotation at liftoff per trial: hardware (interval) beside simulation\"\n"
      "  set ylabel \"|vertebra rotation| at liftoff (rad)\"\n"
      "  set xlabel \"trial\"\n"
      "  set xrange [-1:" + std::to_string(values.size()) + "]\n"
      "  set grid ytics\n"
      "  set key top left\n"
      "  plot \"" + name + ".dat\" index 0 using 1:2:3:4:xticlabels(5) with yerrorbars pt 7 lc rgb "
      "\"#1f77b4\" title \"hardware\", \\\n"
      "       \"\" index 1 using 1:3:($2-$1):(0) with vectors nohead lw 2 lc rgb \"#d62728\" "
      "title \"simulation (per tension point)\", \\\n"
      "       \"\" index 1 using 2:3:4 with labels left offset 0.5,0 font \",8\" notitle\n";
  return figure;
}

}  // namespace liftoff::cli
