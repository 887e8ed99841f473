// Vocabulary of the robot under test: its feet, its horizontal cable groups and the
// rotating vertebra's direction.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace liftoff {

/// Laika's feet. A front right, B front left, C back right, D back left.
enum class Foot { kA = 0, kB = 1, kC = 2, kD = 3 };

inline constexpr std::array<Foot, 4> kAllFeet = {Foot::kA, Foot::kB, Foot::kC, Foot::kD};

/// "A", "B", "C", "D".
std::string_view FootName(Foot foot);
/// "front right", "front left", "back right", "back left".
std::string_view FootPosition(Foot foot);
/// Colour of the foot's tape on the hardware: "blue", "orange", "purple", "red".
std::string_view FootTapeColour(Foot foot);
/// That colour as the synthetic scenes draw it and the video check expects it: blue,
/// green, red, 0..255.
std::array<double, 3> FootTapeBgr(Foot foot);
/// Parses "A".."D" (exact, upper case); nullopt otherwise.
std::optional<Foot> ParseFoot(std::string_view text);
/// The foot diagonally opposite: A <-> D, B <-> C (the pair a twist of the spine raises).
Foot DiagonalPartner(Foot foot);

/// The four horizontal cable groups (one cable in each of the four gaps between
/// consecutive vertebrae): top, bottom, right, left. A foot-lifting test pulls HR or HL.
enum class CableGroup { kHT = 0, kHB = 1, kHR = 2, kHL = 3 };

/// "HT", "HB", "HR", "HL".
std::string_view CableGroupName(CableGroup group);
std::optional<CableGroup> ParseCableGroup(std::string_view text);

/// Direction of the rotating vertebra's ramp: +1 or -1 (sign of the commanded angle).
enum class RotationSense { kPositive = 1, kNegative = -1 };

/// "+" or "-".
std::string_view RotationSenseName(RotationSense sense);
/// Parses "+" or "-".
std::optional<RotationSense> ParseRotationSense(std::string_view text);

/// The paper's Table II as printed, read by foot letter: the cable group pulled and the
/// rotation that lift each foot (A: HR +, B: HR -, C: HL +, D: HL -). Unverified: the
/// printed C/D positions are swapped and the 2018 logs' rotation signs disagree (A and D
/// negative); the simulation is to settle which combination lifts which foot.
struct FootLiftingMotion {
  CableGroup pulled_group = CableGroup::kHR;
  RotationSense rotation = RotationSense::kPositive;
};
FootLiftingMotion PaperTableTwoMotion(Foot foot);

}  // namespace liftoff
