#include "dem/force_terms/conductor_images.h"

#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/force_terms/held_forces.h"
#include "electrostatics/coulomb_constants.h"

#include <algorithm>

namespace magbrush::electrostatics {

ConductorImages::ConductorImages(std::vector<GroundedSurface> surfaces) : surfaces_(std::move(surfaces)) {}

std::vector<GroundedSurface> ConductorImages::surfaces_of(const Case &c)
{
  std::vector<GroundedSurface> s;
  if (!c.sleeve)
    return s;
  if (c.drum.present)
  {
    GroundedSurface drum;
    drum.shape = GroundedSurface::Shape::cylinder;
    const Vec2 centre = c.drum.center(c.sleeve->radius);
    drum.centre_x = centre[0];
    drum.centre_y = centre[1];
    drum.radius = c.drum.radius;
    drum.layer = LayeredImages(c.drum.pc_eps_r, c.drum.pc_thickness);
    s.push_back(drum);
  }
  GroundedSurface sleeve;
  sleeve.shape = GroundedSurface::Shape::cylinder;
  sleeve.radius = c.sleeve->radius;
  s.push_back(sleeve);
  return s;
}

template <typename Index>
void ConductorImages::add_forces_over(const dem::ParticleState &state, dem::ForceBuffers &forces, long count,
                                      Index index) const
{
#pragma omp parallel for schedule(static) if (count >= 2048)
  for (long m = 0; m < count; ++m)
  {
    const std::size_t i = static_cast<std::size_t>(index(m));
    const double q = state.charge[i];
    if (q == 0.0)
      continue;
    for (const GroundedSurface &surface : surfaces_)
    {
      double normal[3];
      const double h = std::max(surface.height(state.x[i], state.y[i], state.z[i], normal), state.radius[i]);
      const double f = coulomb_constant * q * q * surface.layer.self_force(h);
      forces.fx[i] += f * normal[0];
      forces.fy[i] += f * normal[1];
      forces.fz[i] += f * normal[2];
    }
  }
}

void ConductorImages::add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double)
{
  add_forces_over(state, forces, static_cast<long>(state.size()), [](long m) { return m; });
}

void ConductorImages::add_forces_of(const dem::ParticleState &state, dem::ForceBuffers &forces, double,
                                    const std::vector<std::uint32_t> &which)
{
  add_forces_over(state, forces, static_cast<long>(which.size()),
                  [&which](long m) { return which[static_cast<std::size_t>(m)]; });
}

namespace {
std::string images_not_needed_because(const Case &c)
{
  if (!c.electric.conductor_images)
    return "electric.conductor_images is false (Kweon: the field is unchanged by the toner)";
  if (!c.sleeve)
    return "the scene has no sleeve or drum";
  if (c.has_charged_population())
    return "";
  return "no population is charged";
}

const bool registered = dem::register_force_term(
    {"conductor images", dem::force_term_order::conductor_images, images_not_needed_because,
     [](const Case &c, const dem::DemSystem &system) -> std::unique_ptr<dem::ForceTerm> {
       return dem::held_for(std::make_unique<ConductorImages>(ConductorImages::surfaces_of(c)),
                            c.electric.hold_distance, system.box().length);
     }});
} // namespace

} // namespace magbrush::electrostatics
