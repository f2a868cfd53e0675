#include "dem/force_terms/electric_field_force.h"

#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/force_terms/held_forces.h"

#include "fields/field_files.h"
#include "fields/zero_electric_field.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

ElectricFieldForce::ElectricFieldForce(std::shared_ptr<const NipPotentialField> field,
                                       const Drum &drum, const std::array<double, 3> &box)
  : field_(std::move(field)), drum_(drum), box_(box)
{
  if (!field_)
    throw std::invalid_argument("applied electric field: no nip field given");
  weights_ = field_->make_phase_weights();
}

template <typename Index>
void ElectricFieldForce::add_forces_over(const ParticleState &s, ForceBuffers &f, double t, long count, Index index)
{
  // One phase for the whole step: the image has travelled u(t) with the drum surface.
  field_->phase_weights(NipPotentialField::surface_travel(drum_, t), weights_);
  const NipPotentialField &field = *field_;
  const NipPotentialField::PhaseWeights &w = weights_;
  const std::array<double, 3> box = box_;
  long charged = 0, outside = 0, first_outside = -1;
#pragma omp parallel for schedule(static) reduction(+ : charged, outside) reduction(max : first_outside) if (count > 512)
  for (long m = 0; m < count; ++m)
  {
    const long i = static_cast<long>(index(m));
    const std::size_t k = static_cast<std::size_t>(i);
    const double q = s.charge[k];
    if (q == 0.0)
      continue;
    Vec3 x{s.x[k], s.y[k], s.z[k]};
    for (int d = 0; d < 3; ++d)
      if (box[d] > 0.0)
        x[d] -= box[d] * std::floor(x[d] / box[d]);
    Vec3 E;
    ++charged;
    if (!field.evaluate(x, w, E))
    {
      ++outside;
      first_outside = i > first_outside ? i : first_outside;
      continue;
    }
    f.fx[k] += q * E[0];
    f.fy[k] += q * E[1];
  }
  lookups_ += charged;
  outside_ += outside;
  if (outside > 0 && !warned_)
  {
    warned_ = true;
    const std::size_t k = static_cast<std::size_t>(first_outside);
    std::fprintf(stderr,
                 "magbrush-dem: warning: charged particle %d at (%.4g, %.4g) mm left the electric "
                 "grid window x = [%.4g, %.4g] mm, y = [%.4g, %.4g] mm at t = %.6g s; the applied "
                 "field is zero outside it (docs/electrostatics.md); %ld such lookups this step\n",
                 s.id[k], 1e3 * s.x[k], 1e3 * s.y[k], 1e3 * field.x_min(), 1e3 * field.x_max(),
                 1e3 * field.y_min(), 1e3 * field.y_max(), t, outside);
  }
}

void ElectricFieldForce::add_forces(const ParticleState &s, ForceBuffers &f, double t)
{
  add_forces_over(s, f, t, static_cast<long>(s.size()), [](long m) { return m; });
}

void ElectricFieldForce::add_forces_of(const ParticleState &s, ForceBuffers &f, double t,
                                       const std::vector<std::uint32_t> &which)
{
  add_forces_over(s, f, t, static_cast<long>(which.size()), [&which](long m) { return which[static_cast<std::size_t>(m)]; });
}

namespace {
// qE needs the nip field (electric section on, so the field stage stored it) and charges to act
// on. The charges are known per population here, before any particle exists.
std::string electric_field_not_needed_because(const Case &c)
{
  if (!c.electric.enabled)
    return "the case has no enabled electric section";
  // The nip field is the bias solution plus the latent image's: with both zero, E = 0
  // everywhere and qE would only read the grid to add zeros (the field stage stores none).
  if (electric_field_is_zero(c))
    return "the electric field is zero (electric.bias = 0 V and no latent image)";
  if (c.has_charged_population())
    return "";
  return "no population is charged";
}

std::unique_ptr<ForceTerm> make_electric_field(const Case &c, const DemSystem &system)
{
  auto field = std::make_shared<const NipPotentialField>(
    NipPotentialField::for_case(c, field::electric_grid_path(c)));
  // Held between moves of the particles and of the latent image (held_forces.h).
  const Drum drum = c.drum;
  return held_for(std::make_unique<ElectricFieldForce>(std::move(field), c.drum, system.box().length),
                  c.electric.hold_distance, system.box().length,
                  [drum](double t) { return NipPotentialField::surface_travel(drum, t); });
}

const bool registered = register_force_term({"applied electric field qE", force_term_order::electric_field,
                                             electric_field_not_needed_because, make_electric_field});
} // namespace

} // namespace magbrush::dem
