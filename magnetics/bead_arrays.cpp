#include "magnetics/bead_arrays.h"

namespace magbrush::magnetics {

AppliedFieldFunction uniform_field(double Bx, double By, double Bz)
{
  return [Bx, By, Bz](const double *, double B[3], double gradB[3][3]) {
    B[0] = Bx;
    B[1] = By;
    B[2] = Bz;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        gradB[a][b] = 0.0;
  };
}

} // namespace magbrush::magnetics
