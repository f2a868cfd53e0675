// The cell-multipole far field against direct sums: near pairs (exact) + far field must give
// the field and gradient of ALL other dipoles (and all periodic images), for open boxes,
// one periodic axis (the nip slab) and two (the compression box), with the error falling
// as the expansion order grows.
#include "magnetics/cell_multipole_field.h"
#include "tests/magnetics/far_field_error.h"
#include "magnetics/dipole_physics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace magbrush::magnetics;

using magbrush::magnetics::testing::far_field_rms_error;

namespace {

// Field and gradient at r (target − source) of a dipole p: B_a = (μ0/4π) p_i ∂_i∂_a(1/r),
// ∂_b B_a = (μ0/4π) p_i ∂_i∂_a∂_b(1/r).
void dipole_field(const double r[3], const double p[3], double B[3], double G[9])
{
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  const double ir = 1.0 / std::sqrt(r2), ir5 = ir * ir * ir * ir * ir, ir7 = ir5 * ir * ir;
  const double c = mu0 / (4.0 * pi);
  for (int a = 0; a < 3; ++a)
  {
    for (int i = 0; i < 3; ++i)
      B[a] += c * p[i] * (3 * r[i] * r[a] - (i == a) * r2) * ir5;
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < 3; ++i)
        G[3 * a + b] += c * p[i] *
                        (-15.0 * r[i] * r[a] * r[b] * ir7 +
                         3.0 * ((i == a) * r[b] + (i == b) * r[a] + (a == b) * r[i]) * ir5);
  }
}

struct Cloud
{
  std::vector<double> x, y, z, p;
  std::size_t size() const { return x.size(); }
};

// Beads on a jittered cubic lattice of spacing a (about one bead diameter: a dense brush)
// filling a box, random dipoles around a mean along y (a polarised brush). Raw z positions
// are shifted by −0.3 Lz, so that the wrap into the periodic box is exercised.
Cloud random_cloud(double a, double Lx, double Ly, double Lz, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cloud c;
  const long nx = std::lround(Lx / a), ny = std::lround(Ly / a), nz = std::lround(Lz / a);
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j)
      for (long k = 0; k < nz; ++k)
      {
        c.x.push_back(Lx / nx * (i + 0.5 + 0.1 * (u(rng) - 0.5)));
        c.y.push_back(Ly / ny * (j + 0.5 + 0.1 * (u(rng) - 0.5)));
        c.z.push_back(Lz / nz * (k + 0.5 + 0.1 * (u(rng) - 0.5)) - 0.3 * Lz);
        c.p.push_back(1e-9 * (u(rng) - 0.5));
        c.p.push_back(1e-9 * (1.0 + 0.5 * u(rng)));
        c.p.push_back(1e-9 * (u(rng) - 0.5));
      }
  return c;
}

// Direct sum over all other beads and the images listed by `images` (offsets in periods).
template <class Images>
void direct(const Cloud &c, const std::array<double, 3> &box, Images &&images,
            std::vector<double> &B, std::vector<double> &G)
{
  const std::size_t n = c.size();
  B.assign(3 * n, 0.0);
  G.assign(9 * n, 0.0);
#pragma omp parallel for schedule(dynamic, 8)
  for (long i = 0; i < static_cast<long>(n); ++i)
    images([&](long a, long b, long d) {
      for (std::size_t k = 0; k < n; ++k)
      {
        if (static_cast<long>(k) == i && a == 0 && b == 0 && d == 0)
          continue;
        const double r[3] = {c.x[i] - c.x[k] - a * box[0], c.y[i] - c.y[k] - b * box[1],
                             c.z[i] - c.z[k] - d * box[2]};
        dipole_field(r, &c.p[3 * k], &B[3 * i], &G[9 * i]);
      }
    });
}

// Far field (B, G) and the exact sums over the near pairs (Bnear, Gnear) at every bead.
void fast(const Cloud &c, const std::array<double, 3> &box, int order, double h, int reach,
          std::vector<double> &B, std::vector<double> &G, std::vector<double> &Bnear,
          std::vector<double> &Gnear, std::size_t *near = nullptr, bool single = true)
{
  CellMultipoleField field(order, box, reach);
  field.set_single_precision(single);
  field.build(c.size(), c.x.data(), c.y.data(), c.z.data(), h);
  B.assign(3 * c.size(), 0.0);
  G.assign(9 * c.size(), 0.0);
  field.evaluate(c.p.data(), B.data(), G.data());
  Bnear.assign(3 * c.size(), 0.0);
  Gnear.assign(9 * c.size(), 0.0);
  for (const auto &pair : field.near_pairs())
  {
    const double r[3] = {c.x[pair.j] - c.x[pair.i] + pair.shift[0],
                         c.y[pair.j] - c.y[pair.i] + pair.shift[1],
                         c.z[pair.j] - c.z[pair.i] + pair.shift[2]};
    const double mr[3] = {-r[0], -r[1], -r[2]};
    dipole_field(r, &c.p[3 * pair.i], &Bnear[3 * pair.j], &Gnear[9 * pair.j]);
    dipole_field(mr, &c.p[3 * pair.j], &Bnear[3 * pair.i], &Gnear[9 * pair.i]);
  }
  if (near)
    *near = field.near_pairs().size();
}


// RMS |X_ref − X_near| / RMS |X_ref|: the share of the far field in the total.
double far_share(const std::vector<double> &near, const std::vector<double> &ref)
{
  double e = 0.0, r = 0.0;
  for (std::size_t k = 0; k < ref.size(); ++k)
  {
    e += (ref[k] - near[k]) * (ref[k] - near[k]);
    r += ref[k] * ref[k];
  }
  return std::sqrt(e / r);
}

} // namespace

TEST(CellMultipoleField, OpenBoxMatchesDirectSum)
{
  const Cloud c = random_cloud(60e-6, 1.2e-3, 0.6e-3, 0.6e-3, 1);
  std::vector<double> Bref, Gref, B, G, Bn, Gn;
  direct(c, {0, 0, 0}, [](auto &&f) { f(0, 0, 0); }, Bref, Gref);
  double previous = 1.0;
  for (int order = 0; order <= 4; ++order)
  {
    fast(c, {0, 0, 0}, order, 65e-6, 2, B, G, Bn, Gn);
    const double eB = far_field_rms_error(B, Bn, Bref), eG = far_field_rms_error(G, Gn, Gref);
    std::printf("open, order %d: far-field error: field %.2e  gradient %.2e  (far share %.2f, %.2f)\n", order, eB, eG, far_share(Bn, Bref), far_share(Gn, Gref));
    EXPECT_LT(eB, previous);
    previous = eB;
    if (order == 4)
    {
      EXPECT_LT(eB, 8e-3);
      EXPECT_LT(eG, 5e-2);
    }
  }
}

TEST(CellMultipoleField, PeriodicAlongOneAxisMatchesImageSum)
{
  // The nip topology: periodic along z (1 mm), open across.
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  const Cloud c = random_cloud(100e-6, 1.5e-3, 0.2e-3, 1e-3, 2);
  std::vector<double> Bref, Gref, B, G, Bn, Gn;
  direct(c, box, [](auto &&f) { for (long m = -200; m <= 200; ++m) f(0, 0, m); }, Bref, Gref);
  for (int order = 1; order <= 3; ++order)
  {
    fast(c, box, order, 65e-6, 2, B, G, Bn, Gn);
    const double eB = far_field_rms_error(B, Bn, Bref), eG = far_field_rms_error(G, Gn, Gref);
    std::printf("z-periodic, order %d: far-field error: field %.2e  gradient %.2e  (far share %.2f, %.2f)\n", order, eB, eG, far_share(Bn, Bref), far_share(Gn, Gref));
    if (order == 3)
    {
      EXPECT_LT(eB, 2e-2);
      EXPECT_LT(eG, 1.5e-1);
    }
  }
}

TEST(CellMultipoleField, SinglePrecisionTranslationsAreHarmless)
{
  // M2L in float against double, z-periodic: the rounding must stay far below the
  // expansion error (~1e-2 of the far field at order 2).
  const std::array<double, 3> box = {0.0, 0.0, 0.6e-3};
  const Cloud c = random_cloud(60e-6, 1.2e-3, 0.3e-3, 0.6e-3, 8);
  std::vector<double> B1, G1, B2, G2, Bn, Gn;
  fast(c, box, 2, 90e-6, 2, B1, G1, Bn, Gn, nullptr, true);
  fast(c, box, 2, 90e-6, 2, B2, G2, Bn, Gn, nullptr, false);
  const std::vector<double> zeroB(B1.size(), 0.0), zeroG(G1.size(), 0.0);
  const double eB = far_field_rms_error(B1, zeroB, B2), eG = far_field_rms_error(G1, zeroG, G2);
  std::printf("single vs double precision M2L: field %.2e  gradient %.2e (relative to the far field)\n", eB, eG);
  EXPECT_LT(eB, 1e-5);
  EXPECT_LT(eG, 1e-5);
}

TEST(CellMultipoleField, WideStripPeriodicAlongOneAxis)
{
  // A strip much wider than its period (the nip: 6 mm × 1 mm): the open axes keep coarsening
  // above the level where the periodic axis has reached its top cell count.
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  const Cloud c = random_cloud(150e-6, 4.5e-3, 0.3e-3, 1e-3, 6);
  std::vector<double> Bref, Gref, B, G, Bn, Gn;
  direct(c, box, [](auto &&f) { for (long m = -200; m <= 200; ++m) f(0, 0, m); }, Bref, Gref);
  fast(c, box, 3, 65e-6, 2, B, G, Bn, Gn);
  const double eB = far_field_rms_error(B, Bn, Bref), eG = far_field_rms_error(G, Gn, Gref);
  std::printf("wide z-periodic strip, order 3: far-field error: field %.2e  gradient %.2e\n", eB, eG);
  EXPECT_LT(eB, 4e-2);
  EXPECT_LT(eG, 2.5e-1);
}

TEST(CellMultipoleField, PeriodicAlongTwoAxesMatchesLatticeSum)
{
  // The compression box: periodic along x and z (0.4 mm), open along y. Reference: images in
  // a disc of 100 periods plus the continuum beyond it (field tensor only: the gradient's
  // continuum decays like 1/R²), checked against a disc of 50 periods.
  const std::array<double, 3> box = {0.4e-3, 0.0, 0.4e-3};
  const Cloud c = random_cloud(100e-6, 0.4e-3, 0.3e-3, 0.4e-3, 3);
  auto reference = [&](long M, std::vector<double> &B, std::vector<double> &G) {
    long count = 0;
    direct(c, box, [&](auto &&f) {
      for (long a = -M; a <= M; ++a)
        for (long d = -M; d <= M; ++d)
          if (a * a + d * d <= M * M)
            f(a, 0, d);
    }, B, G);
    for (long a = -M; a <= M; ++a)
      for (long d = -M; d <= M; ++d)
        count += (a * a + d * d <= M * M);
    // Continuum beyond R: B_tail = −(μ0/4π)(π/A) R²/(R²+h²)^{3/2} (2 p_y ŷ − p_x x̂ − p_z ẑ).
    const double A = box[0] * box[2], R2 = count * A / pi;
    for (std::size_t i = 0; i < c.size(); ++i)
      for (std::size_t k = 0; k < c.size(); ++k)
      {
        const double h = c.y[i] - c.y[k], s0 = R2 + h * h, q = R2 / (s0 * std::sqrt(s0));
        const double f = mu0 / (4.0 * pi) * pi / A * q;
        B[3 * i + 0] += f * c.p[3 * k + 0];
        B[3 * i + 1] += -2.0 * f * c.p[3 * k + 1];
        B[3 * i + 2] += f * c.p[3 * k + 2];
      }
  };
  std::vector<double> Bref, Gref, B2, G2, B, G, Bn, Gn;
  reference(100, Bref, Gref);
  reference(50, B2, G2);
  const double ref_error = far_field_rms_error(B2, std::vector<double>(B2.size(), 0.0), Bref);
  std::printf("x/z-periodic reference: disc 50 vs 100 periods %.2e\n", ref_error);
  EXPECT_LT(ref_error, 1e-4);
  for (int order = 1; order <= 3; ++order)
  {
    fast(c, box, order, 65e-6, 2, B, G, Bn, Gn);
    const double eB = far_field_rms_error(B, Bn, Bref), eG = far_field_rms_error(G, Gn, Gref);
    std::printf("x/z-periodic, order %d: far-field error: field %.2e  gradient %.2e  (far share %.2f, %.2f)\n", order, eB, eG, far_share(Bn, Bref), far_share(Gn, Gref));
    if (order == 3)
    {
      EXPECT_LT(eB, 1e-2);
      EXPECT_LT(eG, 1.5e-1);
    }
  }
}

TEST(CartesianTaylor, OperatorChainConvergesGeometrically)
{
  // Dipoles within 0.1 of a source centre, targets within 0.1 of a target centre 1.0 away,
  // through the whole chain P2M → M2M (to a parent centre 0.1 off) → M2L → L2L (to a child
  // centre 0.1 off) → L2P: the error must fall geometrically (measured 0.2 per order).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  const double c[3] = {0.0, 0.0, 0.0}, parent[3] = {0.1, -0.05, 0.05};
  const double t[3] = {0.6, 0.7, 0.4}, child[3] = {0.55, 0.75, 0.45};
  std::vector<std::array<double, 3>> src, dip, tgt;
  for (int k = 0; k < 10; ++k)
  {
    src.push_back({c[0] + u(rng), c[1] + u(rng), c[2] + u(rng)});
    dip.push_back({u(rng), u(rng), 1.0 + u(rng)});
    tgt.push_back({child[0] + u(rng), child[1] + u(rng), child[2] + u(rng)});
  }
  for (int order : {0, 2, 4, 6})
  {
    CartesianTaylor taylor(order);
    std::vector<double> M(taylor.multipole_size(), 0.0), Mp(taylor.multipole_size(), 0.0);
    std::vector<double> L(taylor.local_size(), 0.0), Lc(taylor.local_size(), 0.0);
    std::vector<double> D(taylor.derivative_size());
    for (std::size_t k = 0; k < src.size(); ++k)
    {
      const double s[3] = {src[k][0] - c[0], src[k][1] - c[1], src[k][2] - c[2]};
      taylor.add_dipole(s, dip[k].data(), M.data());
    }
    const double d[3] = {c[0] - parent[0], c[1] - parent[1], c[2] - parent[2]};
    taylor.shift_multipole(d, M.data(), Mp.data());
    const double R[3] = {t[0] - parent[0], t[1] - parent[1], t[2] - parent[2]};
    taylor.derivatives(R, D.data());
    taylor.multipole_to_local(D.data(), Mp.data(), L.data());
    const double e[3] = {child[0] - t[0], child[1] - t[1], child[2] - t[2]};
    taylor.shift_local(e, L.data(), Lc.data());
    double eB = 0, nB = 0, eG = 0, nG = 0;
    for (const auto &x : tgt)
    {
      double B[3] = {0, 0, 0}, G[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
      const double uu[3] = {x[0] - child[0], x[1] - child[1], x[2] - child[2]};
      taylor.evaluate(uu, Lc.data(), B, G);
      double Br[3] = {0, 0, 0}, Gr[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      for (std::size_t k = 0; k < src.size(); ++k)
      {
        const double r[3] = {x[0] - src[k][0], x[1] - src[k][1], x[2] - src[k][2]};
        dipole_field(r, dip[k].data(), Br, Gr);
      }
      for (int a = 0; a < 3; ++a)
      {
        eB += (B[a] - Br[a]) * (B[a] - Br[a]);
        nB += Br[a] * Br[a];
        for (int b = 0; b < 3; ++b)
        {
          eG += (G[a][b] - Gr[3 * a + b]) * (G[a][b] - Gr[3 * a + b]);
          nG += Gr[3 * a + b] * Gr[3 * a + b];
        }
      }
    }
    eB = std::sqrt(eB / nB);
    eG = std::sqrt(eG / nG);
    std::printf("operator chain, order %d: field %.2e  gradient %.2e\n", order, eB, eG);
    if (order == 6)
    {
      EXPECT_LT(eB, 1e-5);
      EXPECT_LT(eG, 5e-5);
    }
  }
}
