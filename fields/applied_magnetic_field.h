// The applied magnetic field the DEM holds: B and ∇B at a particle and a time.
//
// Three kinds, chosen once from the case (AppliedField in case_model.h), dispatched by a
// switch on a small enum — no virtual call, no allocation per lookup:
//  * none:    B = 0, ∇B = 0;
//  * uniform: B = s(t) B_0 d̂, ∇B = 0, no grid lookup at all (Kawamoto's compression test);
//  * roller:  s(t) × the polar-grid interpolator of the roller's A_z (polar_field_interpolator.h).
// The ramp s(t) = min(1, t / ramp_time) (s = 1 when ramp_time = 0) multiplies either kind.
// A uniform field may instead follow a piecewise-linear schedule |B|(t) (AppliedField::schedule:
// Kawamoto's field sweep at a held plate): then s(t) = |B|(t) / max|B|, linear between the
// samples, held at the end values outside them.
//
// With a uniform (or no) field, ∇B = 0 and the applied force (p·∇)B vanishes:
// has_gradient() lets the DEM skip that term and report it as off.
//
// The object is cheap to copy (the grid interpolator is shared, read-only) and safe to call
// from many OpenMP threads at once.
#pragma once

#include "case/case_model.h"
#include "fields/polar_field_interpolator.h"

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace magbrush {

class AppliedMagneticField
{
public:
  enum class Kind { none, uniform, roller };

  AppliedMagneticField() = default; // none
  static AppliedMagneticField uniform(const Vec3 &direction, double magnitude,
                                      double ramp_time = 0.0);
  // A uniform field whose magnitude follows the piecewise-linear schedule (t [s], |B| [T]):
  // times strictly increasing, magnitudes ≥ 0 with at least one > 0.
  static AppliedMagneticField uniform_schedule(const Vec3 &direction,
                                               const std::vector<std::pair<double, double>> &schedule);
  static AppliedMagneticField roller(std::shared_ptr<const PolarFieldInterpolator> grid,
                                     double ramp_time = 0.0);
  // From the case's AppliedField; `grid` is required for Kind::roller (read it with
  // read_magnetic_grid after check_provenance) and ignored otherwise.
  static AppliedMagneticField from_settings(const AppliedField &settings,
                                            std::shared_ptr<const PolarFieldInterpolator> grid = {});

  // What `magbrush dem` does: the case's applied field; for a roller, read the magnetic grid
  // at `grid_path` (fields/field_files.h magnetic_grid_path), check that it was computed
  // for this case (throws ProvenanceMismatch naming the key otherwise) and interpolate it.
  // FieldGridError when the file is missing or malformed.
  static AppliedMagneticField for_case(const Case &c, const std::string &grid_path);

  Kind kind() const { return kind_; }
  const char *kind_name() const;
  bool has_gradient() const { return kind_ == Kind::roller; }
  double ramp_time() const { return ramp_time_; }
  const PolarFieldInterpolator *grid() const { return grid_.get(); }

  // The ramp factor s(t) ∈ [0, 1].
  double ramp(double t) const
  {
    if (!schedule_.empty())
      return scheduled(t);
    if (ramp_time_ <= 0.0 || t >= ramp_time_)
      return 1.0;
    return t > 0.0 ? t / ramp_time_ : 0.0;
  }

  // B [T] and gradB[i][j] = ∂B_i/∂x_j [T/m] at x [m], time t [s]. Roller kind: throws
  // FieldLookupError inside the sleeve (see PolarFieldInterpolator).
  void evaluate(const Vec3 &x, double t, Vec3 &B, std::array<Vec3, 3> &gradB) const
  {
    const double s = ramp(t);
    switch (kind_)
    {
    case Kind::none:
      B = {0.0, 0.0, 0.0};
      gradB = {};
      return;
    case Kind::uniform:
      B = {s * uniform_B_[0], s * uniform_B_[1], s * uniform_B_[2]};
      gradB = {};
      return;
    case Kind::roller:
      grid_->evaluate(x, B, gradB);
      if (s != 1.0)
        scale(s, B, gradB);
      return;
    }
  }

  // As evaluate(), but never throws: false (B = 0, ∇B = 0) inside the sleeve. For OpenMP
  // loops, where an exception must not escape the parallel region: count the failures and
  // stop the run after the loop with a message.
  bool try_evaluate(const Vec3 &x, double t, Vec3 &B, std::array<Vec3, 3> &gradB) const noexcept
  {
    if (kind_ != Kind::roller)
    {
      evaluate(x, t, B, gradB);
      return true;
    }
    if (!grid_->try_evaluate(x, B, gradB))
      return false;
    const double s = ramp(t);
    if (s != 1.0)
      scale(s, B, gradB);
    return true;
  }

  Vec3 field(const Vec3 &x, double t) const
  {
    Vec3 B;
    std::array<Vec3, 3> gradB;
    evaluate(x, t, B, gradB);
    return B;
  }

  // The same with plain arrays, for code that takes a callable
  // void(const double x[3], double B[3], double gradB[3][3]) (magnetics/): bind t with
  //   [&field, t](const double *x, double *B, double (*g)[3]) { field.evaluate(x, t, B, g); }
  void evaluate(const double x[3], double t, double B[3], double gradB[3][3]) const
  {
    Vec3 b;
    std::array<Vec3, 3> g;
    evaluate(Vec3{x[0], x[1], x[2]}, t, b, g);
    for (int i = 0; i < 3; ++i)
    {
      B[i] = b[i];
      for (int j = 0; j < 3; ++j)
        gradB[i][j] = g[i][j];
    }
  }

  // The schedule as (t, s) samples (empty for the linear ramp).
  const std::vector<std::pair<double, double>> &schedule() const { return schedule_; }

private:
  // Piecewise-linear s(t) through the schedule's samples (binary search: a handful of points).
  double scheduled(double t) const
  {
    if (t <= schedule_.front().first)
      return schedule_.front().second;
    if (t >= schedule_.back().first)
      return schedule_.back().second;
    std::size_t lo = 0, hi = schedule_.size() - 1;
    while (hi - lo > 1)
    {
      const std::size_t mid = (lo + hi) / 2;
      (schedule_[mid].first <= t ? lo : hi) = mid;
    }
    const auto &[t0, s0] = schedule_[lo];
    const auto &[t1, s1] = schedule_[hi];
    return s0 + (s1 - s0) * (t - t0) / (t1 - t0);
  }

  static void scale(double s, Vec3 &B, std::array<Vec3, 3> &gradB)
  {
    for (int i = 0; i < 3; ++i)
    {
      B[i] *= s;
      for (int j = 0; j < 3; ++j)
        gradB[i][j] *= s;
    }
  }

  Kind kind_ = Kind::none;
  Vec3 uniform_B_{0.0, 0.0, 0.0}; // final field B_0 d̂ [T]
  double ramp_time_ = 0.0;
  std::vector<std::pair<double, double>> schedule_; // (t, s(t)) samples; empty = linear ramp
  std::shared_ptr<const PolarFieldInterpolator> grid_;
};

} // namespace magbrush
