// libFuzzer target for the JSON-driven readers: arbitrary bytes as a manifest, a
// calibration, a simulation model and simulation results, each from text through
// ParseJsonText (depth and size limits included) to the reader's own checks. Any crash,
// sanitizer report or broken invariant is a finding. Build and run: scripts/fuzz.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "liftoff/core/calibration.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/sim/model.h"
#include "liftoff/stats/sim_results.h"

#include "fuzz_check.h"

namespace {

// an error always says where: the source's name leads its message
template <typename T>
void CheckNamesTheSource(const liftoff::Result<T>& result) {
  if (result.ok()) return;
  FUZZ_CHECK(!result.status().message().empty());
  FUZZ_CHECK(result.status().message().find("fuzz.json") != std::string::npos);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto document = liftoff::ParseJsonText(text, "fuzz.json");
  CheckNamesTheSource(document);
  if (!document.ok()) return 0;

  const auto calibration = liftoff::CalibrationFromJson(*document, "fuzz.json");
  CheckNamesTheSource(calibration);
  if (calibration.ok()) {
    // a calibration that loads converts every count to a finite angle
    FUZZ_CHECK(calibration->Validate().ok());
    FUZZ_CHECK(std::isfinite(calibration->VertebraAngleFromCounts(1)));
    FUZZ_CHECK(std::isfinite(calibration->VertebraAngleFromCounts(INT64_C(1) << 40)));
  }
  CheckNamesTheSource(liftoff::ManifestFromJson(*document, "fuzz.json", "/nonexistent"));
  CheckNamesTheSource(liftoff::sim::ModelDescriptionFromJson(*document, "fuzz.json"));
  CheckNamesTheSource(liftoff::stats::SimResultsFromJson(*document, "fuzz.json"));
  return 0;
}
