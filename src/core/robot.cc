#include "liftoff/core/robot.h"

namespace liftoff {

std::string_view FootName(Foot foot) {
  static constexpr std::array<std::string_view, 4> kNames = {"A", "B", "C", "D"};
  return kNames[static_cast<size_t>(foot)];
}

std::string_view FootPosition(Foot foot) {
  static constexpr std::array<std::string_view, 4> kPositions = {"front right", "front left",
                                                                 "back right", "back left"};
  return kPositions[static_cast<size_t>(foot)];
}

std::string_view FootTapeColour(Foot foot) {
  static constexpr std::array<std::string_view, 4> kColours = {"blue", "orange", "purple", "red"};
  return kColours[static_cast<size_t>(foot)];
}

std::array<double, 3> FootTapeBgr(Foot foot) {
  static constexpr std::array<std::array<double, 3>, 4> kBgr = {{
      {200, 80, 20},   // blue
      {20, 140, 255},  // orange
      {160, 40, 130},  // purple
      {30, 30, 210},   // red
  }};
  return kBgr[static_cast<size_t>(foot)];
}

std::optional<Foot> ParseFoot(std::string_view text) {
  for (Foot foot : kAllFeet) {
    if (text == FootName(foot)) return foot;
  }
  return std::nullopt;
}

Foot DiagonalPartner(Foot foot) {
  switch (foot) {
    case Foot::kA: return Foot::kD;
    case Foot::kB: return Foot::kC;
    case Foot::kC: return Foot::kB;
    case Foot::kD: return Foot::kA;
  }
  return Foot::kA;
}

std::string_view CableGroupName(CableGroup group) {
  static constexpr std::array<std::string_view, 4> kNames = {"HT", "HB", "HR", "HL"};
  return kNames[static_cast<size_t>(group)];
}

std::optional<CableGroup> ParseCableGroup(std::string_view text) {
  for (CableGroup group : {CableGroup::kHT, CableGroup::kHB, CableGroup::kHR, CableGroup::kHL}) {
    if (text == CableGroupName(group)) return group;
  }
  return std::nullopt;
}

std::string_view RotationSenseName(RotationSense sense) {
  return sense == RotationSense::kPositive ? "+" : "-";
}

std::optional<RotationSense> ParseRotationSense(std::string_view text) {
  if (text == "+") return RotationSense::kPositive;
  if (text == "-") return RotationSense::kNegative;
  return std::nullopt;
}

FootLiftingMotion PaperTableTwoMotion(Foot foot) {
  switch (foot) {
    case Foot::kA: return {CableGroup::kHR, RotationSense::kPositive};
    case Foot::kB: return {CableGroup::kHR, RotationSense::kNegative};
    case Foot::kC: return {CableGroup::kHL, RotationSense::kPositive};
    case Foot::kD: return {CableGroup::kHL, RotationSense::kNegative};
  }
  return {};
}

}  // namespace liftoff
