// `liftoff calib`: a calibration and its conversions.
#include "liftoff/cli/commands.h"

#include <memory>
#include <ostream>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"

namespace liftoff::cli {
// ---------------------------------------------------------------------------------------
// liftoff calib

int RunCalib(const CalibCommand& command, std::ostream& out, std::ostream& err) {
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  const Calibration& c = *calibration;
  if (command.json) {
    out << CalibrationToJson(c).dump(2) << '\n';
    return kExitOk;
  }
  const double counts_per_shaft_rev = c.encoder_counts_per_motor_rev * c.gearbox_ratio;
  out << "calibration: " << c.Brief() << '\n';
  if (!c.description.empty()) out << "  " << c.description << '\n';
  out << "rotating vertebra: " << FormatFixed(c.encoder_counts_per_motor_rev, 0)
      << " counts/motor rev x " << FormatFixed(c.gearbox_ratio, 0) << ":1 gearbox x "
      << FormatFixed(c.spur_gear_ratio, 2) << ":1 spur gear\n"
      << "  " << FormatFixed(counts_per_shaft_rev, 0) << " counts per output-shaft revolution, "
      << FormatFixed(counts_per_shaft_rev * c.spur_gear_ratio, 0) << " per vertebra revolution\n"
      << "  one count = " << FormatFixed(c.VertebraAngleFromCounts(1) * 1e6, 1)
      << " microrad of vertebra rotation\n"
      << "bending spool grooves (m):";
  for (double radius : c.spool_groove_radii_m) out << ' ' << FormatFixed(radius, 4);
  out << "; cable lengths (m):";
  for (double length : c.cable_lengths_m) out << ' ' << FormatFixed(length, 4);
  const auto percent = c.PercentLengthChangeFromSpoolAngle(1.0);
  out << "\n  percent length change per spool radian:";
  for (double p : percent) out << ' ' << FormatFixed(p, 2);
  out << "\nmaterials (N/m):";
  for (const MaterialConstant& m : c.materials) {
    out << ' ' << m.name << ' ' << FormatFixed(m.stiffness_n_per_m, 0) << " +- "
        << FormatFixed(m.stiffness_stddev_n_per_m, 0) << ';';
  }
  out << "\ntension points (silicone / Buna-N / spring, N/m):\n";
  for (const TensionPoint& p : c.tension_points) {
    out << "  " << p.name << " (" << (p.sigma >= 0 ? "+" : "") << FormatFixed(p.sigma, 0)
        << " sigma): " << FormatFixed(p.silicone_n_per_m, 0) << " / "
        << FormatFixed(p.buna_n_n_per_m, 0) << " / " << FormatFixed(p.spring_n_per_m, 0) << '\n';
  }
  if (!c.notes.empty()) {
    out << "provenance:\n";
    for (const auto& [field, note] : c.notes) out << "  " << field << ": " << note << '\n';
  }
  return kExitOk;
}

Subcommand AddCalibCommand(Command& parent) {
  auto command = std::make_shared<CalibCommand>();
  Command* app =
      parent.AddSubcommand("calib", "Show a calibration, its provenance and its conversions");
  app->AddOption("calibration", command->calibration.calibration_path,
                  "Calibration JSON (default: calib/laika-2018.json)");
  app->AddSwitch("--json", command->json, "Print the calibration as JSON");
  return RunsWith(app, command, RunCalib);
}

}  // namespace liftoff::cli
