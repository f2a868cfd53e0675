#include "magnetics/slab_tail.h"

#include "magnetics/dipole_physics.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

SlabTail::SlabTail(const std::array<double, 3> &box) : box_(box)
{
  int open = 0;
  for (int d = 0; d < 3; ++d)
    if (box_[d] == 0.0)
    {
      normal_axis_ = d;
      ++open;
    }
  if (open != 1)
    throw std::invalid_argument(
      "magnetics: the slab tail correction needs a slab periodic along exactly two axes and "
      "open along the third; found " + std::to_string(3 - open) +
      " periodic axes. Switch slab_tail_correction off for this box.");
}

void SlabTail::prepare(const BeadArrays &beads, double cutoff)
{
  const std::size_t n = beads.n;
  const double *u = normal_axis_ == 0 ? beads.x : normal_axis_ == 1 ? beads.y : beads.z;
  area_ = 1.0;
  for (int d = 0; d < 3; ++d)
    if (d != normal_axis_)
      area_ *= box_[d];
  cutoff_ = cutoff;
  // Sort along the open axis (ties by index: deterministic), centred to limit cancellation.
  order_.resize(n);
  for (std::size_t b = 0; b < n; ++b)
    order_[b] = static_cast<std::uint32_t>(b);
  std::sort(order_.begin(), order_.end(), [&](std::uint32_t i, std::uint32_t j) {
    return u[i] < u[j] || (u[i] == u[j] && i < j);
  });
  const double centre = 0.5 * (u[order_.front()] + u[order_.back()]);
  u_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    u_[k] = u[order_[k]] - centre;
  // Window of every bead (in sorted positions): the sheets with |h| < R_c.
  lo_.resize(n);
  hi_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const double uk = u_[k];
    lo_[k] = std::lower_bound(u_.begin(), u_.end(), uk - cutoff) - u_.begin();
    hi_[k] = std::upper_bound(u_.begin(), u_.end(), uk + cutoff) - u_.begin();
  }
  S0_.resize(3 * (n + 1));
  S1_.resize(3 * (n + 1));
  S2_.resize(3 * (n + 1));
  B_.resize(3 * n);
  dB_.resize(3 * n);
}

void SlabTail::evaluate(const std::vector<double> &p)
{
  const std::size_t n = order_.size();
  const int na = normal_axis_;
  // Prefix sums over the sorted beads of the sheet moments q = 2 p_n n̂ − p_t and of q u, q u².
  for (int d = 0; d < 3; ++d)
    S0_[d] = S1_[d] = S2_[d] = 0.0;
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::uint32_t b = order_[k];
    const double uk = u_[k];
    for (int d = 0; d < 3; ++d)
    {
      const double q = (d == na ? 2.0 : -1.0) * p[3 * b + d];
      S0_[3 * (k + 1) + d] = S0_[3 * k + d] + q;
      S1_[3 * (k + 1) + d] = S1_[3 * k + d] + q * uk;
      S2_[3 * (k + 1) + d] = S2_[3 * k + d] + q * uk * uk;
    }
  }
  const double Rc = cutoff_, c = -mu0 / (4.0 * Rc * area_);
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
  for (long k = 0; k < static_cast<long>(n); ++k)
  {
    const std::uint32_t b = order_[k];
    const double ui = u_[k];
    const std::size_t lo = lo_[k], hi = hi_[k];
    for (int d = 0; d < 3; ++d)
    {
      const double S0 = S0_[3 * hi + d] - S0_[3 * lo + d];
      const double S1 = S1_[3 * hi + d] - S1_[3 * lo + d];
      const double S2 = S2_[3 * hi + d] - S2_[3 * lo + d];
      // Σ_k (1 − (u_k − u_i)²/R_c²) q_k  and its derivative in u_i, Σ 2(u_k − u_i)/R_c² q_k.
      B_[3 * b + d] = c * (S0 - (S2 - 2.0 * ui * S1 + ui * ui * S0) / (Rc * Rc));
      dB_[3 * b + d] = c * 2.0 * (S1 - ui * S0) / (Rc * Rc);
    }
  }
}

void SlabTail::scale(double ratio)
{
  for (auto *v : {&B_, &dB_})
    for (double &x : *v)
      x *= ratio;
}

void SlabTail::write_state(StateOut &out) const
{
  out.put(normal_axis_);
  out.put(area_);
  out.put(cutoff_);
  out.put_array(order_);
  out.put_array(lo_);
  out.put_array(hi_);
  for (const auto *v : {&u_, &S0_, &S1_, &S2_, &B_, &dB_})
    out.put_array(*v);
}

void SlabTail::read_state(StateIn &in)
{
  if (in.get<int>() != normal_axis_)
    in.fail("holds a slab tail along another axis than this run's: restart with the case that wrote it");
  area_ = in.get<double>();
  cutoff_ = in.get<double>();
  in.get_array(order_);
  in.get_array(lo_);
  in.get_array(hi_);
  for (auto *v : {&u_, &S0_, &S1_, &S2_, &B_, &dB_})
    in.get_array(*v);
}

} // namespace magbrush::magnetics
