// Held forces (dem/force_terms/held_forces.h): evaluated again exactly when a particle or the
// source has moved the hold distance, held bit for bit in between, following re-sorted
// particles, evaluated afresh after an exchange, restored from a checkpoint; and, in the
// engine, a harmonic oscillator driven by a held force converges to the exact solution at first
// order in the hold distance.
#include "dem/force_terms/held_forces.h"

#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"

#include "tests/dem/dem_test_scenes.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

// A slowly varying force with a known value: F = −k (x − x_c(t)), the centre x_c = v_c t
// moving along x; torque τz = c_τ x. Counts its evaluations.
class SpringToMovingCentre : public ForceTerm
{
public:
  SpringToMovingCentre(double k, double centre_speed, long *evaluations, double torque_per_x = 1.0)
    : k_(k), v_(centre_speed), c_(torque_per_x), evaluations_(evaluations)
  {}
  const char *name() const override { return "spring"; }
  void add_forces(const ParticleState &s, ForceBuffers &f, double t) override
  {
    ++*evaluations_;
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      f.fx[i] += -k_ * (s.x[i] - v_ * t);
      f.fy[i] += -k_ * s.y[i];
      f.fz[i] += -k_ * s.z[i];
      f.tz[i] += c_ * s.x[i];
    }
  }

private:
  double k_, v_, c_;
  long *evaluations_;
};

// The same force, declared as acting on each particle alone (held per particle); counts the
// particle-evaluations.
class SpringPerParticle : public SpringToMovingCentre
{
public:
  SpringPerParticle(double k, long *evaluations) : SpringToMovingCentre(k, 0.0, &calls_), k_(k), evaluations_(evaluations) {}
  bool acts_on_each_particle_alone() const override { return true; }
  void add_forces_of(const ParticleState &s, ForceBuffers &f, double, const std::vector<std::uint32_t> &which) override
  {
    for (const std::uint32_t i : which)
    {
      ++*evaluations_;
      f.fx[i] += -k_ * s.x[i];
    }
  }

private:
  long calls_ = 0;
  double k_;
  long *evaluations_;
};

ParticleState three_particles()
{
  ParticleState s;
  s.add({1e-6, 0.0, 0.0}, 1e-6, 1000.0, 0, 0.0);
  s.add({2e-6, 1e-6, 0.0}, 1e-6, 1000.0, 0, 0.0);
  s.add({3e-6, 0.0, 1e-6}, 1e-6, 1000.0, 0, 0.0);
  return s;
}

ForceBuffers forces_of(HeldForces &held, const ParticleState &s, double t)
{
  ForceBuffers f;
  f.resize(s.size());
  held.add_forces(s, f, t);
  return f;
}

constexpr double d = 10e-9; // the hold distance

} // namespace

TEST(HeldForces, ZeroHoldDistanceIsTheTermItself)
{
  long n = 0;
  auto term = std::make_unique<SpringToMovingCentre>(1.0, 0.0, &n);
  const ForceTerm *raw = term.get();
  EXPECT_EQ(held_for(std::move(term), 0.0, {0, 0, 0}).get(), raw);
}

TEST(HeldForces, EvaluatedAgainExactlyWhenAParticleMovedTheHoldDistance)
{
  long n = 0;
  HeldForces held(std::make_unique<SpringToMovingCentre>(2.0, 0.0, &n), d, {0, 0, 0});
  ParticleState s = three_particles();
  const ForceBuffers f0 = forces_of(held, s, 0.0);
  EXPECT_EQ(n, 1);
  EXPECT_DOUBLE_EQ(f0.fx[1], -2.0 * 2e-6);

  // 0.99 d (diagonally): held, the old forces to the bit.
  s.y[1] += 0.99 * d / std::sqrt(2.0);
  s.z[1] += 0.99 * d / std::sqrt(2.0);
  const ForceBuffers f1 = forces_of(held, s, 1e-9);
  EXPECT_EQ(n, 1);
  EXPECT_EQ(f1.fy[1], f0.fy[1]);
  EXPECT_EQ(f1.tz[2], f0.tz[2]);

  // Past d from where it was evaluated (not from the last step): evaluated at the new place.
  s.x[2] += 1.001 * d;
  const ForceBuffers f2 = forces_of(held, s, 2e-9);
  EXPECT_EQ(n, 2);
  EXPECT_DOUBLE_EQ(f2.fx[2], -2.0 * s.x[2]);
  EXPECT_DOUBLE_EQ(f2.fy[1], -2.0 * s.y[1]);
  EXPECT_DOUBLE_EQ(f2.tz[2], s.x[2]);
  EXPECT_EQ(held.evaluations(), 2);
  EXPECT_EQ(held.calls(), 3);
}

TEST(HeldForces, CrossingAPeriodicBoundaryIsNoMove)
{
  long n = 0;
  const double L = 1e-4;
  HeldForces held(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &n), d, {0.0, 0.0, L});
  ParticleState s = three_particles();
  forces_of(held, s, 0.0);
  s.z[0] += L - 0.5 * d; // wrapped: moved by 0.5 d
  forces_of(held, s, 1e-9);
  EXPECT_EQ(n, 1);
  s.z[0] += 1.6 * d; // now 1.1 d from the evaluated place (min image)
  forces_of(held, s, 2e-9);
  EXPECT_EQ(n, 2);
}

TEST(HeldForces, AMovingSourceCountsAsAMove)
{
  long n = 0;
  const double v = 0.25; // the source's speed [m/s]
  HeldForces held(std::make_unique<SpringToMovingCentre>(1.0, v, &n), d, {0, 0, 0},
                  [v](double t) { return v * t; });
  const ParticleState s = three_particles(); // at rest
  forces_of(held, s, 0.0);
  forces_of(held, s, 0.99 * d / v);
  EXPECT_EQ(n, 1);
  const ForceBuffers f = forces_of(held, s, 1.01 * d / v);
  EXPECT_EQ(n, 2);
  EXPECT_DOUBLE_EQ(f.fx[0], -(s.x[0] - v * 1.01 * d / v));
}

// Measured in the frame turning with a sleeve about (cx, cy): particles carried rigidly by the
// turn (by far more than d) renew nothing, while the same turn measured in the lab renews at
// every step; a particle that moves over the turning frame is renewed when IT moved d there;
// the frame's own turn by max_turn evaluates everybody again.
TEST(HeldForces, ATurningFrameIgnoresTheRideAndSeesTheMovesOverIt)
{
  const double cx = 1e-3, cy = -2e-3, omega = 40.0; // [m], [rad/s]: the ride ~0.1 m/s at 2 mm
  RotatingFrame frame;
  frame.cx = cx, frame.cy = cy;
  frame.angle = [omega](double t) { return omega * t; };
  frame.max_turn = 1e-2;
  long in_frame = 0, in_lab = 0;
  HeldForces turning(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &in_frame), d, {0, 0, 1e-4}, {}, 0.0, frame);
  HeldForces lab(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &in_lab), d, {0, 0, 1e-4});
  // `base` turned about (cx, cy) by omega t: particles carried rigidly by the frame.
  auto turned_by = [&](const ParticleState &base, double t) {
    ParticleState s = base;
    const double c = std::cos(omega * t), sn = std::sin(omega * t);
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      const double px = base.x[i] - cx, py = base.y[i] - cy;
      s.x[i] = cx + c * px - sn * py;
      s.y[i] = cy + sn * px + c * py;
    }
    return s;
  };
  const ParticleState start = three_particles();
  auto carried = [&](double t) { return turned_by(start, t); };
  const double dt = 1e-6; // each step carries the particles ~9 d at 2.2 mm from the axis
  for (int k = 0; k < 10; ++k)
  {
    const ParticleState s = carried(k * dt);
    forces_of(turning, s, k * dt);
    forces_of(lab, s, k * dt);
  }
  EXPECT_EQ(in_frame, 1); // the first evaluation only
  EXPECT_EQ(in_lab, 10);

  // Particle 1 moves 1.1 d radially over the frame (and 0.9 d does not count).
  ParticleState s = carried(10 * dt);
  const double px = s.x[1] - cx, py = s.y[1] - cy, r = std::hypot(px, py);
  ParticleState near = s, far = s;
  near.x[1] += 0.9 * d * px / r, near.y[1] += 0.9 * d * py / r;
  far.x[1] += 1.1 * d * px / r, far.y[1] += 1.1 * d * py / r;
  forces_of(turning, near, 10 * dt);
  EXPECT_EQ(in_frame, 1);
  const ForceBuffers f = forces_of(turning, far, 10 * dt);
  EXPECT_EQ(in_frame, 2);
  EXPECT_DOUBLE_EQ(f.fx[1], -far.x[1]); // evaluated where it is now

  // The frame turns max_turn since that evaluation: everybody again, though nothing moved in it.
  const ParticleState moved_base = turned_by(far, -10 * dt); // where they now sit in the frame
  const double t_held = 10 * dt + 0.99 * frame.max_turn / omega, t_turned = 10 * dt + 1.01 * frame.max_turn / omega;
  forces_of(turning, turned_by(moved_base, t_held), t_held);
  EXPECT_EQ(in_frame, 2);
  forces_of(turning, turned_by(moved_base, t_turned), t_turned);
  EXPECT_EQ(in_frame, 3);
}

TEST(HeldForces, ATurningFrameIsRefusedWhereItCannotHold)
{
  long n = 0;
  RotatingFrame frame;
  frame.angle = [](double t) { return t; };
  // A term acting on each particle where it is in the lab (qE): no frame.
  EXPECT_THROW(HeldForces(std::make_unique<SpringPerParticle>(1.0, &n), d, {0, 0, 0}, {}, 0.0, frame),
               std::invalid_argument);
  // Periodic along x: a turn about z does not map the box onto itself.
  EXPECT_THROW(HeldForces(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &n), d, {1e-3, 0, 0}, {}, 0.0, frame),
               std::invalid_argument);
}

TEST(HeldForces, HeldForcesFollowReSortedParticlesAndAnExchangeEvaluatesAgain)
{
  long n = 0;
  HeldForces held(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &n), d, {0, 0, 0});
  ParticleState s = three_particles();
  const ForceBuffers before = forces_of(held, s, 0.0);
  const std::vector<std::int32_t> order{2, 0, 1};
  std::vector<double> scratch;
  permute_array(s.x, order, scratch);
  permute_array(s.y, order, scratch);
  permute_array(s.z, order, scratch);
  held.particles_reordered(order);
  const ForceBuffers after = forces_of(held, s, 1e-9);
  EXPECT_EQ(n, 1); // nobody moved: held
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_EQ(after.fx[k], before.fx[static_cast<std::size_t>(order[k])]);
    EXPECT_EQ(after.tz[k], before.tz[static_cast<std::size_t>(order[k])]);
  }
  held.particles_changed({0, 1, 2});
  forces_of(held, s, 2e-9);
  EXPECT_EQ(n, 2);
}

TEST(HeldForces, PerParticleOnlyTheMovedParticleIsEvaluatedAndStayersKeepTheirsInAnExchange)
{
  long n = 0;
  HeldForces held(std::make_unique<SpringPerParticle>(3.0, &n), d, {0, 0, 0});
  EXPECT_TRUE(held.per_particle());
  ParticleState s = three_particles();
  forces_of(held, s, 0.0);
  EXPECT_EQ(n, 3);
  s.x[0] += 0.5 * d;
  s.x[1] += 1.5 * d;
  const ForceBuffers f = forces_of(held, s, 1e-9);
  EXPECT_EQ(n, 4); // particle 1 alone
  EXPECT_EQ(f.fx[0], -3.0 * (s.x[0] - 0.5 * d));
  EXPECT_DOUBLE_EQ(f.fx[1], -3.0 * s.x[1]);
  // Particle 1 left, a newcomer took index 1 and particle 2 moved to index 2's place: only the
  // newcomer is evaluated; the stayers keep their held forces.
  s.x[1] = 7e-6;
  held.particles_changed({0, -1, 2});
  const ForceBuffers g = forces_of(held, s, 2e-9);
  EXPECT_EQ(n, 5);
  EXPECT_EQ(g.fx[0], f.fx[0]);
  EXPECT_DOUBLE_EQ(g.fx[1], -3.0 * 7e-6);
  EXPECT_EQ(g.fx[2], f.fx[2]);
  EXPECT_EQ(held.evaluations(), 5);
  EXPECT_EQ(held.calls(), 9); // particle-steps
}

TEST(HeldForces, ACheckpointRestoresTheHeldForces)
{
  long n1 = 0, n2 = 0;
  HeldForces a(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &n1), d, {0, 0, 0});
  ParticleState s = three_particles();
  forces_of(a, s, 0.0);
  s.x[0] += 0.5 * d;
  const std::string path = (magbrush::testing::test_temp_dir("held_forces") / "held.bin").string();
  {
    CheckpointWriter out(path);
    a.write_state(out);
    out.commit();
  }
  HeldForces b(std::make_unique<SpringToMovingCentre>(1.0, 0.0, &n2), d, {0, 0, 0});
  {
    CheckpointReader in(path);
    b.read_state(in);
  }
  const ForceBuffers fa = forces_of(a, s, 1e-9), fb = forces_of(b, s, 1e-9);
  EXPECT_EQ(n2, 0); // held from the checkpoint, not evaluated
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_EQ(fa.fx[k], fb.fx[k]);
  s.x[0] += 0.6 * d; // 1.1 d from the place of the checkpointed evaluation
  forces_of(b, s, 2e-9);
  EXPECT_EQ(n2, 1);
}

// A sphere on a spring F = −k x (the held term) released from rest at x = A: the exact motion
// is A cos(ωt). Held for a distance d, the force lags the motion by up to d, which acts like a
// negative damping of order k d: the amplitude after a few periods is off by O(d). The error
// must be small against A and halve with d (first order), and be zero at d = 0.
TEST(HeldForces, HeldSpringConvergesAtFirstOrderInTheHoldDistance)
{
  const double A = 1e-6, k = 1e-3, R = 5e-6, rho = 1000.0;
  const double mass = rho * 4.0 / 3.0 * M_PI * R * R * R;
  const double omega = std::sqrt(k / mass), periods = 3.0;
  auto amplitude_error = [&](double hold) {
    Case c = dem::testing::single_species_case(dem::testing::elastic_material("m", 1e6, 0.3, rho));
    c.dem.time_step = 2.0 * M_PI / omega / 20000.0;
    DemSystem sys(c);
    sys.particles().add({A, 0.0, 0.0}, R, rho, 0, 0.0);
    long n = 0;
    sys.add_force_term(held_for(std::make_unique<SpringToMovingCentre>(k, 0.0, &n, 0.0), hold, {0, 0, 0}));
    sys.initialize();
    const long steps = static_cast<long>(std::lround(periods * 20000.0));
    double worst = 0.0;
    for (long s = 0; s < steps; ++s)
    {
      sys.advance(1);
      const double t = (s + 1) * c.dem.time_step;
      worst = std::max(worst, std::abs(sys.particles().x[0] - A * std::cos(omega * t)));
    }
    return worst / A;
  };
  const double e0 = amplitude_error(0.0), e1 = amplitude_error(A / 50.0), e2 = amplitude_error(A / 100.0),
               e3 = amplitude_error(A / 200.0);
  std::printf("worst |x - A cos wt| / A over %.0f periods: exact %.3g, hold A/50 %.3g, A/100 %.3g, A/200 %.3g\n",
              periods, e0, e1, e2, e3);
  EXPECT_LT(e0, 1e-5);     // the integrator alone (20,000 steps per period)
  EXPECT_LT(e2, 0.1);      // held for 1 % of the amplitude
  EXPECT_GT(e3, 50.0 * e0); // the hold's error dominates
  // First order in d: the observed order over two halvings.
  const double order = std::log2(e1 / e3) / 2.0;
  EXPECT_NEAR(order, 1.0, 0.2);
}
