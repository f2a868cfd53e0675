// Particles entering and leaving a scene: the interface through which the engine asks, at
// fixed steps, which particles leave and which enter (dem/particle_flow.h implements it for
// the case's inflow and outflow; tests plug in their own).
//
// When: during every step k ≥ 1 with k a multiple of interval_steps(), after the drift and
// before any force of the step is computed. The positions are then x(t_k), the velocities
// v(t_k − dt/2). The engine removes the leaving particles, appends the entering ones (new
// ids, never reused), rebuilds the neighbour list carrying the history of every surviving
// contact, and tells every force term (ForceTerm::particles_changed); the step then computes
// all forces on the new set, so an entering particle's first force is that of its own
// position, and no surviving particle feels one that has left. An entering particle's
// velocity is taken as its v(t_k − dt/2): the step's final half kick completes it.
//
// The decision depends on the step number and the state only, never on the thread count,
// and whatever it remembers between exchanges (counters, a random stream, mass owed) goes
// into the checkpoint through write_state/read_state: a restarted run continues bit for bit.
#pragma once

#include "dem/particle_state.h"

#include <cstdint>
#include <vector>

namespace magbrush::dem {

class CheckpointWriter;
class CheckpointReader;

class ParticleExchange
{
public:
  virtual ~ParticleExchange() = default;
  virtual const char *name() const = 0;
  // Steps between exchanges (≥ 1).
  virtual long interval_steps() const = 0;
  // At time t (step k): appends to `leave` the indices of the particles that leave (any
  // order, each once) and to `enter` the particles that enter (their id is ignored: the
  // engine names them). Both come in empty. It may change the mass, moment of inertia, charge
  // and velocity of present particles (a carrier releasing the toner it carried or taking it
  // back, carried_toner.h), never their number or order, and only together with a particle
  // entering or leaving: the force terms learn of the change through
  // ForceTerm::particles_changed (a term that holds a particle's force keeps it until its
  // next renewal).
  virtual void plan(ParticleState &state, double t, std::vector<std::int32_t> &leave,
                    ParticleState &enter) = 0;
  // The smallest particles the exchange may ever bring in (one or a few per population), so
  // that the engine's stable time step covers them before they exist; may stay empty.
  virtual void smallest_particles(ParticleState & /*out*/) const {}
  // The particles the exchange puts into the scene before the run starts (after the case's
  // own insertion, `present`; e.g. the layer the sleeve brought before t = 0). They are part
  // of the initial state, not of what entered; may stay empty.
  virtual void initial_particles(const ParticleState & /*present*/, ParticleState & /*add*/) {}
  virtual void write_state(CheckpointWriter & /*out*/) const {}
  virtual void read_state(CheckpointReader & /*in*/) {}
};

} // namespace magbrush::dem
