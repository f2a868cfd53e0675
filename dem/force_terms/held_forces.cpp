#include "dem/force_terms/held_forces.h"

#include "dem/checkpoint_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

HeldForces::HeldForces(std::unique_ptr<ForceTerm> inner, double hold_distance, const std::array<double, 3> &box,
                       std::function<double(double)> source_travel, double renew_share,
                       std::optional<RotatingFrame> frame)
  : inner_(std::move(inner)), hold_distance_(hold_distance), box_(box), source_travel_(std::move(source_travel)),
    renew_share_(renew_share), frame_(std::move(frame))
{
  if (!inner_)
    throw std::invalid_argument("held forces: no force term given");
  if (!(hold_distance_ >= 0.0))
    throw std::invalid_argument("held forces: the hold distance must be >= 0");
  per_particle_ = inner_->acts_on_each_particle_alone();
  if (frame_ && per_particle_)
    throw std::invalid_argument("held forces: '" + std::string(inner_->name()) +
                                "' acts on each particle where it is in the lab: its moves cannot be measured in a "
                                "turning frame");
  if (frame_ && (box_[0] > 0.0 || box_[1] > 0.0))
    throw std::invalid_argument("held forces: a frame turning about z needs x and y not periodic");
  if (frame_ && (!frame_->angle || !(frame_->max_turn > 0.0)))
    throw std::invalid_argument("held forces: a turning frame needs its angle and a positive max_turn");
}

void HeldForces::turn_frame(double t)
{
  if (!frame_)
    return;
  const double a = frame_->angle(t);
  cos_ = std::cos(a);
  sin_ = std::sin(a);
}

void HeldForces::set_reference(const ParticleState &state, std::size_t i)
{
  if (frame_)
  {
    const double dx = state.x[i] - frame_->cx, dy = state.y[i] - frame_->cy;
    x0_[i] = cos_ * dx + sin_ * dy;
    y0_[i] = -sin_ * dx + cos_ * dy;
  }
  else
  {
    x0_[i] = state.x[i];
    y0_[i] = state.y[i];
  }
  z0_[i] = state.z[i];
}

void HeldForces::squared_moves(const ParticleState &state, std::size_t begin, std::size_t end, double *out) const
{
  // Minimum image along the periodic axes: crossing the box is no move. A move is far below
  // half the box, so one wrap is the only case. Written without calls or branches (a wrap is
  // a select, an axis that is not periodic has half = 0 and wraps by 0) so that the compiler
  // vectorises it: this check runs for every particle at every step, once per held term.
  const double *x = state.x.data(), *y = state.y.data(), *z = state.z.data();
  const double *x0 = x0_.data(), *y0 = y0_.data(), *z0 = z0_.data();
  const double bx = box_[0], by = box_[1], bz = box_[2];
  const double hx = 0.5 * bx, hy = 0.5 * by, hz = 0.5 * bz;
  if (frame_)
  {
    // In the turning frame (x and y are not periodic there): the position turned back by the
    // frame's angle, against the reference stored the same way.
    const double c = cos_, s = sin_, cx = frame_->cx, cy = frame_->cy;
    for (std::size_t i = begin; i < end; ++i)
    {
      const double px = x[i] - cx, py = y[i] - cy;
      const double dx = c * px + s * py - x0[i], dy = -s * px + c * py - y0[i];
      double dz = z[i] - z0[i];
      dz -= (dz > hz ? bz : 0.0) - (dz < -hz ? bz : 0.0);
      out[i - begin] = dx * dx + dy * dy + dz * dz;
    }
    return;
  }
  for (std::size_t i = begin; i < end; ++i)
  {
    double dx = x[i] - x0[i], dy = y[i] - y0[i], dz = z[i] - z0[i];
    dx -= (dx > hx ? bx : 0.0) - (dx < -hx ? bx : 0.0);
    dy -= (dy > hy ? by : 0.0) - (dy < -hy ? by : 0.0);
    dz -= (dz > hz ? bz : 0.0) - (dz < -hz ? bz : 0.0);
    out[i - begin] = dx * dx + dy * dy + dz * dz;
  }
}

bool HeldForces::stale_as_a_whole(const ParticleState &state, double t) const
{
  if (!valid_ || held_.fx.size() != state.size())
    return true;
  if (frame_ && std::abs(frame_->angle(t) - frame_->angle(evaluated_at_)) >= frame_->max_turn)
    return true;
  return source_travel_ && std::abs(source_travel_(t) - source_travel_(evaluated_at_)) >= hold_distance_;
}

bool HeldForces::must_evaluate(const ParticleState &state, double t) const
{
  if (stale_as_a_whole(state, t))
    return true;
  // The largest squared displacement since the last evaluation (a max is the same on any
  // number of threads).
  const long blocks = static_cast<long>((state.size() + move_block - 1) / move_block);
  double largest = 0.0;
#pragma omp parallel for schedule(static) reduction(max : largest) if (blocks > 16)
  for (long b = 0; b < blocks; ++b)
  {
    double d2[move_block];
    const std::size_t begin = static_cast<std::size_t>(b) * move_block,
                      end = std::min(state.size(), begin + move_block);
    squared_moves(state, begin, end, d2);
    for (std::size_t k = 0; k < end - begin; ++k)
      largest = d2[k] > largest ? d2[k] : largest;
  }
  return largest >= hold_distance_ * hold_distance_;
}

void HeldForces::evaluate(const ParticleState &state, double t)
{
  held_.resize(state.size()); // zeroed
  inner_->add_forces(state, held_, t);
  if (frame_)
  {
    x0_.resize(state.size());
    y0_.resize(state.size());
    z0_.resize(state.size());
    for (std::size_t i = 0; i < state.size(); ++i)
      set_reference(state, i);
  }
  else
  {
    x0_ = state.x;
    y0_ = state.y;
    z0_ = state.z;
  }
  evaluated_at_ = t;
  valid_ = true;
  evaluations_ += 1;
}

void HeldForces::hold_as_a_whole(const ParticleState &state, double t)
{
  if (renew_share_ <= 0.0)
  {
    if (must_evaluate(state, t))
      evaluate(state, t);
    return;
  }
  if (stale_as_a_whole(state, t))
  {
    evaluate(state, t);
    return;
  }
  // Who moved d since their last evaluation or renewal, in index order (serial: the list is
  // the same on any number of threads). Few: the term renews them alone, if it can. The scan
  // stops at the block where they became too many.
  const std::size_t n = state.size(), most = static_cast<std::size_t>(renew_share_ * static_cast<double>(n));
  const double hold2 = hold_distance_ * hold_distance_;
  which_.clear();
  double d2[move_block];
  for (std::size_t begin = 0; begin < n && which_.size() <= most; begin += move_block)
  {
    const std::size_t end = std::min(n, begin + move_block);
    squared_moves(state, begin, end, d2);
    for (std::size_t i = begin; i < end; ++i)
      if (d2[i - begin] >= hold2)
        which_.push_back(static_cast<std::uint32_t>(i));
  }
  if (which_.empty())
    return;
  if (which_.size() > most || !inner_->renew_moved(state, held_, t, which_))
  {
    evaluate(state, t);
    return;
  }
  for (const std::uint32_t i : which_)
    set_reference(state, i);
  renewals_ += 1;
  renewed_ += static_cast<long>(which_.size());
}

void HeldForces::evaluate_moved_particles(const ParticleState &state, double t)
{
  const std::size_t n = state.size();
  if (held_.fx.size() != n) // the first step (or a state of another size): everybody
  {
    held_.resize(n);
    x0_.assign(n, 0.0);
    y0_.assign(n, 0.0);
    z0_.assign(n, 0.0);
    u0_.assign(n, 0.0);
    stale_.assign(n, 1);
  }
  // Who moved (or whose source did), in index order: the list, and so the bits, are the same on
  // any number of threads.
  const double u = source_travel_ ? source_travel_(t) : 0.0, hold2 = hold_distance_ * hold_distance_;
  which_.clear();
  double d2[move_block];
  for (std::size_t begin = 0; begin < n; begin += move_block)
  {
    const std::size_t end = std::min(n, begin + move_block);
    squared_moves(state, begin, end, d2);
    for (std::size_t i = begin; i < end; ++i)
      if (stale_[i] || std::abs(u - u0_[i]) >= hold_distance_ || d2[i - begin] >= hold2)
        which_.push_back(static_cast<std::uint32_t>(i));
  }
  if (which_.empty())
    return;
  for (const std::uint32_t i : which_)
  {
    for (auto *a : {&held_.fx, &held_.fy, &held_.fz, &held_.tx, &held_.ty, &held_.tz})
      (*a)[i] = 0.0;
    x0_[i] = state.x[i];
    y0_[i] = state.y[i];
    z0_[i] = state.z[i];
    u0_[i] = u;
    stale_[i] = 0;
  }
  inner_->add_forces_of(state, held_, t, which_);
  evaluations_ += static_cast<long>(which_.size());
}

void HeldForces::add_forces(const ParticleState &state, ForceBuffers &forces, double t)
{
  if (per_particle_)
  {
    calls_ += static_cast<long>(state.size());
    evaluate_moved_particles(state, t);
  }
  else
  {
    ++calls_;
    turn_frame(t);
    hold_as_a_whole(state, t);
  }
  const long n = static_cast<long>(state.size());
#pragma omp parallel for schedule(static) if (n > 4096)
  for (long il = 0; il < n; ++il)
  {
    const std::size_t i = static_cast<std::size_t>(il);
    forces.fx[i] += held_.fx[i];
    forces.fy[i] += held_.fy[i];
    forces.fz[i] += held_.fz[i];
    forces.tx[i] += held_.tx[i];
    forces.ty[i] += held_.ty[i];
    forces.tz[i] += held_.tz[i];
  }
}

void HeldForces::particles_reordered(const std::vector<std::int32_t> &order)
{
  inner_->particles_reordered(order);
  if (held_.fx.size() != order.size())
    return; // nothing held for these particles yet
  held_.permute(order, scratch_);
  for (auto *a : {&x0_, &y0_, &z0_})
    permute_array(*a, order, scratch_);
  if (per_particle_)
  {
    permute_array(u0_, order, scratch_);
    std::vector<std::uint8_t> stale(order.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      stale[k] = stale_[static_cast<std::size_t>(order[k])];
    stale_.swap(stale);
  }
}

void HeldForces::particles_changed(const std::vector<std::int32_t> &origin)
{
  inner_->particles_changed(origin);
  if (!per_particle_ || held_.fx.empty())
  {
    valid_ = false; // held as a whole: everybody again at the next step
    return;
  }
  // Per particle: the stayers keep what they hold, the newcomers are evaluated at the next step.
  const std::size_t n = origin.size();
  auto carry = [&](std::vector<double> &a) {
    scratch_.assign(n, 0.0);
    for (std::size_t k = 0; k < n; ++k)
      if (origin[k] >= 0)
        scratch_[k] = a[static_cast<std::size_t>(origin[k])];
    a.swap(scratch_);
  };
  for (auto *a : {&held_.fx, &held_.fy, &held_.fz, &held_.tx, &held_.ty, &held_.tz, &x0_, &y0_, &z0_, &u0_})
    carry(*a);
  held_.zero_fast();
  std::vector<std::uint8_t> stale(n, 1);
  for (std::size_t k = 0; k < n; ++k)
    if (origin[k] >= 0)
      stale[k] = stale_[static_cast<std::size_t>(origin[k])];
  stale_.swap(stale);
}

void HeldForces::write_state(CheckpointWriter &out) const
{
  inner_->write_state(out);
  out.put<std::uint8_t>(valid_ ? 1 : 0);
  out.put<double>(evaluated_at_);
  out.put<std::int64_t>(evaluations_);
  out.put<std::int64_t>(calls_);
  for (const auto *a : {&held_.fx, &held_.fy, &held_.fz, &held_.tx, &held_.ty, &held_.tz, &x0_, &y0_, &z0_, &u0_})
    out.put_array(*a);
  out.put_array(stale_);
}

void HeldForces::read_state(CheckpointReader &in)
{
  inner_->read_state(in);
  valid_ = in.get<std::uint8_t>() != 0;
  evaluated_at_ = in.get<double>();
  evaluations_ = static_cast<long>(in.get<std::int64_t>());
  calls_ = static_cast<long>(in.get<std::int64_t>());
  for (auto *a : {&held_.fx, &held_.fy, &held_.fz, &held_.tx, &held_.ty, &held_.tz, &x0_, &y0_, &z0_, &u0_})
    in.get_array(*a);
  in.get_array(stale_);
  held_.zero_fast();
  const std::size_t n = held_.fx.size();
  for (const auto *a : {&held_.fy, &held_.fz, &held_.tx, &held_.ty, &held_.tz, &x0_, &y0_, &z0_})
    if (a->size() != n)
      in.fail("is corrupt (the held forces of '" + std::string(name()) + "' have arrays of different lengths)");
  if (per_particle_ && (u0_.size() != n || stale_.size() != n))
    in.fail("is corrupt (the held forces of '" + std::string(name()) + "' have arrays of different lengths)");
}

std::string HeldForces::cost_note() const
{
  char line[200];
  const double share = calls_ > 0 ? 100.0 * static_cast<double>(evaluations_) / static_cast<double>(calls_) : 0.0;
  if (per_particle_)
    std::snprintf(line, sizeof line, "evaluated at %.2g %% of %ld particle-steps, each held until it moved %.3g nm",
                  share, calls_, hold_distance_ * 1e9);
  else if (renew_share_ <= 0.0)
    std::snprintf(line, sizeof line, "evaluated at %ld of %ld steps (%.2g %%), held until something moved %.3g nm",
                  evaluations_, calls_, share, hold_distance_ * 1e9);
  else
    std::snprintf(line, sizeof line,
                  "evaluated at %ld of %ld steps (%.2g %%), held until something moved %.3g nm; the moved alone "
                  "renewed at %ld steps since the start of this run (%.3g particles each)",
                  evaluations_, calls_, share, hold_distance_ * 1e9, renewals_,
                  renewals_ > 0 ? static_cast<double>(renewed_) / static_cast<double>(renewals_) : 0.0);
  std::string note = line;
  if (frame_)
    note += " (moves measured in the frame turning with the sleeve)";
  const std::string inner = inner_->cost_note();
  return inner.empty() ? note : note + "; " + inner;
}

std::unique_ptr<ForceTerm> held_for(std::unique_ptr<ForceTerm> term, double hold_distance,
                                    const std::array<double, 3> &box, std::function<double(double)> source_travel,
                                    double renew_share, std::optional<RotatingFrame> frame)
{
  if (hold_distance <= 0.0)
    return term;
  return std::make_unique<HeldForces>(std::move(term), hold_distance, box, std::move(source_travel), renew_share,
                                      std::move(frame));
}

} // namespace magbrush::dem
