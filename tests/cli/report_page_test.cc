// The report's HTML page in a real browser: `liftoff report` on the sample trials and a
// synthetic clip (entered twice: two traces figures, two verification images), then
// headless Chromium (Debian's `chromium`) opens report.html offline. A copy of the page
// with a probe script appended reports in its title how many of its figures decoded; a
// second copy with every figure's data broken checks that the probe sees a broken one.
// Chromium also renders the page to a screenshot. Skips with a message without Chromium.
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.h"
#include "video_campaign.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ReadFile;
using liftoff::testing::RunCommand;
using liftoff::testing::ScratchDir;
using liftoff::testing::WriteFile;

// Chromium on PATH, or empty
fs::path FindChromium() {
  for (const char* name : {"chromium", "chromium-browser"}) {
    if (auto found = liftoff::testing::FindOnPath(name)) return *found;
  }
  return {};
}

// headless, offline, no sandbox (CI runs as root), its profile in the scratch folder;
// --virtual-time-budget lets the page load and its scripts run before the dump
std::string ChromiumFlags(const ScratchDir& scratch) {
  return "--headless=new --no-sandbox --disable-gpu --no-first-run --disable-extensions "
         "--user-data-dir=" +
         Quoted(scratch / "chromium-profile") + " --virtual-time-budget=10000";
}

// sets the page's title to "figures N of M loaded" once the page has loaded
constexpr const char* kProbe =
    "<script>window.addEventListener('load', function () {"
    " var images = document.images, loaded = 0;"
    " for (var i = 0; i < images.length; ++i)"
    "  if (images[i].complete && images[i].naturalWidth > 0) ++loaded;"
    " document.title = 'figures ' + loaded + ' of ' + images.length + ' loaded'; });</script>";

// the page with the probe before </body>
std::string WithProbe(std::string page) {
  const size_t end = page.rfind("</body>");
  return end == std::string::npos ? page + kProbe : page.insert(end, kProbe);
}

// the title Chromium's DOM dump ends with, or what it said instead
std::string LoadedTitle(const fs::path& chromium, const fs::path& page, const ScratchDir& scratch) {
  const CommandRun run = RunCommand(chromium, ChromiumFlags(scratch) + " --dump-dom " +
                                                  Quoted("file://" + page.string()),
                                    scratch);
  std::smatch match;
  if (std::regex_search(run.out, match, std::regex("<title>(figures [0-9]+ of [0-9]+ loaded)"))) {
    return match[1];
  }
  return "no probe title (exit " + std::to_string(run.code) + "): " + run.err.substr(0, 400);
}

int CountOf(const std::string& text, const std::string& what) {
  int count = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

TEST(ReportPage, OpensOfflineInChromiumWithEveryFigureLoaded) {
  const fs::path chromium = FindChromium();
  if (chromium.empty()) {
    GTEST_SKIP() << "chromium is not installed (Debian package chromium): the report page is "
                    "not checked in a browser";
  }
  ScratchDir scratch;
  const VideoCampaign campaign = WriteVideoCampaign(scratch / "campaign", 8);
  ASSERT_TRUE(campaign.error.empty()) << campaign.error;
  const fs::path out = scratch / "report";
  const CommandRun report =
      RunCommand(LIFTOFF_BINARY,
                 "report " + Quoted(campaign.manifest_path) + " -o " + Quoted(out) +
                     " --tensions mean,high --progress off",
                 scratch);
  ASSERT_EQ(report.code, 0) << report.err;
  const std::string page = ReadFile(out / "report.html");
  const int figures = CountOf(page, "<img ");
  // the trials, Figure 7, the fit and the Monte Carlo; each clip's traces and verification
  EXPECT_EQ(CountOf(page, "<img alt=\"verification image\""), 2);
  EXPECT_EQ(CountOf(page, "<img alt=\"trial clip"), 2);
  ASSERT_GE(figures, 6) << "the page holds the trials, Figure 7 and each clip's evidence at least";
  EXPECT_EQ(CountOf(page, "src=\"data:image/png;base64,"), figures) << "every figure inline";

  const fs::path probed = out / "probed.html";
  WriteFile(probed, WithProbe(page));
  EXPECT_EQ(LoadedTitle(chromium, probed, scratch),
            "figures " + std::to_string(figures) + " of " + std::to_string(figures) + " loaded");

  // the probe sees a figure that does not decode
  const fs::path broken = out / "broken.html";
  WriteFile(broken, WithProbe(std::regex_replace(page, std::regex("base64,[A-Za-z0-9+/]{8}"),
                                                 "base64,AAAAAAAA")));
  EXPECT_EQ(LoadedTitle(chromium, broken, scratch),
            "figures 0 of " + std::to_string(figures) + " loaded");

  // and the page renders
  const fs::path shot = out / "page.png";
  const CommandRun render =
      RunCommand(chromium,
                 ChromiumFlags(scratch) + " --window-size=1200,3000 --screenshot=" +
                     Quoted(shot) + " " + Quoted("file://" + (out / "report.html").string()),
                 scratch);
  ASSERT_TRUE(fs::exists(shot)) << render.err.substr(0, 400);
  const std::string png = ReadFile(shot);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(png.size(), 50'000u) << "a page with figures, not a blank one";
}

}  // namespace
}  // namespace liftoff::cli
