// Kawamoto's compression test, measured at the plate (Kawamoto et al., "fundamental
// investigation", Fig. 5, 6, 9, 10, 12): a magnetic brush stands on a stage in a uniform field
// normal to it; a plate moves on a prescribed path (down onto the brush, then sideways). This
// measurement reads the beads touching the plate and writes
//
//   plate_compression.csv   one row per averaging window: time, brush length (plate gap),
//                           applied |B|, normal and tangential plate force and pressure, number
//                           and density of touching beads, mean normal force per touching bead,
//                           chain spacing l/√n, tangential/normal ratio;
//   contact_map_<k>.csv     per-bead contact map at chosen instants (Fig. 9): position in the
//                           plate plane, normal and tangential force of each touching bead;
//   contact_maps.csv        the index of the maps (time, gap, |B|, beads).
//
// Definitions (A = the periodic area l_a × l_b of the box in the plate plane; the plate normal
// n̂ points into the brush; F_w = Σ forces of the touching beads on the plate):
//   gap      = (x_plate(t) − x_stage(t))·n̂_stage       (the brush length between the walls)
//   F_n      = −F_w·n̂  (> 0 when the brush pushes the plate away)
//   F_t      = F_w − (F_w·n̂)n̂ (its components along the plate-plane axes, and |F_t|)
//   density  = n / A,  mean force per bead = F_n / n,  chain spacing = √(A/n) = l/√n for l×l
// Every row is the mean over its window of the sampled values; per-bead quantities are ratios
// of window means (⟨F_n⟩/⟨n⟩), so that pressure = density × mean force per bead holds exactly.
#pragma once

#include "dem/measurement.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_model.h"
#include "dem/dem_system.h"
#include "geometry/wall_primitives.h"

#include <array>
#include <string>
#include <vector>

namespace magbrush::dem {

// One bead touching the plate at a map instant.
struct PlateContactBead
{
  std::int32_t id = 0;
  double u = 0, v = 0;       // centre in the plate plane (coordinates along the two in-plane axes) [m]
  double radius = 0;         // [m]
  double fn = 0;             // normal force on the plate [N] (> 0 pushing it away)
  double ft_u = 0, ft_v = 0; // tangential force on the plate [N]
};

struct PlateContactMap
{
  double time = 0, gap = 0, field = 0;
  std::vector<PlateContactBead> beads;
};

// One output row: means over an averaging window.
struct PlateCompressionRow
{
  double time = 0;           // mean sample time [s]
  double gap = 0;            // brush length [m]
  double field = 0;          // applied |B| at the stage [T]
  double fn = 0;             // normal force [N]
  double ft_u = 0, ft_v = 0; // tangential force components along the in-plane axes [N]
  double ft = 0;             // |mean tangential force| [N]
  double touching = 0;       // mean number of beads touching the plate
  long samples = 0;
};

class PlateCompression : public Measurement
{
public:
  // Throws std::invalid_argument when the scene lacks the named plate or stage, when the plate
  // is not normal to a coordinate axis, or when the box is not periodic along both in-plane
  // axes (the pressure needs the periodic area).
  explicit PlateCompression(const Case &c);

  // The scene calls for it: a box scene with planes named compression.plate and .stage.
  static bool applies(const Case &c);

  const char *name() const override { return "plate compression"; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;

  // Results so far (the current, unfinished window is not included).
  const std::vector<PlateCompressionRow> &rows() const { return rows_; }
  const std::vector<PlateContactMap> &maps() const { return maps_; }
  double area() const { return area_; }
  // The contact map now (for tests), and the latest sampled one.
  PlateContactMap contact_map(const DemSystem &system);
  const PlateContactMap &last_map() const { return last_map_; }
  // Brush length (plate gap) at time t.
  double gap(double t) const;

private:
  CompressionSettings settings_;
  PlaneWallPrimitive plate_, stage_;
  AppliedMagneticField field_;
  int normal_axis_ = 2;                 // the coordinate axis the plate normal lies along
  std::array<int, 2> in_plane_{{0, 1}}; // the two in-plane axes (u, v)
  double area_ = 0.0;                   // periodic area l_u × l_v [m²]
  std::size_t plate_wall_ = 0;          // index among the engine's walls (found at the first sample)
  bool wall_found_ = false;

  // The window being accumulated.
  PlateCompressionRow sum_;
  double next_map_ = 0.0;
  std::vector<PlateCompressionRow> rows_;
  std::vector<PlateContactMap> maps_;
  PlateContactMap last_map_; // the latest sample's map (written at the end)
  std::vector<WallContactRecord> records_;
  long samples_per_window_ = 1;

  void close_window();
  PlateCompressionRow window_mean(const PlateCompressionRow &sum) const;
  std::size_t find_plate_wall(const DemSystem &system) const;
  static void write_map(const std::string &path, const PlateContactMap &map, const std::array<int, 2> &axes);
};

} // namespace magbrush::dem
