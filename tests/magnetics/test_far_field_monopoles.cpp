// The far-field machinery with MONOPOLE sources (the electrostatics to come: Coulomb between
// charged toner and carriers, no cutoff): the Cartesian Taylor operators and the cell
// multipole method built for charges (SourceKind::charges) against direct Coulomb sums.
//
// The kernel sums are Φ(x) = Σ q_j/|x − x_j| and E = −∇Φ = Σ q_j r/|r|³ (r = x − x_j), the
// dipole terms Φ = Σ p·r/|r|³; no physical prefactor. Charges random and net-neutral,
// open boundaries (periodic charges: tests/electrostatics/test_periodic_coulomb.cpp).
//
// Measured far-field error (RMS over beads |X_far − (X_direct − X_near)| / RMS |X_direct −
// X_near|, 2,000 charges on a jittered 60 µm lattice in 1.2 × 0.6 × 0.6 mm, cells 65 µm,
// near field reach 2; the same with the M2L in double precision):
//   order 2: potential 1.4e-2, field 4.5e-2, gradient 2.0e-1
//   order 4: potential 1.6e-3, field 7.3e-3, gradient 4.4e-2
//   order 6: potential 1.9e-4, field 1.1e-3, gradient 8.2e-3
// (total field, far + near, against the whole direct sum at order 6: 3.8e-4). Charges with
// dipoles of moment ~ q × spacing: field 2.3e-2 at order 4, 4.8e-3 at order 6.
#include "magnetics/cartesian_taylor.h"
#include "magnetics/cell_multipole_field.h"
#include "tests/magnetics/far_field_error.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

using namespace magbrush::magnetics;

using magbrush::magnetics::testing::far_field_rms_error;

namespace {

// Adds at r = x − y the potential, field E = −∇Φ and its gradient ∂_c E_a of a charge q and a
// dipole p (either may be zero) at y.
void coulomb(const double r[3], double q, const double p[3], double &phi, double E[3], double G[9])
{
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  const double ir = 1.0 / std::sqrt(r2), ir3 = ir * ir * ir, ir5 = ir3 * ir * ir, ir7 = ir5 * ir * ir;
  const double pr = p[0] * r[0] + p[1] * r[1] + p[2] * r[2];
  phi += q * ir + pr * ir3;
  for (int a = 0; a < 3; ++a)
  {
    E[a] += q * r[a] * ir3 + 3.0 * pr * r[a] * ir5 - p[a] * ir3;
    for (int c = 0; c < 3; ++c)
    {
      const double d = a == c ? 1.0 : 0.0;
      G[3 * a + c] += q * (d * ir3 - 3.0 * r[a] * r[c] * ir5) +
                      3.0 * (p[c] * r[a] + pr * d + p[a] * r[c]) * ir5 - 15.0 * pr * r[a] * r[c] * ir7;
    }
  }
}

struct Charges
{
  std::vector<double> x, y, z, q, p;
  std::size_t size() const { return x.size(); }
};

// Charges on a jittered cubic lattice of spacing a filling an L box, random ±q with the mean
// removed (net neutral); with `dipoles`, random dipoles of moment ~ q a as well.
Charges random_charges(double a, double Lx, double Ly, double Lz, bool dipoles, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Charges c;
  const long nx = std::lround(Lx / a), ny = std::lround(Ly / a), nz = std::lround(Lz / a);
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j)
      for (long k = 0; k < nz; ++k)
      {
        c.x.push_back(Lx / nx * (i + 0.5 + 0.1 * (u(rng) - 0.5)));
        c.y.push_back(Ly / ny * (j + 0.5 + 0.1 * (u(rng) - 0.5)));
        c.z.push_back(Lz / nz * (k + 0.5 + 0.1 * (u(rng) - 0.5)));
        c.q.push_back(1e-15 * (2.0 * u(rng) - 1.0));
        for (int d = 0; d < 3; ++d)
          c.p.push_back(dipoles ? 1e-15 * a * (2.0 * u(rng) - 1.0) : 0.0);
      }
  double mean = 0.0;
  for (double q : c.q)
    mean += q;
  mean /= static_cast<double>(c.size());
  for (double &q : c.q)
    q -= mean;
  return c;
}

struct Fields
{
  std::vector<double> phi, E, G;
  void zero(std::size_t n)
  {
    phi.assign(n, 0.0);
    E.assign(3 * n, 0.0);
    G.assign(9 * n, 0.0);
  }
};

// Direct sum over all other charges.
Fields direct(const Charges &c)
{
  const std::size_t n = c.size();
  Fields f;
  f.zero(n);
#pragma omp parallel for schedule(dynamic, 16)
  for (long i = 0; i < static_cast<long>(n); ++i)
    for (std::size_t k = 0; k < n; ++k)
    {
      if (static_cast<long>(k) == i)
        continue;
      const double r[3] = {c.x[i] - c.x[k], c.y[i] - c.y[k], c.z[i] - c.z[k]};
      coulomb(r, c.q[k], &c.p[3 * k], f.phi[i], &f.E[3 * i], &f.G[9 * i]);
    }
  return f;
}

// The far field of the cell multipole method, and the exact sums over its near pairs.
void fast(const Charges &c, int order, double h, Fields &far, Fields &near, bool with_dipoles)
{
  CellMultipoleField field(order, {0.0, 0.0, 0.0}, 2, SourceKind::charges);
  field.build(c.size(), c.x.data(), c.y.data(), c.z.data(), h);
  far.zero(c.size());
  field.evaluate(FarFieldSources{c.q.data(), with_dipoles ? c.p.data() : nullptr},
                 FarFieldTargets{far.phi.data(), far.E.data(), far.G.data()});
  near.zero(c.size());
  for (const auto &pair : field.near_pairs())
  {
    const double r[3] = {c.x[pair.j] - c.x[pair.i], c.y[pair.j] - c.y[pair.i], c.z[pair.j] - c.z[pair.i]};
    const double mr[3] = {-r[0], -r[1], -r[2]};
    coulomb(r, c.q[pair.i], &c.p[3 * pair.i], near.phi[pair.j], &near.E[3 * pair.j], &near.G[9 * pair.j]);
    coulomb(mr, c.q[pair.j], &c.p[3 * pair.j], near.phi[pair.i], &near.E[3 * pair.i], &near.G[9 * pair.i]);
  }
}


} // namespace

TEST(CartesianTaylor, ChargeOperatorChainConvergesGeometrically)
{
  // Charges (net neutral) and dipoles within 0.1 of a source centre, targets within 0.1 of a
  // target centre 1.0 away, through P2M → M2M → M2L → L2L → L2P: potential and field must
  // converge geometrically with the order (measured field 1.0, 4.7e-2, 1.5e-3, 4.5e-5 at
  // orders 0, 2, 4, 6).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  const double c[3] = {0.0, 0.0, 0.0}, parent[3] = {0.1, -0.05, 0.05};
  const double t[3] = {0.6, 0.7, 0.4}, child[3] = {0.55, 0.75, 0.45};
  std::vector<std::array<double, 3>> src, dip, tgt;
  std::vector<double> q;
  for (int k = 0; k < 10; ++k)
  {
    src.push_back({c[0] + u(rng), c[1] + u(rng), c[2] + u(rng)});
    dip.push_back({u(rng), u(rng), 0.1 + u(rng)});
    q.push_back(k % 2 ? 1.0 + u(rng) : -1.0 - u(rng));
    tgt.push_back({child[0] + u(rng), child[1] + u(rng), child[2] + u(rng)});
  }
  double previous = 2.0; // (order 0, the total charge alone, knows nothing of a neutral cluster)
  for (int order : {0, 2, 4, 6})
  {
    CartesianTaylor taylor(order, SourceKind::charges);
    std::vector<double> M(taylor.multipole_size(), 0.0), Mp(taylor.multipole_size(), 0.0);
    std::vector<double> L(taylor.local_size(), 0.0), Lc(taylor.local_size(), 0.0);
    std::vector<double> D(taylor.derivative_size());
    for (std::size_t k = 0; k < src.size(); ++k)
    {
      const double s[3] = {src[k][0] - c[0], src[k][1] - c[1], src[k][2] - c[2]};
      taylor.add_charge(s, q[k], M.data());
      taylor.add_dipole(s, dip[k].data(), M.data());
    }
    const double d[3] = {c[0] - parent[0], c[1] - parent[1], c[2] - parent[2]};
    taylor.shift_multipole(d, M.data(), Mp.data());
    const double R[3] = {t[0] - parent[0], t[1] - parent[1], t[2] - parent[2]};
    taylor.derivatives(R, D.data());
    taylor.multipole_to_local(D.data(), Mp.data(), L.data());
    const double e[3] = {child[0] - t[0], child[1] - t[1], child[2] - t[2]};
    taylor.shift_local(e, L.data(), Lc.data());
    double ephi = 0, nphi = 0, eE = 0, nE = 0;
    for (const auto &x : tgt)
    {
      double phi = 0.0, grad[3] = {0, 0, 0};
      const double uu[3] = {x[0] - child[0], x[1] - child[1], x[2] - child[2]};
      taylor.evaluate_potential(uu, Lc.data(), &phi, grad, nullptr);
      double phir = 0.0, Er[3] = {0, 0, 0}, Gr[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      for (std::size_t k = 0; k < src.size(); ++k)
      {
        const double r[3] = {x[0] - src[k][0], x[1] - src[k][1], x[2] - src[k][2]};
        coulomb(r, q[k], dip[k].data(), phir, Er, Gr);
      }
      ephi += (phi - phir) * (phi - phir);
      nphi += phir * phir;
      for (int a = 0; a < 3; ++a)
      {
        eE += (-grad[a] - Er[a]) * (-grad[a] - Er[a]);
        nE += Er[a] * Er[a];
      }
    }
    ephi = std::sqrt(ephi / nphi);
    eE = std::sqrt(eE / nE);
    std::printf("charge operator chain, order %d: potential %.2e  field %.2e\n", order, ephi, eE);
    EXPECT_LT(eE, previous);
    previous = eE;
    if (order == 6)
    {
      EXPECT_LT(ephi, 3e-5);
      EXPECT_LT(eE, 1e-4);
    }
  }
}

TEST(CellMultipoleField, OpenBoxChargesMatchDirectCoulombSum)
{
  const Charges c = random_charges(60e-6, 1.2e-3, 0.6e-3, 0.6e-3, false, 11);
  const Fields ref = direct(c);
  Fields far, near;
  double previous = 1.0;
  for (int order : {2, 4, 6})
  {
    fast(c, order, 65e-6, far, near, false);
    const double ephi = far_field_rms_error(far.phi, near.phi, ref.phi), eE = far_field_rms_error(far.E, near.E, ref.E),
                 eG = far_field_rms_error(far.G, near.G, ref.G);
    std::printf("charges, open, order %d: far-field error: potential %.2e  field %.2e  gradient %.2e\n",
                order, ephi, eE, eG);
    EXPECT_LT(eE, 0.5 * previous); // at least halves per two orders
    previous = eE;
    const double field_bound[3] = {6e-2, 1e-2, 1.5e-3}, potential_bound[3] = {2e-2, 2.5e-3, 3e-4};
    EXPECT_LT(eE, field_bound[order / 2 - 1]);
    EXPECT_LT(ephi, potential_bound[order / 2 - 1]);
  }
  // Far + near is the whole Coulomb field, to the far part's error.
  Fields total;
  total.zero(c.size());
  for (std::size_t k = 0; k < far.E.size(); ++k)
    total.E[k] = far.E[k] + near.E[k];
  const std::vector<double> zero(total.E.size(), 0.0);
  const double e_total = far_field_rms_error(total.E, zero, ref.E);
  std::printf("charges, open, order 6: total field error %.2e (relative to the whole field)\n", e_total);
  EXPECT_LT(e_total, 6e-4);
}

TEST(CellMultipoleField, OpenBoxChargesAndDipolesMatchDirectSum)
{
  // Charges with dipoles (a polarised charged bead) in one expansion. The dipoles' moments
  // start one order higher than the charges', so at order p they are expanded like the
  // dipole-only expansion at order p − 1.
  const Charges c = random_charges(60e-6, 0.9e-3, 0.6e-3, 0.6e-3, true, 12);
  const Fields ref = direct(c);
  Fields far, near;
  for (int order : {4, 6})
  {
    fast(c, order, 65e-6, far, near, true);
    const double ephi = far_field_rms_error(far.phi, near.phi, ref.phi), eE = far_field_rms_error(far.E, near.E, ref.E);
    std::printf("charges + dipoles, open, order %d: far-field error: potential %.2e  field %.2e\n",
                order, ephi, eE);
    EXPECT_LT(ephi, order == 4 ? 7e-3 : 1.5e-3);
    EXPECT_LT(eE, order == 4 ? 3.5e-2 : 7e-3);
  }
}

// Periodic charges (one or two axes) are verified in tests/electrostatics/; three periodic
// axes stay refused for any source kind, and the source kinds are not interchangeable.
TEST(CellMultipoleField, TriplyPeriodicChargesAndWrongSourceKindAreRefused)
{
  EXPECT_THROW(CellMultipoleField(2, {1e-3, 1e-3, 1e-3}, 2, SourceKind::charges), std::invalid_argument);
  CellMultipoleField dipoles(2, {0.0, 0.0, 0.0});
  EXPECT_THROW(dipoles.evaluate(FarFieldSources{}, FarFieldTargets{}), std::logic_error);
}
