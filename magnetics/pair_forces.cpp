#include "magnetics/pair_forces.h"

namespace magbrush::magnetics {

std::size_t PairForces::evaluate_all(const InducedState &s, const NearPairs &near,
                                     const TwoSphereCorrection *correction)
{
  const std::size_t np = near.pairs().size();
  force_.resize(3 * np);
  std::size_t corrected_pairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : corrected_pairs) if (np >= bead_parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
    corrected_pairs += evaluate(s, near, correction, k);
  return corrected_pairs;
}

bool PairForces::evaluate(const InducedState &s, const NearPairs &near,
                          const TwoSphereCorrection *correction, std::size_t k)
{
  double *F = &force_[3 * k];
  if (!near.active(k))
  {
    F[0] = F[1] = F[2] = 0.0;
    return false;
  }
  const std::uint32_t i = near.pairs()[k].i, j = near.pairs()[k].j;
  const double *r = near.r(k);
  dipole_pair_force(r, &s.p[3 * j], &s.p[3 * i], F);
  if (!correction)
    return false;
  return correction->add(s, i, j, r, near.tensor(k), F);
}

void PairForces::scale(double ratio2)
{
  for (double &x : force_)
    x *= ratio2;
}

void PairForces::write_state(StateOut &out) const { out.put_array(force_); }

void PairForces::read_state(StateIn &in) { in.get_array(force_); }

} // namespace magbrush::magnetics
