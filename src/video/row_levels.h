// Levelling the rows of a picture against a reference (private to the video module).
//
// A lamp's flicker seen through a rolling shutter bands the picture by rows: each sensor row
// integrates the lamp over its own part of the readout, so a band's brightness changes from
// row to row and rolls from frame to frame. Registered against a template with one gain and
// offset, a small patch takes the change of brightness from its top row to its bottom one
// partly for vertical motion. RowGains measures each row's gain against the reference (the
// median ratio over the row's columns, so the few columns a moving object covers do not
// count), smoothed over rows (bands change slowly from row to row) and relative to their
// median; LevelRows divides the rows by them, giving the picture the reference's banding.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace liftoff::video::internal {

/// Each row's gain of `grey` against `reference` (both CV_32F of one size): the median over
/// the row's columns where the reference is at least `min_level` of their ratio, rows with
/// fewer than half their columns measured taking the nearest measured row's; then a running
/// mean over 2 * smooth_rows + 1 rows (clipped at the picture's edges); then divided by the
/// median of all rows. Empty when no row can be measured.
std::vector<float> RowGains(const cv::Mat& grey, const cv::Mat& reference, int smooth_rows,
                            float min_level);

/// Largest minus smallest of `gains` (0 for none): how far the rows' banding differs from the
/// reference's.
float GainRange(const std::vector<float>& gains);

/// Divides each row of `image` (CV_32F, any channels; as many rows as `gains`) by its gain.
void LevelRows(cv::Mat& image, const std::vector<float>& gains);

}  // namespace liftoff::video::internal
