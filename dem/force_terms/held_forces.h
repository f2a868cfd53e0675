// Multiple time stepping for slow forces: a force term evaluated only when something it
// depends on has moved far enough to change it, and held in between.
//
// The electric forces of a development nip (qE in the nip field, Coulomb between the charges,
// their images in the drum and the sleeve) change over distances of micrometres — the toner's
// size, the strips' edges, the distance to the drum — while the step (0.5 ns, set by the
// toner's Hertz contact) moves a particle by a nanometre or less. Evaluated at every step they
// cost 20× the contacts (kweon_development: 93 % of the step, docs/development.md). Held until
// a particle or the field's source has moved `hold_distance`, they are evaluated tens of times
// less often, at a force error that grows linearly with that distance (measured against the
// exact forces along the same trajectory by bench_held_electric_forces: docs/electrostatics.md).
//
// The rule is a distance, not a time, because a toner flying across the gap at 1 m/s and one
// resting on a carrier need very different intervals: the fastest particle decides. Distances
// are measured with the minimum image along the periodic axes, so crossing the box is no move.
// A source that moves by itself (the latent image turns with the drum: `source_travel(t)`,
// the distance it has travelled by time t) counts as a move too.
//
// Two ways to hold. A term whose force on a particle depends on that particle alone (qE, a
// charge's own images: ForceTerm::acts_on_each_particle_alone) is held PER PARTICLE: each
// particle is evaluated again when IT (or the source) has moved d since its own last
// evaluation, so a few fast toner do not make the resting thousands pay. Any other term (Coulomb
// between the charges) is held as a WHOLE: evaluated for everybody when the fastest particle has
// moved d. A whole term that can renew what a few moved particles change
// (ForceTerm::renew_moved: Coulomb) is asked to do that instead when at most `renew_share` of
// the particles moved d (each is then renewed when IT moved d since its last renewal, like a
// per-particle term, and everybody when more moved); the bound on each pair is unchanged.
//
// A FRAME FOR THE MOVES (whole terms only). Whether a pair's distance changed by more than the
// bound does not depend on the frame the moves are measured in, as long as both members are
// measured in the same one: |Δ(r_i − r_j)| ≤ |u_i| + |u_j| with u in any one frame. A term whose
// pair forces depend on the pairs' separations alone (Coulomb between the charges) can therefore
// measure the moves in the frame that turns with the sleeve (`RotatingFrame`): the developer that
// rides the sleeve changes no separation and triggers nothing, however far it rides, and what
// moves over the sleeve (free toner, the layer on the drum) is renewed as before. A rigid turn by
// φ turns the forces with it, which the held ones do not follow: the term is evaluated again
// when the frame has turned `max_turn` since its last whole evaluation (an error of at most
// max_turn × |F| in direction). Terms that depend on where a particle is in the lab (qE, the
// images of each charge in the conductors) are held per particle in the lab frame.
//
// The held forces (and torques) are the inner term's, so held at distance 0 they are its
// forces at every step, bit for bit. Particles re-sorted: the held forces and the reference
// positions follow them. Particles entering or leaving: evaluated again at the next step.
// Checkpoint: the inner term's state, then the held forces, the reference positions and the
// time of the last evaluation, so a restarted run continues bit for bit.
#pragma once

#include "dem/force_term.h"

#include <array>
#include <functional>
#include <memory>
#include <optional>

namespace magbrush::dem {

// The frame turning with a cylinder (the sleeve) about the z axis through (cx, cy): `angle(t)`
// is how far it has turned by time t.
struct RotatingFrame
{
  double cx = 0.0, cy = 0.0;
  std::function<double(double)> angle;
  double max_turn = 1e-3; // [rad] evaluated again after this turn (the held forces' direction)
};

class HeldForces : public ForceTerm
{
public:
  // `box`: the periodic lengths (0 = not periodic along that axis).
  // `renew_share`: a whole term renews the moved particles alone (ForceTerm::renew_moved) when
  // they are at most this share of all (0: never; everybody whenever one moved d).
  // `frame`: a whole term's moves measured in this frame instead of the lab's (refused for a
  // term held per particle, and where x or y is periodic).
  HeldForces(std::unique_ptr<ForceTerm> inner, double hold_distance, const std::array<double, 3> &box,
             std::function<double(double)> source_travel = {}, double renew_share = 0.0,
             std::optional<RotatingFrame> frame = std::nullopt);

  const char *name() const override { return inner_->name(); }
  void add_forces(const ParticleState &state, ForceBuffers &forces, double t) override;
  void particles_reordered(const std::vector<std::int32_t> &order) override;
  void particles_changed(const std::vector<std::int32_t> &origin) override;
  void write_state(CheckpointWriter &out) const override;
  void read_state(CheckpointReader &in) override;
  std::string cost_note() const override;

  const ForceTerm &inner() const { return *inner_; }
  bool per_particle() const { return per_particle_; }
  // Evaluations of the inner term so far (per particle: particle-evaluations), steps served
  // (per particle: particle-steps).
  long evaluations() const { return evaluations_; }
  long calls() const { return calls_; }
  // Whole: steps on which the moved particles alone were renewed, and how many in all.
  long renewals() const { return renewals_; }
  long renewed() const { return renewed_; }

private:
  std::unique_ptr<ForceTerm> inner_;
  double hold_distance_;
  std::array<double, 3> box_;
  std::function<double(double)> source_travel_;
  double renew_share_ = 0.0;
  std::optional<RotatingFrame> frame_;
  double cos_ = 1.0, sin_ = 0.0; // the frame's turn at the current step: (x, y) → R(−angle) (x − c, y − c)

  bool per_particle_;
  bool valid_ = false;     // whole: the held forces belong to the particles present
  double evaluated_at_ = 0.0; // whole: the time of the last evaluation
  ForceBuffers held_;
  std::vector<double> x0_, y0_, z0_; // positions at the last evaluation (in the frame, when there is one)
  std::vector<double> u0_;           // per particle: the source's travel at its last evaluation
  std::vector<std::uint8_t> stale_;  // per particle: must be evaluated (entered, or never)
  std::vector<std::uint32_t> which_; // per particle: those evaluated this step
  std::vector<double> scratch_;
  long evaluations_ = 0, calls_ = 0;
  long renewals_ = 0, renewed_ = 0; // since this run (re)started: not in the checkpoint

  // The squared moves since the last evaluation of particles [begin, end) into out[0 ..),
  // scanned in blocks of move_block (a buffer on the stack: nothing allocated per step).
  static constexpr std::size_t move_block = 256;
  void squared_moves(const ParticleState &state, std::size_t begin, std::size_t end, double *out) const;
  // Particle i's position in the frame of the moves (the lab's without a frame), for x0_ .. z0_.
  void set_reference(const ParticleState &state, std::size_t i);
  void turn_frame(double t); // cos_, sin_ at time t
  bool must_evaluate(const ParticleState &state, double t) const;
  bool stale_as_a_whole(const ParticleState &state, double t) const;
  void hold_as_a_whole(const ParticleState &state, double t);
  void evaluate(const ParticleState &state, double t);
  void evaluate_moved_particles(const ParticleState &state, double t);
};

// `term` held for `hold_distance` (> 0), or `term` itself (0: evaluated at every step).
std::unique_ptr<ForceTerm> held_for(std::unique_ptr<ForceTerm> term, double hold_distance,
                                    const std::array<double, 3> &box,
                                    std::function<double(double)> source_travel = {}, double renew_share = 0.0,
                                    std::optional<RotatingFrame> frame = std::nullopt);

} // namespace magbrush::dem
