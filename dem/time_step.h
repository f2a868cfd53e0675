// The automatic time step and the refusal of unstable user steps.
//
// Two criteria, the smaller wins:
//  * Rayleigh time of the smallest particle of each species (the classic DEM critical step,
//    the time a Rayleigh surface wave needs to cross the sphere):
//        T_R = π r √(ρ/G) / (0.1631 ν + 0.8766)
//  * Hertz: the contact duration t_c = 2.868 (m*² / (R* E*² v))^{1/5} of the lightest pair of
//    each interaction type (including the stiff walls) at a reference impact speed, divided by
//    10 (at least ten steps resolve the stiffest collision; below ~t_c/π the explicit scheme
//    is unstable).
// The limit is the smaller of the two; the automatic step is DemSettings::time_step_safety
// times the limit; a user step above the limit is refused with the limit in the message.
#pragma once

#include "dem/contact_parameters.h"
#include "dem/particle_state.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

struct StableTimeStep
{
  double limit = 0.0;
  double rayleigh = 0.0;  // smallest Rayleigh time
  double hertz = 0.0;     // smallest t_c / 10
  double impact_speed = 0.0;
  std::string limiting;   // which species/pair sets the limit
};

StableTimeStep stable_time_step(const ParticleState &particles,
                                const std::vector<Material> &species_materials,
                                const std::vector<std::string> &species_names,
                                const ContactTable &table, std::size_t n_walls, double impact_speed,
                                const std::vector<char> *excluded = nullptr);

// `excluded` (one flag per species, optional): those species and every contact they take part
// in are left out — the limit of the rest, e.g. the carriers' own when the toner is subcycled.

// The step to use: automatic (time_step = 0) or the user's, refused if above the limit.
double choose_time_step(const DemSettings &settings, const StableTimeStep &limit);

} // namespace magbrush::dem
