// Inflow and outflow as the engine's particle exchange (see particle_flow.h).
#include "dem/particle_flow.h"

#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

ParticleFlow::ParticleFlow(const Case &c, const DemSystem &system) : system_(system), interval_(c.flow.interval)
{
  if (c.flow.inflow())
    source_ = std::make_unique<ParticleSource>(c, system.walls(), system.box());
  if (c.flow.outflow())
    sink_ = std::make_unique<ParticleSink>(c);
  if (carried_toner_population(c) >= 0)
    release_ = std::make_unique<CarriedTonerRelease>(c, system.walls(), system.box());
}

long ParticleFlow::interval_steps() const
{
  const double dt = system_.time_step();
  return dt > 0.0 ? std::max(1L, std::lround(interval_ / dt)) : 1L;
}

void ParticleFlow::plan(ParticleState &state, double t, std::vector<std::int32_t> &leave, ParticleState &enter)
{
  if (sink_)
    sink_->select(state, leave);
  if (source_)
  {
    // A finite sump gets back what leaves (before it feeds, so that it can feed it again);
    // the toner a carrier carries goes back as toner.
    for (std::int32_t i : leave)
    {
      const std::size_t k = static_cast<std::size_t>(i);
      source_->return_to_sump(state.species[k], state.mass[k] - state.carried_mass[k]);
      if (release_ && state.carried_count[k] > 0)
        source_->return_to_sump(release_->species(), state.carried_mass[k]);
    }
    source_->create(state, t, enter);
  }
  if (release_)
  {
    leaving_.assign(state.size(), 0);
    for (std::int32_t i : leave)
      leaving_[static_cast<std::size_t>(i)] = 1;
    release_->release(state, t, leaving_, enter);
    release_->recapture(state, leaving_, leave);
  }
}

void ParticleFlow::smallest_particles(ParticleState &out) const
{
  if (source_)
    source_->smallest_particles(out);
  if (release_)
    release_->smallest_particles(out);
}

void ParticleFlow::initial_particles(const ParticleState &present, ParticleState &add)
{
  if (source_)
    source_->prefill(present, add);
}

void ParticleFlow::write_state(CheckpointWriter &out) const
{
  if (source_)
    source_->write_state(out);
  if (sink_)
    sink_->write_state(out);
  if (release_)
    release_->write_state(out);
}

void ParticleFlow::read_state(CheckpointReader &in)
{
  if (source_)
    source_->read_state(in);
  if (sink_)
    sink_->read_state(in);
  if (release_)
    release_->read_state(in);
}

} // namespace magbrush::dem
