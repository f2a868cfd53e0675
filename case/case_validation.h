// Geometric and physical consistency of a resolved case: the checks a schema cannot express
// (the drum must not cut the sleeve, a blade must sit outside it, the magnet must fit inside
// the sleeve, a size distribution must stay positive, toner needs a charge, every measurement's
// averaging window lies inside the run, ...).
#pragma once

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush {

// One problem, attached to the key path it is about ("drum.gap", "roller.poles.N1.angle").
struct CaseIssue
{
  std::string path;
  std::string message;
};

// Smallest angular separation allowed between two poles.
constexpr double min_pole_separation_deg = 10.0;

std::vector<CaseIssue> validate_case(const Case &c);

// Helpers shared with the parser and the geometry stage.
double polygon_signed_area(const std::vector<Vec2> &polygon);      // > 0 counter-clockwise
bool polygon_is_simple(const std::vector<Vec2> &polygon);          // no self-intersection
double polygon_distance_to_point(const std::vector<Vec2> &polygon, const Vec2 &p); // 0 inside
bool polygon_contains(const std::vector<Vec2> &polygon, const Vec2 &p);

// The rectangle of a blade given by its centre-line angle, tip gap to a sleeve of radius
// `sleeve_radius`, thickness and radial length (counter-clockwise).
std::vector<Vec2> generated_blade_polygon(double sleeve_radius, double angle, double gap,
                                          double thickness, double length);

} // namespace magbrush
