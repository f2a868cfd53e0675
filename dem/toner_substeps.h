// Multiple time stepping: the toner in substeps of the carriers' step (dem.toner_substeps).
//
// Why. The stable step of a contact scales with the particle's size (Hertz: t_c ∝ R for one
// material), so a 7 µm toner needs a step ~6× shorter than a 35 µm carrier. In a development
// nip the toner is a minority of the particles (carried toner rides its carrier as mass and
// charge until it nears the drum), yet with one step for all every carrier, with its
// magnetics and electrics, pays the toner's step. Here the step dt is the carriers' and the
// toner advances in k substeps of δ = dt / k.
//
// What is fast and what is slow. The subcycled ("fast") particles are the toner; a fast pair
// is a particle pair with a fast member, a fast wall contact one of a fast particle. Only the
// contacts (Hertz–Mindlin, damping, rolling friction, van der Waals adhesion) are fast: they
// are what sets the toner's stable step. Every other force on the toner (gravity, drag, the
// applied field qE, Coulomb, the images) varies on the scale of its motion through the
// fields, micrometres, and is evaluated once per step, with the carriers' forces, and held
// over the substeps.
//
// One step from t to t + dt (velocity Verlet for both, nested; dem_advance.cpp runs it):
//   1. every slow particle: kick by dt/2 with its force at t, drift by dt (its velocity is
//      then constant over the step: its position at t + s is x(t + dt) − (dt − s) v);
//   2. (the neighbour list is rebuilt if some particle may have drifted half the skin by
//      t + dt: for a fast particle, its drift at t plus dt (2|v| + 1 m/s), a bound on its
//      motion over the step);
//   3. the substeps j = 1 … k: the fast particles kick by δ/2 (held force + their fast force),
//      drift by δ, their fast pairs and wall contacts are evaluated with the slow partners
//      placed where their drift has them at t + j δ, and they kick by δ/2 again; each slow
//      partner sums the fast pairs' reaction over the substeps;
//   4. the slow forces at t + dt (the slow pairs, the slow particles' walls, every force term
//      on every particle); a slow particle adds the average of its fast pairs' reaction over
//      the substeps (its impulse / dt), and kicks by dt/2.
// The reaction reaches the slow partner as the same impulse the fast member received (to the
// order of the trapezoidal sums), so the momentum exchanged is conserved; the carrier is
// ~125× heavier than a toner, so a toner contact changes its velocity by ~1 % of what it does
// to the toner's within a step. The slow partner's position in a substep is exactly where its
// own drift puts it (a straight line), so the list's guarantee still holds: a point on the
// segment between two positions within half a skin of the build position is within half a
// skin too.
//
// The substeps share their work among the team's threads: the fast pairs in blocks (each pair
// writes only its own slot), then each particle sums its own pairs in pair order and adds its
// walls — the order of one thread's pass, so the bits are the same on any number of threads.
// k = 1 is the engine without substeps, bit for bit (no mask, no extra pass).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace magbrush::dem {

struct TonerSubsteps
{
  int substeps = 1;               // k (1: off)
  double substep = 0.0;           // δ = dt / k [s]
  std::vector<char> species_fast; // per species: subcycled (the toner populations)
  double carrier_limit = 0.0;     // the step allowed by the scene without the toner [s]
  std::string carrier_limiting;   // what sets it

  // Refreshed at every build of the neighbour list (indices in the current particle order):
  std::vector<std::int32_t> skip;    // per listed pair: 1 for a fast pair (the main pass's mask)
  std::vector<std::int32_t> pair;    // the fast pairs' indices in the list, ascending
  std::vector<std::int32_t> owner, partner, image; // their members and image codes (compact)
  std::vector<std::int32_t> movers;  // the fast particles, ascending
  std::vector<std::int32_t> dragged; // the slow particles of fast pairs, ascending
  std::vector<char> mark;            // per particle (scratch of the build)
  // Each mover's and each dragged particle's fast pairs (CSR over S.movers and S.dragged), in
  // ascending pair order: 2 q for the pair's owner, 2 q + 1 for its partner. A particle sums its
  // pairs' forces in this order on any number of threads, the order of a serial pass over the pairs.
  std::vector<std::int32_t> mover_begin, mover_pairs, dragged_begin, dragged_pairs;
  std::vector<std::int32_t> member_of; // per particle (scratch of the build): its mover or dragged index

  // Scratch of the substeps (sized at the build: no allocation inside a step).
  std::vector<double> hx, hy, hz;                  // the fast pairs' history
  std::vector<std::int32_t> touching;              // and touching flags
  std::vector<double> fx, fy, fz, tix, tiy, tiz, tjx, tjy, tjz; // per fast pair, one substep
  std::vector<double> end_x, end_y, end_z;         // dragged: positions at t + dt
  std::vector<double> start_x, start_y, start_z;   // movers: positions at t

  bool on() const { return substeps > 1; }
  bool fast(std::int32_t species) const { return on() && species_fast[static_cast<std::size_t>(species)] != 0; }
};

} // namespace magbrush::dem
