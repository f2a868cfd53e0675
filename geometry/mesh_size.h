// The target element size of a mesh as an analytic function of position.
//
// Each feature of the scene (the sleeve band where the DEM samples the field, the development
// gap, a circle that must be resolved, a magnetic blade) asks for a size at the feature that
// grows linearly with the distance from it; the target size is the smallest of these, capped
// at the far-field size. A linear growth h = h0 + g d makes neighbouring elements grow by the
// factor (1 + g), a geometric grading that keeps the quads well shaped.
//
// The same function drives Gmsh (a size callback) and the structured parts of the meshes
// (the node counts of the photoconductor layer and of the shell arcs), and the tests compare
// the element sizes of the mesh with it.
#pragma once

#include "case/case_model.h"

#include <functional>
#include <vector>

namespace magbrush {

// Minimum number of chords on every circle of a mesh: the area of a circle drawn with n chords
// is short by (2π/n)²/6 of it (4·10⁻⁴ at 128), which keeps every region area within 10⁻³ of
// the exact one even on coarse meshes.
constexpr int min_segments_per_circle = 128;
// Growth rate of the element size with distance from a feature (about 20 % per element).
constexpr double mesh_grading = 0.2;

class MeshSizeFunction
{
public:
  // far_size: the cap [m]; grading: the growth rate g = dh/dd of the size with distance.
  MeshSizeFunction(double far_size, double grading);

  // Size `size` on the band r_lo ≤ |x − c| ≤ r_hi (a circle when r_lo = r_hi).
  void add_annulus(const Vec2 &c, double r_lo, double r_hi, double size);
  // A circle resolved with at least `segments` chords (its chord area error ≈ (2π/n)²/6).
  void add_resolved_circle(const Vec2 &c, double radius, int segments);
  // Size `size` in the disk |x − p| ≤ radius.
  void add_disk(const Vec2 &p, double radius, double size);
  // Size `size` on and inside a polygon.
  void add_polygon(const std::vector<Vec2> &polygon, double size);

  double operator()(const Vec2 &x) const;
  double far_size() const { return far_size_; }
  double grading() const { return grading_; }

private:
  struct Feature
  {
    std::function<double(const Vec2 &)> distance; // 0 on the feature
    double size;
  };
  double far_size_;
  double grading_;
  std::vector<Feature> features_;
};

// Number of segments of a curve of length `length` meshed with a geometric progression
// from size h0 at its start to size h1 at its end (h = h0 + g s on a straight run has exactly
// this form), and the ratio between neighbouring segments. Returns {1, 1} for very short
// curves and a uniform division when h1 ≈ h0.
struct Progression
{
  int segments = 1;
  double ratio = 1.0;
};
Progression graded_division(double length, double h0, double h1);

} // namespace magbrush
