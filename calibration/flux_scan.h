// Gaussmeter scans of the sleeve: the normal (Bn) and tangential (Bt) flux density against the
// angle around the roller, as a CSV export.
//
// Accepted files:
//   * '#' comment lines anywhere (kept in FluxScan::comments), blank lines ignored;
//   * a header line naming the columns, in any order, extra columns ignored:
//       angle: angle, theta, phi, deg, degrees, position, pos, ...
//       Bn:    Bn, B_n, Br, B_r, Bnormal, normal, ...
//       Bt:    Bt, B_t, Btheta, B_theta, Btan, tangential, ... (optional: a Bn-only scan is fine)
//     with the unit in the name (angle_deg, Bn_mT, "Bn [G]", "Bt (mT)", Bn/T); without a header
//     the columns are angle, Bn[, Bt] in that order;
//   * separators: comma, semicolon, tab or blanks (taken from the header / first data line);
//     with a separator other than the comma, a decimal comma is accepted ("1,25").
// Units: angle deg | rad, field T | mT | G | kG. A unit given as an option overrides the header
// (with a note); with neither, degrees and millitesla are assumed (with a note).
// A scan whose angle wraps around (…, 359, 0, 1, …) is unwrapped (with a note).
// Angular origin and direction: the roller-frame angle is
//     θ_roller = (clockwise ? −θ_scan : θ_scan) + angle_offset,
// and a clockwise scan also flips the sign of Bt (Bt is positive counter-clockwise).
// Errors (ScanError, "file:line: what was found, what was expected, what to do"): unreadable
// file, missing angle or Bn column, non-numeric or missing cells, non-finite values, fewer than
// min_points samples, angles that are not strictly monotone or span more than one turn.
#pragma once

#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {

class ScanError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

struct ScanReadOptions
{
  std::string angle_unit;      // "" = from the header; else "deg" | "rad"
  std::string field_unit;      // "" = from the header; else "T" | "mT" | "G" | "kG"
  double angle_offset = 0.0;   // [rad], added after the direction is applied
  bool clockwise = false;      // the scan's angle runs clockwise seen from +z
  bool flip_tangential = false; // the probe's Bt is positive clockwise (negate it)
  size_t min_points = 8;
  bool require_tangential = false;
};

struct FluxScan
{
  std::string source;            // file name (for messages)
  std::vector<double> angle;     // roller-frame angle [rad], in file order
  std::vector<double> Bn, Bt;    // [T]; Bt empty when the file has no tangential column
  std::vector<int> line;         // source line of every sample
  std::string angle_column, bn_column, bt_column; // header names as found
  std::string angle_unit, field_unit;             // units used ("deg", "mT", ...)
  std::vector<std::string> comments;              // '#' lines, without the '#'
  std::vector<std::string> notes;                 // assumptions the reader made
  bool has_tangential() const { return !Bt.empty(); }
  size_t size() const { return angle.size(); }
};

FluxScan read_flux_scan(const std::string &path, const ScanReadOptions &options = {});
FluxScan parse_flux_scan(std::istream &in, const std::string &name,
                         const ScanReadOptions &options = {});

// The same scan with `angle` added to every roller-frame angle: an encoder offset found after
// reading it (by the pole fit), so that θ_roller = θ_scan + angle_offset + angle.
FluxScan rotated_scan(FluxScan scan, double angle);

// Unit factors (throw ScanError naming the accepted units).
double angle_unit_factor(const std::string &unit); // to rad
double field_unit_factor(const std::string &unit); // to T

// Values of a periodic profile (angles in rad, any order, one turn at most) at other angles,
// by periodic cubic (Catmull–Rom) interpolation — used to put an FEM profile on the scan's angles.
std::vector<double> interpolate_periodic(const std::vector<double> &angle,
                                         const std::vector<double> &value,
                                         const std::vector<double> &at);

} // namespace magbrush
