// A grounded conductor the charges see from the air: the drum substrate under its
// photoconductor layer, the sleeve, or (tests, box scenes) a plane. The images of a charge
// are taken LOCALLY PLANAR: at the foot point of the charge on the surface, with the
// surface's tangent plane as the mirror (layered_images.h). The error is set by the height h
// (or the pair distance d) against the radius of curvature R: near a grounded SPHERE the exact
// self force is the planar one times 1 − h²/(2R + h)² (Kelvin's image q R/D at R²/D), a
// second-order error; a cylinder curves in one direction only, and we state the error as at
// most O(h/R): toner at h = 3.5 µm on a 15 mm drum ≤ 2e-4, a chain tip 0.5 mm from it ≤ 3 %.
#pragma once

#include "electrostatics/layered_images.h"

#include <cmath>

namespace magbrush::electrostatics {

struct GroundedSurface
{
  enum class Shape { plane, cylinder };
  Shape shape = Shape::plane;
  // Plane: a point on the surface and the unit normal into the air.
  double point[3] = {0.0, 0.0, 0.0};
  double normal[3] = {0.0, 1.0, 0.0};
  // Cylinder along z (the drum, the sleeve): the axis in the x–y plane and the radius of the
  // surface the charges see (the photoconductor's outer surface for the drum); air outside.
  double centre_x = 0.0, centre_y = 0.0, radius = 0.0;
  LayeredImages layer{1.0, 0.0}; // a bare conductor unless given a layer

  // Height of (x, y, z) above the surface (negative inside) and the unit normal n into the
  // air at its foot point; the foot point is (x, y, z) − h n.
  double height(double x, double y, double z, double n[3]) const
  {
    if (shape == Shape::plane)
    {
      n[0] = normal[0];
      n[1] = normal[1];
      n[2] = normal[2];
      return (x - point[0]) * n[0] + (y - point[1]) * n[1] + (z - point[2]) * n[2];
    }
    const double dx = x - centre_x, dy = y - centre_y;
    const double r = std::sqrt(dx * dx + dy * dy);
    n[0] = r > 0.0 ? dx / r : 1.0;
    n[1] = r > 0.0 ? dy / r : 0.0;
    n[2] = 0.0;
    return r - radius;
  }
};

} // namespace magbrush::electrostatics
