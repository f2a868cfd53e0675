// Particles entering and leaving a roller scene, as the case asks (inflow.*, outflow.*): the
// engine's ParticleExchange (particle_exchange.h) built from the inflow (particle_source.h)
// and the outflow (particle_sink.h). Every inflow.interval (rounded to whole steps) the sink
// first names the particles in its region, then the source creates the developer owed for the
// arc the sleeve swept since the last exchange; then the carriers near the drum release the
// toner they carry (carried_toner.h). DemRun installs it when the case has an inflow, an
// outflow or carried toner; the flow report (dem/measurements/flow_report.h) reads its counts.
#pragma once

#include "dem/carried_toner.h"
#include "dem/particle_exchange.h"
#include "dem/particle_sink.h"
#include "dem/particle_source.h"

#include "case/case_model.h"

#include <memory>

namespace magbrush::dem {

class DemSystem;

class ParticleFlow : public ParticleExchange
{
public:
  // The source and sink the case asks for; `system` supplies the walls, the box and (once
  // initialised) the time step. Throws std::invalid_argument naming a key.
  ParticleFlow(const Case &c, const DemSystem &system);

  const char *name() const override { return "inflow/outflow"; }
  long interval_steps() const override;
  void plan(ParticleState &state, double t, std::vector<std::int32_t> &leave, ParticleState &enter) override;
  void smallest_particles(ParticleState &out) const override;
  void initial_particles(const ParticleState &present, ParticleState &add) override;
  void write_state(CheckpointWriter &out) const override;
  void read_state(CheckpointReader &in) override;

  const ParticleSource *source() const { return source_.get(); }
  const ParticleSink *sink() const { return sink_.get(); }
  const CarriedTonerRelease *release() const { return release_.get(); }

private:
  const DemSystem &system_;
  double interval_ = 0.0;
  std::unique_ptr<ParticleSource> source_;
  std::unique_ptr<ParticleSink> sink_;
  std::unique_ptr<CarriedTonerRelease> release_;
  std::vector<char> leaving_; // scratch: the particles the sink removes at this exchange
};

} // namespace magbrush::dem
