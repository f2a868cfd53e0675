// Populations and insertion: draws each population's diameters (normal, mean ± std,
// truncated to positive values) until its count, mass or toner concentration is reached,
// then places the spheres without overlap at random in the population's region (a box, or a
// layer on the sleeve), largest first, by random sequential addition — or, for toner given
// by a concentration with `attached: true`, touching the carriers' surfaces at random points,
// each carrier carrying the concentration times its own mass, as developer carries its toner.
// The engine then lets them settle (DemSettings::settle_time).
#pragma once

#include "dem/neighbour_list.h"
#include "dem/particle_state.h"
#include "dem/wall_contacts.h"

#include "case/case_model.h"

#include <random>
#include <vector>

namespace magbrush::dem {

// Diameters of one population [m]. `carrier_mass` is the total mass of the carrier
// populations drawn before it (for a toner concentration).
std::vector<double> draw_diameters(const Case &c, const Population &p, double carrier_mass,
                                   std::mt19937_64 &rng);

// A random point (uniform over the sphere) at distance (rc + rt)(1 + 1e-9) from `centre`: a
// sphere of radius rt there touches the sphere (centre, rc) without overlapping it. Toner
// attached to a carrier, at insertion and by the inflow, is placed so.
Vector3 touching_point(const Vector3 &centre, double rc, double rt, std::mt19937_64 &rng);

// Fills `particles` with every population of the case, species = population index.
void insert_populations(const Case &c, const DemWalls &walls, const PeriodicBox &box,
                        ParticleState &particles);

} // namespace magbrush::dem
