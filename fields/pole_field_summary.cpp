#include "fields/pole_field_summary.h"

#include "case/units.h"
#include "fields/multipole_ring.h"

#include <exception>
#include <sstream>

namespace magbrush {

std::string format_pole_field(const Case &c)
{
  if (!c.roller || !c.sleeve || c.roller->poles.empty())
    return "";
  constexpr double mu0 = 4.0e-7 * 3.14159265358979323846;
  std::ostringstream out;
  // The exact field of the pole model (multipole_ring.h), the same one the field solver is
  // verified against: normal flux density on the sleeve surface at each pole and at the nip.
  try
  {
    const MultipoleRing ring(*c.roller);
    const auto B = [&](double theta) { return ring.field_polar(c.sleeve->radius, theta).Br; };
    out << "sleeve-surface field of the pole model (exact multipole ring, " << ring.harmonic_count()
        << " harmonics):\n";
    for (const auto &p : c.roller->poles)
    {
      const double b = B(p.angle);
      out << "  " << p.name << " at " << format_quantity(p.angle, Dimension::angle) << ": Bn = "
          << format_quantity(b, Dimension::magnetic_flux_density)
          << ", magnetic pressure B^2/2mu0 = " << format_quantity(b * b / (2.0 * mu0), Dimension::pressure) << "\n";
    }
    if (c.drum.present)
      out << "  at the nip (" << format_quantity(c.drum.angle, Dimension::angle)
          << "): Bn = " << format_quantity(B(c.drum.angle), Dimension::magnetic_flux_density) << "\n";
  }
  catch (const std::exception &e)
  {
    out << "sleeve-surface field: not available (" << e.what() << ")\n";
  }
  return out.str();
}

} // namespace magbrush
