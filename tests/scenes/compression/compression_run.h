// Running Kawamoto's compression scene in-process, as `magbrush-dem` does (the case, the
// induced-dipole magnetics, the plate measurement), for the regression test and the benchmark.
//
// The reduced protocol (what the regression test asserts on, in a small periodic square):
//   0–0.3 ms      field ramp 0 → 130 mT, plate held at 1.0 mm (the tallest chain tips touch it)
//   0.4–2.4 ms    plate down to 0.6 mm at 0.2 m/s                       → F_n against length
//   2.4–2.7 ms    hold at 130 mT                                        → density, force per bead
//   then, with `sweep_and_slide`:
//   2.7–4.2 ms    B stepped 130 → 80 → 50 → 30 → 20 mT, 0.3 ms each       → F_n against B
//   4.2–4.5 ms    back to 130 mT and held
//   4.5–7.7 ms    plate slid 0.8 mm sideways at 0.25 m/s                 → F_t / F_n over the
//                 last 0.25 mm (the ratio saturates after ~0.35 mm of sliding)
#pragma once

#include "dem/measurements/plate_compression.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::compression_test {

struct ReducedScene
{
  int diameter_um = 60;
  double box_mm = 0.7; // periodic square side
  unsigned long seed = 1;
  bool sweep_and_slide = true;
  double time_step = 3.5e-8; // below the 3.8e-8 s limit of the 42 um beads
  // true: the paper's magnetics (A9–A11 truncated at its interaction sphere 8 diameters wide:
  // far field none, cutoff 4 d, plus our slab tail); false: the case's, i.e. the project
  // defaults (no cutoff: the cell-multipole far field).
  bool paper_magnetics = true;
  // With sweep_and_slide: false ends the run after the field sweep (3.9 ms), without the slide.
  bool slide = true;
  // The carrier's saturation magnetisation M_s [A/m] (Fröhlich–Kennelly); 0 = the case's
  // linear μr.
  double saturation_magnetisation = 0.0;
};

// Kawamoto's bead count of this size on 2 x 2 mm² (equal mass per area), scaled to the box.
long bead_count(int diameter_um, double box_mm);

// The phase windows of the reduced protocol [s].
struct Window
{
  double t0, t1;
};
constexpr Window descent{0.4e-3, 2.4e-3};
constexpr Window hold_130{2.5e-3, 2.68e-3};
struct FieldHold
{
  double field_mT;
  Window w;
};
const std::vector<FieldHold> &field_holds();   // 130, 80, 50, 30, 20 mT (the second half of each hold)
constexpr Window slide_steady{6.7e-3, 7.7e-3}; // the last 0.25 mm of the slide

Case reduced_case(const ReducedScene &s, const std::string &output_dir);

// Which plate contacts slide, over the steady part of the slide (slide_steady), from the
// kinematics alone: a contact whose contact point moves over the plate faster than
// `sliding_speed` slides (Coulomb: it pulls the plate along its slip with μ F_n). S = share of
// the normal force on sliding contacts; D = the same weighted with the cosine between each
// slip and −x̂ (the plate slides along +x over beads that lag behind: their slip relative to
// the plate is along −x). Then |F_t|/F_n ≥ |F_t·x̂|/F_n ≥ μ (D − (1 − S)), a bound that does
// not use the forces the ratio is made of.
struct PlateSliding
{
  static constexpr double sliding_speed = 0.025; // [m/s]: a tenth of the plate's 0.25 m/s
  double fn = 0.0, fn_sliding = 0.0, fn_sliding_along = 0.0; // sums over samples and contacts
  long samples = 0;
  double share() const { return fn > 0.0 ? fn_sliding / fn : 0.0; }
  double along_share() const { return fn > 0.0 ? fn_sliding_along / fn : 0.0; }
};

struct RunResult
{
  std::vector<dem::PlateCompressionRow> rows;
  double area = 0.0; // [m²]
  long beads = 0;
  double wall_s = 0.0;     // run() wall time
  double magnetic_s = 0.0; // of which the magnetic term
  std::string log;
  PlateSliding sliding; // over slide_steady (empty without the slide)
};

// Runs the case (fresh: insert, settle, run to dem.duration) with the magnetics and the plate
// measurement; `threads` 0 = the OpenMP default.
RunResult run_case(const Case &c, const std::string &output_dir, int threads = 0);

// Means of row quantities over a time window (rows whose mean time lies inside it).
struct WindowMean
{
  double fn = 0, ft = 0, touching = 0, field = 0, gap = 0;
  long rows = 0;
};
WindowMean mean_over(const std::vector<dem::PlateCompressionRow> &rows, Window w);
// Mean over the descent rows whose brush length lies in [lo, hi] [m].
WindowMean mean_at_length(const std::vector<dem::PlateCompressionRow> &rows, double lo, double hi);

// Least-squares exponent k of y = c x^k.
double power_law_exponent(const std::vector<double> &x, const std::vector<double> &y);

} // namespace magbrush::compression_test
