// The exact two-sphere force against the dipole models over D = d/a and μr: ratios to the
// point-dipole force for the three coefficients, the series orders needed, and the cost of
// one exact evaluation and of building the correction table. Prints tables; asserts nothing.
#include "magnetics/dipole_physics.h"
#include "magnetics/two_sphere_exact.h"
#include "magnetics/two_sphere_table.h"

#include <chrono>
#include <cstdio>

using namespace magbrush::magnetics;

int main()
{
  const double Ds[] = {2.0, 2.02, 2.05, 2.1, 2.2, 2.5, 3.0, 3.5, 4.0, 5.0};
  std::printf("# Exact two-sphere force / point-dipole force (identical spheres, uniform field)\n");
  for (const char *which : {"parallel (field along the axis)", "perpendicular (across)", "transverse (sin psi cos psi term)"})
  {
    std::printf("\n## %s: exact/pd [mutual/pd]\n| mu_r |", which);
    for (double D : Ds)
      std::printf(" D=%.2f |", D);
    std::printf("\n|---|");
    for (std::size_t k = 0; k < sizeof Ds / sizeof Ds[0]; ++k)
      std::printf("---|");
    std::printf("\n");
    for (double mu : {1.5, 2.0, 3.9, 5.0, 10.0, 20.0})
    {
      const double beta = clausius_mossotti(mu);
      std::printf("| %4.1f |", mu);
      for (double D : Ds)
      {
        const TwoSphereForce ex = two_sphere_force({1, 1, mu, mu, D}, 1e-10, 2000);
        const TwoSphereForce pd = point_dipole_pair_force(1, beta, D);
        const TwoSphereForce md = mutual_dipole_pair_force(1, beta, D);
        double e, m;
        if (which[0] == 'p' && which[1] == 'a')
          e = ex.parallel / pd.parallel, m = md.parallel / pd.parallel;
        else if (which[0] == 'p')
          e = ex.perpendicular / pd.perpendicular, m = md.perpendicular / pd.perpendicular;
        else
          e = ex.transverse / pd.transverse, m = md.transverse / pd.transverse;
        std::printf(" %.3f [%.3f] |", e, m);
      }
      std::printf("\n");
    }
  }
  std::printf("\n## Cost: series orders for 1e-10 and time per exact evaluation; table build\n"
              "| mu_r | orders D=2 | time D=2 [s] | orders D=2.2 | time D=2.2 [s] | table build [s] |\n"
              "|---|---|---|---|---|---|\n");
  for (double mu : {1.5, 3.9, 10.0, 20.0})
  {
    auto t0 = std::chrono::steady_clock::now();
    const TwoSphereForce c = two_sphere_force({1, 1, mu, mu, 2.0}, 1e-10, 2000);
    const double t_contact = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t0 = std::chrono::steady_clock::now();
    const TwoSphereForce n = two_sphere_force({1, 1, mu, mu, 2.2}, 1e-10, 2000);
    const double t_near = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t0 = std::chrono::steady_clock::now();
    const TwoSphereTable table(clausius_mossotti(mu), 5.0);
    const double t_table = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("| %4.1f | %d | %.3f | %d | %.4f | %.2f |\n", mu, c.orders, t_contact, n.orders,
                t_near, t_table);
  }
  return 0;
}
