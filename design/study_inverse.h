// The inverse of a finished study: which value of the varied key (the blade gap, the bias)
// gives a target value of a measured quantity (the DMA, the TMA), with its standard error.
//
// The study's table (sweep_summary.csv or sweep_mean.csv of `magbrush sweep`) has one row per
// point: the varied value as given and in SI ("<key> [unit]"), then every key number with its
// standard error ("<quantity>_stderr"). Two ways to invert it:
//
//   piecewise   where the means are strictly monotone in the varied value, the straight piece
//               between the two points that bracket the target: x* = x_i + t Δx with
//               t = (T − y_i)/Δy, and from the points' standard errors (independent runs)
//               σ_x² = (Δx/Δy)² [(1 − t)² σ_i² + t² σ_{i+1}²];
//   line        the straight line through all points weighted by 1/σ², x* = (T − a)/b, its
//               σ from the covariance of (a, b) (scaled by χ²/dof when that exceeds 1: the
//               line then misses the points by more than their errors).
//
// `automatic` takes the piecewise answer when the means are monotone, else the line (noise
// larger than the steps). A target outside the range of the means is said to be outside; the
// line's extrapolation is then the only answer, marked as such.
#pragma once

#include <string>
#include <vector>

namespace magbrush {

struct StudySample
{
  std::string label;
  double x = 0, y = 0, se = 0; // varied value [SI], quantity, its standard error (0: none)
};

struct StudyTable
{
  std::string source;
  std::string case_path;       // from the table's "# magbrush sweep of CASE" line, if any
  std::string x_key, y_key;
  std::vector<StudySample> points; // sorted by x
  std::vector<std::string> notes; // rows skipped and why
};

// Reads the varied column "<x_key> [unit]" (SI) — or "<x_key>" when it holds plain numbers —
// and the quantity with "<y_key>_stderr". Rows whose status is not ok, or with a missing or
// non-finite value, are skipped with a note. Throws naming the columns found when one is missing.
StudyTable read_study_table(const std::string &path, const std::string &x_key, const std::string &y_key);

struct StudyAnswer
{
  enum class Method { automatic, piecewise, line };
  double x = 0, se = 0;         // the answer [SI] and its standard error
  bool inside = true;           // the target lies within the range of the study's means
  bool monotone = true;         // the means are strictly monotone in x
  Method method = Method::piecewise;
  std::string how;              // the method in words, with the points used
  double slope = 0, slope_se = 0, chi2_per_dof = 0; // the line's (always computed, ≥ 2 points)
};

StudyAnswer invert_study(const StudyTable &table, double target,
                         StudyAnswer::Method method = StudyAnswer::Method::automatic);

} // namespace magbrush
