#include "liftoff/stats/table.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "liftoff/core/json.h"
#include "liftoff/core/text.h"

namespace liftoff::stats {
namespace {

using nlohmann::json;

// A cell's text, or nullopt for a missing value (rendered per format).
using Cell = std::optional<std::string>;
using Row = std::vector<Cell>;

Cell Fixed3(double value) {
  if (!std::isfinite(value)) return std::nullopt;
  return FormatFixed(value, 3);
}

Cell Interval(double low, double high) {
  if (!std::isfinite(low) || !std::isfinite(high)) return std::nullopt;
  return "[" + *Fixed3(low) + ", " + *Fixed3(high) + "]";
}

std::string CalibrationLine(std::string_view calibration, std::string_view lookup_rule) {
  return "Calibration: " + std::string(calibration.empty() ? "(not named)" : calibration) +
         ". Lookup: " + std::string(lookup_rule.empty() ? "(not named)" : lookup_rule) + ".";
}

// --- markdown ---

std::string MarkdownEscape(std::string_view text) {
  std::string escaped;
  for (char c : text) {
    if (c == '|') escaped += '\\';
    // a line break would end the table row
    escaped += c == '\n' || c == '\r' ? ' ' : c;
  }
  return escaped;
}

// title in bold, the table, the calibration line, then the notes as a list
// `alignment` has one letter per column: l, r or c
std::string RenderMarkdown(std::string_view title, std::string_view alignment,
                           const std::vector<std::string>& header, const std::vector<Row>& rows,
                           std::string_view calibration, std::string_view lookup_rule,
                           const std::vector<std::string>& notes) {
  std::string out = "**" + MarkdownEscape(title) + "**\n\n|";
  for (const std::string& name : header) out += " " + MarkdownEscape(name) + " |";
  out += "\n|";
  for (char align : alignment)
    out += align == 'r' ? " ---: |" : align == 'c' ? " :---: |" : " --- |";
  out += "\n";
  for (const Row& row : rows) {
    out += "|";
    for (const Cell& cell : row)
      out += " " + (cell ? MarkdownEscape(*cell) : std::string("–")) + " |";
    out += "\n";
  }
  out += "\n" + CalibrationLine(calibration, lookup_rule) + "\n";
  if (!notes.empty()) {
    out += "\nNotes:\n";
    for (const std::string& note : notes) out += "- " + note + "\n";
  }
  return out;
}

// --- csv ---

std::string CsvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

std::string RenderCsv(const std::vector<std::string>& header, const std::vector<Row>& rows) {
  std::string out;
  const auto line = [&out](const auto& cells, const auto& text_of) {
    for (size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + CsvField(text_of(cells[i]));
    out += "\r\n";
  };
  line(header, [](const std::string& name) { return name; });
  for (const Row& row : rows) line(row, [](const Cell& cell) { return cell.value_or(""); });
  return out;
}

// --- latex ---

std::string LatexEscape(std::string_view text) {
  std::string escaped;
  for (char c : text) {
    switch (c) {
      case '\\': escaped += "\\textbackslash{}"; break;
      case '~': escaped += "\\textasciitilde{}"; break;
      case '^': escaped += "\\textasciicircum{}"; break;
      case '&':
      case '%':
      case '$':
      case '#':
      case '_':
      case '{':
      case '}':
        escaped += '\\';
        escaped += c;
        break;
      default: escaped += c;
    }
  }
  return escaped;
}

// a booktabs table; `header` is already LaTeX (it may hold rules and \multicolumn)
std::string RenderLatex(std::string_view title, std::string_view column_spec,
                        std::string_view header, const std::vector<Row>& rows,
                        std::string_view calibration, std::string_view lookup_rule,
                        const std::vector<std::string>& notes) {
  std::string out = "\\begin{table}[htb]\n  \\centering\n  \\caption{" + LatexEscape(title) + ". " +
                    LatexEscape(CalibrationLine(calibration, lookup_rule)) + "}\n";
  out += "  \\begin{tabular}{" + std::string(column_spec) + "}\n    \\toprule\n";
  out += std::string(header) + "    \\midrule\n";
  for (const Row& row : rows) {
    out += "   ";
    for (size_t i = 0; i < row.size(); ++i) {
      out += (i ? " & " : " ") + (row[i] ? LatexEscape(*row[i]) : std::string("--"));
    }
    out += " \\\\\n";
  }
  out += "    \\bottomrule\n  \\end{tabular}\n";
  if (!notes.empty()) {
    out += "  \\par\\smallskip\n  {\\footnotesize\n";
    for (const std::string& note : notes) out += "  " + LatexEscape(note) + "\\par\n";
    out += "  }\n";
  }
  out += "\\end{table}\n";
  return out;
}

json TrialToJson(const TrialValue& trial) {
  return {{"trial_id", trial.trial_id},
          {"foot", FootName(trial.foot)},
          {"liftoff_rad", NumberOrNull(trial.liftoff_rad)},
          {"lower_rad", NumberOrNull(trial.lower_rad)},
          {"upper_rad", NumberOrNull(trial.upper_rad)},
          {"flags", trial.flags}};
}

// column alignments of the two tables (markdown and latex)
constexpr std::string_view kResultsAlignment = "lrrrrrrrrc";
constexpr std::string_view kTrialAlignment = "llrcl";

Cell Count(int64_t n) { return std::to_string(n); }

}  // namespace

ResultsTable BuildResultsTable(std::span<const TrialValue> trials, const SimResults* sim,
                               std::string calibration, std::string lookup_rule) {
  ResultsTable table;
  table.title = "Absolute vertebra rotation at liftoff (rad)";
  table.calibration = std::move(calibration);
  table.lookup_rule = std::move(lookup_rule);

  // one row per foot with trials or a simulated range
  for (Foot foot : kAllFeet) {
    FootRow row;
    row.foot = foot;
    std::vector<double> values;
    for (const TrialValue& trial : trials) {
      if (trial.foot != foot) continue;
      row.trials.push_back(trial);
      values.push_back(trial.liftoff_rad);
    }
    // at 95 %, the level the table's ci95_* columns and keys name
    row.hardware = Summarize(values, 0.95);
    if (sim != nullptr) {
      if (auto it = sim->ranges.find(foot); it != sim->ranges.end()) row.sim = it->second;
    }
    if (!row.trials.empty() || row.sim) table.rows.push_back(std::move(row));
  }

  // notes: where the simulation came from, what was left out, what was typed in
  if (sim != nullptr) {
    std::string note =
        "Simulation: " + (sim->model.empty() ? std::string("(unnamed model)") : sim->model);
    if (!sim->description.empty()) note += ", " + sim->description;
    table.notes.push_back(note + " (" + sim->source + ").");
    for (const auto& [foot, range] : sim->ranges) {
      if (!range.from_summary) continue;
      table.notes.push_back(
          "Sim range of foot " + std::string(FootName(foot)) +
          " from the results' summary (typed in), not from runs" +
          (range.n_runs ? "; " + std::to_string(range.n_runs) + " standing runs listed." : "."));
    }
    for (const SimRun& run : sim->runs) {
      if (run.stood) continue;
      table.notes.push_back("Sim run of foot " + std::string(FootName(run.foot)) +
                            " at tension point " + run.tension_point +
                            (run.diverged ? " diverged (the engine's state stopped being finite)"
                                          : " did not stand") +
                            "; excluded from sim min/max.");
    }
  }
  for (const TrialValue& trial : trials) {
    if (std::isfinite(trial.liftoff_rad)) continue;
    table.notes.push_back("Trial " + trial.trial_id + " gave no liftoff value" +
                          (trial.flags.empty() ? "" : " (" + trial.flags + ")") +
                          "; listed, not counted.");
  }
  return table;
}

std::optional<TableFormat> ParseTableFormat(std::string_view text) {
  if (text == "md" || text == "markdown") return TableFormat::kMarkdown;
  if (text == "csv") return TableFormat::kCsv;
  if (text == "latex" || text == "tex") return TableFormat::kLatex;
  if (text == "json") return TableFormat::kJson;
  return std::nullopt;
}

std::string_view TableFormatName(TableFormat format) {
  switch (format) {
    case TableFormat::kMarkdown: return "markdown";
    case TableFormat::kCsv: return "csv";
    case TableFormat::kLatex: return "latex";
    case TableFormat::kJson: return "json";
  }
  return "?";
}

json ResultsTableToJson(const ResultsTable& table) {
  json rows = json::array();
  for (const FootRow& row : table.rows) {
    const Summary& hw = row.hardware;
    json trials = json::array();
    for (const TrialValue& trial : row.trials) trials.push_back(TrialToJson(trial));
    json sim = nullptr;
    if (row.sim) {
      sim = {{"min_rad", row.sim->min_rad},
             {"max_rad", row.sim->max_rad},
             {"n_runs", row.sim->n_runs},
             {"from_summary", row.sim->from_summary}};
    }
    rows.push_back({{"foot", FootName(row.foot)},
                    {"sim", std::move(sim)},
                    {"hardware",
                     {{"n", hw.n},
                      {"min_rad", NumberOrNull(hw.min)},
                      {"max_rad", NumberOrNull(hw.max)},
                      {"mean_rad", NumberOrNull(hw.mean)},
                      {"stddev_rad", NumberOrNull(hw.stddev)},
                      {"median_rad", NumberOrNull(hw.median)},
                      {"ci95_low_rad", NumberOrNull(hw.ci_low)},
                      {"ci95_high_rad", NumberOrNull(hw.ci_high)},
                      {"confidence", hw.confidence}}},
                    {"trials", std::move(trials)}});
  }
  return {{"format", "liftoff-results-table"},
          {"version", 1},
          {"title", table.title},
          {"calibration", table.calibration},
          {"lookup_rule", table.lookup_rule},
          {"rows", std::move(rows)},
          {"notes", table.notes}};
}

std::string RenderResultsTable(const ResultsTable& table, TableFormat format) {
  if (format == TableFormat::kJson) return ResultsTableToJson(table).dump(2) + "\n";

  // cells shared by every text format; CSV splits the interval and adds the run count
  const bool csv = format == TableFormat::kCsv;
  std::vector<Row> rows;
  for (const FootRow& row : table.rows) {
    const Summary& hw = row.hardware;
    Row cells = {std::string(FootName(row.foot)), row.sim ? Fixed3(row.sim->min_rad) : std::nullopt,
                 row.sim ? Fixed3(row.sim->max_rad) : std::nullopt};
    if (csv) cells.push_back(row.sim ? Count(row.sim->n_runs) : std::nullopt);
    for (Cell cell : {Fixed3(hw.min), Fixed3(hw.max), Count(hw.n), Fixed3(hw.mean),
                      Fixed3(hw.stddev), Fixed3(hw.median)}) {
      cells.push_back(std::move(cell));
    }
    if (csv) {
      for (Cell cell : {Fixed3(hw.ci_low), Fixed3(hw.ci_high), Cell(table.calibration),
                        Cell(table.lookup_rule)}) {
        cells.push_back(std::move(cell));
      }
    } else {
      cells.push_back(Interval(hw.ci_low, hw.ci_high));
    }
    rows.push_back(std::move(cells));
  }

  switch (format) {
    case TableFormat::kMarkdown:
      return RenderMarkdown(table.title, kResultsAlignment,
                            {"Foot", "Sim min", "Sim max", "HW min", "HW max", "HW n", "HW mean",
                             "HW sd", "HW median", "HW 95 % CI of mean"},
                            rows, table.calibration, table.lookup_rule, table.notes);
    case TableFormat::kCsv:
      return RenderCsv({"foot", "sim_min_rad", "sim_max_rad", "sim_n_runs", "hw_min_rad",
                        "hw_max_rad", "hw_n", "hw_mean_rad", "hw_sd_rad", "hw_median_rad",
                        "hw_ci95_low_rad", "hw_ci95_high_rad", "calibration", "lookup_rule"},
                       rows);
    case TableFormat::kLatex:
      return RenderLatex(
          table.title, kResultsAlignment,
          "    & \\multicolumn{2}{c}{Simulation} & \\multicolumn{7}{c}{Hardware} \\\\\n"
          "    \\cmidrule(lr){2-3} \\cmidrule(lr){4-10}\n"
          "    Foot & Min & Max & Min & Max & $n$ & Mean & SD & Median & "
          "95\\,\\% CI of mean \\\\\n",
          rows, table.calibration, table.lookup_rule, table.notes);
    case TableFormat::kJson: break;
  }
  return "";
}

std::string RenderTrialTable(std::span<const TrialValue> trials, TableFormat format,
                             std::string_view calibration, std::string_view lookup_rule) {
  const std::string title = "Absolute vertebra rotation at liftoff per trial (rad)";
  if (format == TableFormat::kJson) {
    json rows = json::array();
    for (const TrialValue& trial : trials) rows.push_back(TrialToJson(trial));
    return json({{"format", "liftoff-trial-table"},
                 {"version", 1},
                 {"title", title},
                 {"calibration", calibration},
                 {"lookup_rule", lookup_rule},
                 {"trials", std::move(rows)}})
               .dump(2) +
           "\n";
  }

  // csv keeps the interval's ends apart and names the calibration on every row
  const bool csv = format == TableFormat::kCsv;
  std::vector<Row> rows;
  for (const TrialValue& trial : trials) {
    Row cells = {trial.trial_id, std::string(FootName(trial.foot)), Fixed3(trial.liftoff_rad)};
    if (csv) {
      for (Cell cell : {Fixed3(trial.lower_rad), Fixed3(trial.upper_rad), Cell(trial.flags),
                        Cell(std::string(calibration)), Cell(std::string(lookup_rule))}) {
        cells.push_back(std::move(cell));
      }
    } else {
      cells.push_back(Interval(trial.lower_rad, trial.upper_rad));
      cells.push_back(trial.flags);  // empty flags are an empty cell, not a missing value
    }
    rows.push_back(std::move(cells));
  }

  switch (format) {
    case TableFormat::kMarkdown:
      return RenderMarkdown(title, kTrialAlignment,
                            {"Trial", "Foot", "Liftoff", "Interval", "Flags"}, rows, calibration,
                            lookup_rule, {});
    case TableFormat::kCsv:
      return RenderCsv({"trial_id", "foot", "liftoff_rad", "lower_rad", "upper_rad", "flags",
                        "calibration", "lookup_rule"},
                       rows);
    case TableFormat::kLatex:
      return RenderLatex(title, kTrialAlignment,
                         "    Trial & Foot & Liftoff & Interval & Flags \\\\\n", rows, calibration,
                         lookup_rule, {});
    case TableFormat::kJson: break;
  }
  return "";
}

}  // namespace liftoff::stats
