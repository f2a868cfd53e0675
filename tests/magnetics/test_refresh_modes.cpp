// When held magnetic forces are stale, and the local refresh that renews them around the beads
// that moved (magnetic_settings.h StalenessMode, InducedDipoles::check_staleness /
// refresh_locally), against constructed cases with an exact answer:
//
//  * a rigidly translated brush in a uniform field has exactly the forces it had: the
//    relative criterion triggers nothing, the absolute one does, and the held forces equal a
//    fresh evaluation at the new positions (to the solver's round-off);
//  * a single bead pulled away from its chain triggers the relative criterion;
//  * a periodic wrap is no move;
//  * the local refresh equals a full evaluation when its region covers every bead and every
//    changed dipole is followed (local_dipole_change = 0): same pair tensors, same dipoles to
//    the solver tolerance, same forces;
//  * with the defaults on a brush, its error against a full evaluation is far below the
//    held-force error it removes; Newton's third law stays exact, and 1 and 2 threads give the
//    same bits;
//  * no applied field: nothing solved, no force; a ramped field rescales the held state
//    exactly (p ∝ B, F ∝ B²).
#include "tests/magnetics/brush_configuration.h"
#include "magnetics/induced_dipoles.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace magbrush::magnetics;

namespace {

constexpr double a = 30e-6, mu_r = 3.9, B0 = 0.13;

struct Beads
{
  std::vector<double> x, y, z, r, mu;
  std::vector<double> fx, fy, fz;
  void add(double X, double Y, double Z, double R)
  {
    x.push_back(X); y.push_back(Y); z.push_back(Z);
    r.push_back(R); mu.push_back(mu_r);
  }
  std::size_t size() const { return x.size(); }
  BeadArrays arrays() const { return {x.size(), x.data(), y.data(), z.data(), r.data(), mu.data(), nullptr}; }
  ForceArrays forces()
  {
    fx.assign(size(), 0.0); fy.assign(size(), 0.0); fz.assign(size(), 0.0);
    return {fx.data(), fy.data(), fz.data()};
  }
};

// Chains of touching beads (radius a ± 10 %) standing along ŷ on a 4 × 4 grid, 60 beads, open box.
Beads small_brush()
{
  Beads b;
  for (int cx = 0; cx < 4; ++cx)
    for (int cz = 0; cz < 4; ++cz)
    {
      double y = 0.0, r_prev = 0.0;
      const int height = 2 + (cx * 4 + cz) % 3;
      for (int k = 0; k < height + 1; ++k)
      {
        const double r = a * (1.0 + 0.1 * std::sin(1.7 * (cx + 3 * cz + 5 * k)));
        y += r_prev + r + 1e-3 * a;
        b.add(cx * 5.0 * a + 0.3 * a * std::sin(k + cz), y, cz * 5.0 * a + 0.2 * a * std::cos(k + cx), r);
        r_prev = r;
      }
    }
  return b;
}

// The standing brush of the benchmarks (periodic along x and z), as bead arrays.
Beads standing_brush(std::size_t chains, double box, unsigned seed)
{
  const auto brush = bench::make_brush(chains, box, a, 3e-6, 8, 16, mu_r, seed);
  Beads b;
  for (std::size_t k = 0; k < brush.size(); ++k)
    b.add(brush.x[k], brush.y[k], brush.z[k], brush.radius[k]);
  return b;
}

MagneticSettings exact_settings(StalenessMode mode)
{
  MagneticSettings s;
  s.model = DipoleModel::corrected;
  s.far_field = FarField::none;
  s.cutoff_diameters = 8.0;
  s.tolerance = 1e-13;
  s.max_sweeps = 500;
  s.refresh_interval = 5e-6;
  s.staleness_fraction = 0.05;
  s.staleness_mode = mode;
  return s;
}

// RMS over beads of |F − F_ref| and the largest bead error, both relative to RMS |F_ref|.
struct ForceError
{
  double rms = 0.0, max = 0.0;
};
ForceError force_error(const Beads &b, const std::vector<double> &fx, const std::vector<double> &fy,
                       const std::vector<double> &fz)
{
  double e2 = 0.0, f2 = 0.0, emax2 = 0.0;
  for (std::size_t k = 0; k < b.size(); ++k)
  {
    const double e = std::pow(b.fx[k] - fx[k], 2) + std::pow(b.fy[k] - fy[k], 2) + std::pow(b.fz[k] - fz[k], 2);
    e2 += e;
    emax2 = std::max(emax2, e);
    f2 += fx[k] * fx[k] + fy[k] * fy[k] + fz[k] * fz[k];
  }
  const double n = static_cast<double>(b.size());
  return {std::sqrt(e2 / f2), std::sqrt(emax2 / (f2 / n))};
}

// Every bead of `b` displaced by up to `fraction` of its radius along each axis (a fixed,
// irregular pattern).
Beads shaken_by(const Beads &b, double fraction)
{
  Beads out = b;
  for (std::size_t k = 0; k < out.size(); ++k)
  {
    const double f = fraction * out.r[k];
    out.x[k] += f * std::sin(1.3 * k + 0.2);
    out.y[k] += f * std::cos(2.1 * k + 0.7);
    out.z[k] += f * std::sin(0.7 * k + 1.9);
  }
  return out;
}

// Forces of a fresh, cold evaluation of `b` with settings `s` (box `box`), field along ŷ.
void fresh_forces(const Beads &b, const MagneticSettings &s, const std::array<double, 3> &box,
                  std::vector<double> &fx, std::vector<double> &fy, std::vector<double> &fz,
                  double field = B0)
{
  Beads copy = b;
  InducedDipoles fresh(s, box);
  fresh.compute(copy.arrays(), uniform_field(0, field, 0), 0.0, copy.forces());
  fx = copy.fx;
  fy = copy.fy;
  fz = copy.fz;
}

// The watched pairs of a ~900-bead periodic standing brush, as a full evaluation leaves them:
// the near list within 8 radii + a 0.3-diameter skin, its tensors, every bead's reference.
struct WatchedBrush
{
  static constexpr double L = 0.9e-3;
  Beads beads = standing_brush(75, L, 11);
  NearPairs near;
  StalenessTracker tracker;
  const double skin = 0.3 * 2.0 * a;
  explicit WatchedBrush(const MagneticSettings &s) : tracker(s, {L, 0.0, L})
  {
    near.list().build(beads.size(), beads.x.data(), beads.y.data(), beads.z.data(), {L, 0.0, L}, 8.0 * a + skin);
    evaluate();
  }
  // Every pair's tensor and every bead's reference renewed at the current positions.
  void evaluate()
  {
    near.evaluate_tensors(beads.arrays(), 8.0 * a);
    tracker.evaluated_all(beads.arrays(), 0.0);
    tracker.watch_close_pairs(beads.arrays(), near, skin);
  }
};

} // namespace

TEST(RefreshModes, RigidTranslationTriggersOnlyTheAbsoluteCriterion)
{
  Beads beads = small_brush();
  InducedDipoles relative(exact_settings(StalenessMode::relative));
  InducedDipoles absolute(exact_settings(StalenessMode::absolute));
  relative.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
  absolute.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
  // Translate the whole brush by 0.2 radii (4 × the staleness fraction, below the relative
  // mode's absolute bound of 5 ×): no pair vector changes.
  for (std::size_t k = 0; k < beads.size(); ++k)
  {
    beads.x[k] += 0.12 * a;
    beads.y[k] -= 0.1 * a;
    beads.z[k] += 0.12 * a;
  }
  const StalenessCheck r = relative.check_staleness(beads.arrays(), 1e-6);
  const StalenessCheck s = absolute.check_staleness(beads.arrays(), 1e-6);
  EXPECT_EQ(r.reason, RefreshReason::none);
  EXPECT_EQ(r.stale_pairs, 0u);
  EXPECT_EQ(s.reason, RefreshReason::moved);
  EXPECT_EQ(s.stale_beads, beads.size());
  // The held forces are those of a fresh evaluation at the translated positions.
  std::vector<double> fx, fy, fz;
  fresh_forces(beads, exact_settings(StalenessMode::relative), {0, 0, 0}, fx, fy, fz);
  relative.add_held_forces(beads.forces());
  const ForceError e = force_error(beads, fx, fy, fz);
  std::printf("rigid translation by 0.2 radii: held vs fresh forces RMS %.2e, max %.2e\n", e.rms, e.max);
  EXPECT_LT(e.max, 1e-12);
  // Beyond 5 × the fraction the applied field may differ: the relative mode refreshes too.
  for (std::size_t k = 0; k < beads.size(); ++k)
    beads.x[k] += 0.1 * a;
  EXPECT_EQ(relative.check_staleness(beads.arrays(), 1e-6).reason, RefreshReason::moved);
}

TEST(RefreshModes, BeadPulledFromItsChainTriggersTheRelativeCriterion)
{
  Beads beads = small_brush();
  InducedDipoles relative(exact_settings(StalenessMode::relative));
  relative.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
  const std::size_t top = 2; // the top bead of the first chain (3 beads)
  const double ymax = beads.y[top];
  beads.y[top] += 0.04 * 0.9 * a; // 4 % of the smallest radius: within the limit
  EXPECT_EQ(relative.check_staleness(beads.arrays(), 1e-6).reason, RefreshReason::none);
  beads.y[top] = ymax + 0.06 * 1.1 * a; // 6 % of the largest radius: past it
  const StalenessCheck c = relative.check_staleness(beads.arrays(), 1e-6);
  EXPECT_EQ(c.reason, RefreshReason::moved);
  EXPECT_GE(c.stale_pairs, 1u);
  EXPECT_EQ(c.stale_beads, 0u); // no bead is past the absolute bound
  // The interval still rules: elapsed → refresh whatever moved.
  beads.y[top] = ymax;
  EXPECT_EQ(relative.check_staleness(beads.arrays(), 5e-6).reason, RefreshReason::interval);
}

TEST(RefreshModes, PeriodicWrapIsNoMove)
{
  const double L = 0.6e-3;
  Beads beads = standing_brush(20, L, 3);
  MagneticSettings s = exact_settings(StalenessMode::absolute);
  s.cutoff_diameters = 4.0;
  InducedDipoles magnetics(s, {L, 0.0, L});
  magnetics.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
  beads.x[5] += L;
  beads.z[9] -= L;
  EXPECT_EQ(magnetics.check_staleness(beads.arrays(), 1e-6).reason, RefreshReason::none);
  beads.x[5] += 0.06 * beads.r[5];
  EXPECT_EQ(magnetics.check_staleness(beads.arrays(), 1e-6).reason, RefreshReason::moved);
}

TEST(RefreshModes, LocalRefreshCoveringEveryBeadEqualsFullRefresh)
{
  for (const StalenessMode mode : {StalenessMode::local, StalenessMode::relative})
  {
    Beads beads = small_brush();
    MagneticSettings s = exact_settings(mode);
    s.cutoff_diameters = 20.0;     // every pair of the brush within the cutoff
    s.local_region_radius = 1e3;   // the region: every bead
    s.local_region_limit = 1.0;
    s.local_dipole_change = 0.0;   // follow every changed dipole
    InducedDipoles local(s);
    local.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
    // Pull two beads (one inside a chain, one at a tip) by 8 % of their radius.
    beads.x[1] += 0.08 * beads.r[1];
    beads.y[10] += 0.08 * beads.r[10];
    ASSERT_EQ(local.check_staleness(beads.arrays(), 1e-6).reason, RefreshReason::moved);
    MagneticStats st;
    ASSERT_TRUE(local.refresh_locally(beads.arrays(), uniform_field(0, B0, 0), 1e-6, st));
    EXPECT_EQ(st.local_region, beads.size());
    EXPECT_GE(st.local_moved, 2u);
    EXPECT_EQ(local.check_staleness(beads.arrays(), 1e-6).reason, RefreshReason::none);
    local.add_held_forces(beads.forces());
    std::vector<double> fx, fy, fz;
    fresh_forces(beads, s, {0, 0, 0}, fx, fy, fz);
    const ForceError e = force_error(beads, fx, fy, fz);
    std::printf("%s: local refresh covering every bead vs full: RMS %.2e, max %.2e (%d sweeps)\n",
                to_string(mode).c_str(), e.rms, e.max, st.sweeps);
    EXPECT_LT(e.max, 1e-10);
  }
}

TEST(RefreshModes, LocalRefreshOnABrushNewtonThreadsAndError)
{
  const double L = 0.9e-3;
  Beads start = standing_brush(75, L, 11); // ~900 beads: the parallel paths are taken
  for (const FarField far : {FarField::none, FarField::cell_multipole})
  {
    MagneticSettings s = exact_settings(StalenessMode::relative);
    s.far_field = far;
    s.cutoff_diameters = 4.0;
    s.tolerance = 1e-8;
    std::vector<double> forces[2][3];
    MagneticStats st;
    for (int threads : {1, 2})
    {
      omp_set_num_threads(threads);
      Beads beads = start;
      InducedDipoles magnetics(s, {L, 0.0, L});
      magnetics.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
      // Three beads pulled sideways by 7 % of their radius.
      for (std::size_t k : {7u, 150u, 400u})
        beads.z[k] += 0.07 * beads.r[k];
      ASSERT_TRUE(magnetics.refresh_locally(beads.arrays(), uniform_field(0, B0, 0), 1e-6, st));
      magnetics.add_held_forces(beads.forces());
      forces[threads - 1][0] = beads.fx;
      forces[threads - 1][1] = beads.fy;
      forces[threads - 1][2] = beads.fz;
      if (threads == 2)
      {
        // Newton's third law: exact per pair with a cutoff (uniform field: no applied force).
        double sum[3] = {0, 0, 0}, total = 0.0;
        for (std::size_t k = 0; k < beads.size(); ++k)
        {
          sum[0] += beads.fx[k];
          sum[1] += beads.fy[k];
          sum[2] += beads.fz[k];
          total += std::sqrt(beads.fx[k] * beads.fx[k] + beads.fy[k] * beads.fy[k] + beads.fz[k] * beads.fz[k]);
        }
        const double momentum = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]) / total;
        // Against a fresh full evaluation, and the error of simply holding the old forces.
        std::vector<double> fx, fy, fz;
        fresh_forces(beads, s, {L, 0.0, L}, fx, fy, fz);
        const ForceError local = force_error(beads, fx, fy, fz);
        Beads held = beads;
        InducedDipoles old(s, {L, 0.0, L});
        old.compute(start.arrays(), uniform_field(0, B0, 0), 0.0, held.forces());
        const ForceError holding = force_error(held, fx, fy, fz);
        std::printf("%s, %zu beads, 3 moved by 0.07 r: region %zu, pairs %zu, gathered %zu; "
                    "|ΣF|/Σ|F| = %.1e; vs full: local RMS %.2e max %.2e, held RMS %.2e max %.2e\n",
                    to_string(far).c_str(), beads.size(), st.local_region, st.local_pairs,
                    st.local_gathered, momentum, local.rms, local.max, holding.rms, holding.max);
        if (far == FarField::none)
        {
          EXPECT_LT(momentum, 1e-13);
        }
        EXPECT_LT(local.rms, 1e-3);
        EXPECT_LT(local.max, 0.1 * holding.max);
      }
    }
    omp_set_num_threads(2);
    for (int d = 0; d < 3; ++d)
      EXPECT_EQ(forces[0][d], forces[1][d]) << "1 vs 2 threads, " << to_string(far);
  }
}

TEST(RefreshModes, NoAppliedFieldSolvesNothing)
{
  Beads beads = small_brush();
  MagneticSettings s = exact_settings(StalenessMode::relative);
  InducedDipoles magnetics(s);
  const MagneticStats off = magnetics.compute(beads.arrays(), uniform_field(0, 0, 0), 0.0, beads.forces());
  EXPECT_TRUE(off.zero_field);
  EXPECT_EQ(off.sweeps, 0);
  for (std::size_t k = 0; k < beads.size(); ++k)
    EXPECT_EQ(beads.fx[k] * beads.fx[k] + beads.fy[k] * beads.fy[k] + beads.fz[k] * beads.fz[k], 0.0);
  // No local refresh from a field-free state; the next compute starts cold and is exact.
  beads.x[2] += 0.1 * a;
  MagneticStats st;
  EXPECT_FALSE(magnetics.refresh_locally(beads.arrays(), uniform_field(0, B0, 0), 1e-6, st));
  const MagneticStats on = magnetics.compute(beads.arrays(), uniform_field(0, B0, 0), 1e-6, beads.forces());
  EXPECT_FALSE(on.zero_field);
  std::vector<double> fx, fy, fz;
  fresh_forces(beads, s, {0, 0, 0}, fx, fy, fz);
  EXPECT_LT(force_error(beads, fx, fy, fz).max, 1e-12);
}

TEST(RefreshModes, RampRescalesTheHeldStateExactly)
{
  Beads beads = small_brush();
  MagneticSettings s = exact_settings(StalenessMode::relative);
  InducedDipoles magnetics(s);
  magnetics.compute(beads.arrays(), uniform_field(0, 0.4 * B0, 0), 0.0, beads.forces());
  ASSERT_TRUE(magnetics.linear());
  magnetics.scale_applied_field(2.5); // 0.4 B0 → B0
  magnetics.add_held_forces(beads.forces());
  std::vector<double> fx, fy, fz;
  fresh_forces(beads, s, {0, 0, 0}, fx, fy, fz, B0);
  const ForceError e = force_error(beads, fx, fy, fz);
  std::printf("held state rescaled 0.4 B0 → B0 vs fresh at B0: max %.2e\n", e.max);
  EXPECT_LT(e.max, 1e-12);
}

// The relative trigger's per-step pair check skips the pairs whose beads have not moved half
// the pair's limit (|Δr| ≤ |Δx_i| + |Δx_j|; and the whole pass while no bead has): it must
// flag exactly the pairs a plain pass over every watched pair flags — the guard for any
// faster version of the check. Beads of a ~900-bead brush moved by 0 … 8 % of their radius
// in a fixed pattern (many past half a limit, some pairs past it), three times over.
TEST(RefreshModes, StalePairCountEqualsAPassOverEveryWatchedPair)
{
  WatchedBrush w(exact_settings(StalenessMode::relative));
  Beads &beads = w.beads;
  StalenessTracker &tracker = w.tracker;
  for (int round = 0; round < 3; ++round)
  {
    for (std::size_t k = 0; k < beads.size(); ++k)
    {
      const double f = 0.08 * std::pow(std::sin(1.3 * k + round), 8); // mostly small, a few large
      beads.x[k] += f * beads.r[k] * std::cos(0.7 * k);
      beads.z[k] += f * beads.r[k] * std::sin(0.7 * k);
    }
    const StalenessCheck c = tracker.check(beads.arrays(), 1e-6, true);
    std::size_t every = 0;
    for (const StalenessTracker::ClosePair &p : tracker.close_pairs())
      every += StalenessTracker::drift2(beads.arrays(), p) > p.limit2;
    std::printf("round %d: %zu of %zu watched pairs stale\n", round, every, tracker.close_pairs().size());
    EXPECT_EQ(c.stale_pairs, every);
    EXPECT_GT(every, 0u);
    EXPECT_LT(every, tracker.close_pairs().size());
  }
}

// The same guard for the skip that matters in a flowing brush: the whole brush carried along
// (every bead soon past half its limit) while the pairs drift slowly apart, one small step at a
// time. After a pass over the pairs, the next one waits until twice the largest bead move
// since could have used up the margin the pass left; the count must still equal a plain pass
// at every step, and most steps must skip the pass.
TEST(RefreshModes, CarriedBrushSkipsThePairPassWithoutMissingAStalePair)
{
  MagneticSettings s = exact_settings(StalenessMode::relative);
  s.staleness_fraction = 0.2;
  WatchedBrush w(s);
  Beads &beads = w.beads;
  StalenessTracker &tracker = w.tracker;
  const int steps = 400;
  int refreshes = 0;
  for (int step = 1; step <= steps; ++step)
  {
    // Carried by 0.5 % of a radius per step along y (no wrap: y is open), and each bead
    // drifting on its own by up to 0.05 % of a radius per step in x and z.
    for (std::size_t k = 0; k < beads.size(); ++k)
    {
      beads.y[k] += 5e-3 * beads.r[k];
      beads.x[k] += 5e-4 * beads.r[k] * std::sin(1.7 * k);
      beads.z[k] += 5e-4 * beads.r[k] * std::cos(2.3 * k);
    }
    const StalenessCheck c = tracker.check(beads.arrays(), 1e-6, true);
    std::size_t every = 0;
    for (const StalenessTracker::ClosePair &p : tracker.close_pairs())
      every += StalenessTracker::drift2(beads.arrays(), p) > p.limit2;
    ASSERT_EQ(c.stale_pairs, every) << "step " << step;
    if (every == 0)
      continue;
    // A refresh: every pair's tensor and every bead's reference renewed (as a full
    // evaluation that keeps its lists does).
    ++refreshes;
    w.evaluate();
  }
  std::printf("carried brush: %zu pair passes in %d checks, %d refreshes for stale pairs\n",
              tracker.pair_passes(), steps, refreshes);
  EXPECT_GE(refreshes, 2) << "the drift must reach the limit more than once";
  // Passing over the pairs whenever some bead moved half its limit since its evaluation (the
  // skip before) passes at ~80 % of these checks.
  EXPECT_LT(tracker.pair_passes(), static_cast<std::size_t>(0.4 * steps));
}

// InducedDipoles::forces_of_dipoles: the forces of given dipoles at given positions, no solve.
// (1) At the positions they were solved at, the solved dipoles give the solve's forces. (2) After
// every bead of a periodic brush is shaken by up to 5 % of its radius, the held dipoles'
// forces at the new positions are much closer to a fresh solve than the held forces are:
// the forces change mostly with the geometry of the close pairs (a touching pair's force goes
// as 1/r⁴), the dipoles only through the neighbours' share of the local field.
TEST(RefreshModes, HeldDipolesAtTheNewPositionsBeatHeldForces)
{
  const double L = 0.9e-3;
  const std::array<double, 3> box = {L, 0.0, L};
  Beads beads = standing_brush(75, L, 11);
  MagneticSettings s = exact_settings(StalenessMode::relative);
  s.far_field = FarField::cell_multipole;
  s.tolerance = 1e-10;
  s.far_passes = 8; // (the solve's far field from its final dipoles, as the replay takes it)
  InducedDipoles solved(s, box);
  solved.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
  const std::vector<double> p = solved.dipoles();
  const Beads at_solve = beads;

  Beads same = beads;
  InducedDipoles replay(s, box);
  replay.forces_of_dipoles(same.arrays(), uniform_field(0, B0, 0), 0.0, p, same.forces());
  const ForceError replayed = force_error(same, at_solve.fx, at_solve.fy, at_solve.fz);
  // (The solve's far field lags its final dipoles by one pass: 1.6e-3 RMS with one pass, 7e-6
  // with four, 1.1e-8 with eight.)
  EXPECT_LT(replayed.rms, 1e-7);
  EXPECT_LT(replayed.max, 5e-7);

  Beads shaken = shaken_by(beads, 0.05);
  std::vector<double> fx, fy, fz;
  fresh_forces(shaken, s, box, fx, fy, fz);
  const ForceError holding_forces = force_error(at_solve, fx, fy, fz); // (the forces held from the solve)
  InducedDipoles live(s, box);
  live.forces_of_dipoles(shaken.arrays(), uniform_field(0, B0, 0), 0.0, p, shaken.forces());
  const ForceError holding_dipoles = force_error(shaken, fx, fy, fz);
  std::printf("%zu beads shaken by up to 0.05 r: held forces RMS %.2e worst %.2e; held dipoles at the new "
              "positions RMS %.2e worst %.2e (replay at the solve's positions: %.1e)\n",
              shaken.size(), holding_forces.rms, holding_forces.max, holding_dipoles.rms, holding_dipoles.max,
              replayed.rms);
  EXPECT_GT(holding_forces.rms, 1e-2); // the shaking matters
  EXPECT_LT(holding_dipoles.rms, holding_forces.rms / 3.0);
  EXPECT_LT(holding_dipoles.max, holding_forces.max / 3.0);
}

// MagneticSettings::hold_dipoles through InducedDipoles: (1) right after an evaluation the
// live close pairs change nothing; (2) after the beads are shaken, the held forces plus the
// live changes are much closer to a fresh solve than the held forces alone (only the close
// pairs follow, so less close than every pair live, measured above); (3) 1 and 2 threads
// give the same bits; (4) a restart from the written state gives the same bits.
TEST(RefreshModes, HoldingTheDipolesLetsTheClosePairsFollowTheBeads)
{
  const double L = 0.9e-3;
  const std::array<double, 3> box = {L, 0.0, L};
  const Beads start = standing_brush(75, L, 11);
  MagneticSettings s = exact_settings(StalenessMode::relative);
  s.far_field = FarField::cell_multipole;
  s.tolerance = 1e-10;
  s.hold_dipoles = true;
  s.live_pair_steps = 1; // (every call evaluates: the shaken positions are the second call)
  const Beads shaken = shaken_by(start, 0.05);
  std::vector<double> live_forces[2][3];
  for (int threads : {1, 2})
  {
    omp_set_num_threads(threads);
    Beads beads = start;
    InducedDipoles magnetics(s, box);
    magnetics.compute(beads.arrays(), uniform_field(0, B0, 0), 0.0, beads.forces());
    ASSERT_GT(magnetics.live_pairs(), beads.size()); // (within 3 mean radii: the chain neighbours and more)
    const Beads held = beads;
    Beads unchanged = start;
    unchanged.forces();
    magnetics.add_live_pair_changes(unchanged.arrays(), unchanged.forces());
    for (std::size_t k = 0; k < unchanged.size(); ++k)
      ASSERT_EQ(unchanged.fx[k], 0.0) << k;
    Beads moved = shaken;
    magnetics.add_held_forces(moved.forces());
    magnetics.add_live_pair_changes(moved.arrays(), {moved.fx.data(), moved.fy.data(), moved.fz.data()});
    live_forces[threads - 1][0] = moved.fx;
    live_forces[threads - 1][1] = moved.fy;
    live_forces[threads - 1][2] = moved.fz;
    if (threads == 2)
    {
      std::vector<double> fx, fy, fz;
      fresh_forces(shaken, s, box, fx, fy, fz);
      const ForceError forces_held = force_error(held, fx, fy, fz); // (the forces of the evaluation)
      const ForceError dipoles_held = force_error(moved, fx, fy, fz);
      std::printf("%zu beads shaken by up to 0.05 r, %zu live pairs: held forces RMS %.2e worst %.2e; held "
                  "dipoles with the close pairs live RMS %.2e worst %.2e\n",
                  shaken.size(), magnetics.live_pairs(), forces_held.rms, forces_held.max, dipoles_held.rms,
                  dipoles_held.max);
      EXPECT_LT(dipoles_held.rms, forces_held.rms / 3.0);
      EXPECT_LT(dipoles_held.max, forces_held.max / 3.0);
      // A restart from the written state: the same live changes, bit for bit.
      magbrush::MemoryStateOut out;
      magnetics.write_state(out);
      InducedDipoles restarted(s, box);
      magbrush::MemoryStateIn in(out.bytes(), "test state");
      ASSERT_TRUE(restarted.read_state(in));
      Beads again = shaken;
      restarted.add_held_forces(again.forces());
      restarted.add_live_pair_changes(again.arrays(), {again.fx.data(), again.fy.data(), again.fz.data()});
      EXPECT_EQ(again.fx, moved.fx);
      EXPECT_EQ(again.fz, moved.fz);
    }
  }
  omp_set_num_threads(2);
  for (int d = 0; d < 3; ++d)
    EXPECT_EQ(live_forces[0][d], live_forces[1][d]) << "1 vs 2 threads";
}
