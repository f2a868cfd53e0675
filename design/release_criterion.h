// A field criterion for release, from the field alone (seconds, no DEM): is a carrier bead
// resting on the sleeve still held there, angle by angle?
//
// A linear magnetisable sphere of radius a and permeability μ in a field B (no neighbours)
// carries the induced moment m = 4π a³ β B / μ0, β = (μ − 1)/(μ + 2), and feels
//
//      F = (m · ∇) B = (2π a³ β / μ0) ∇(B²)           (curl-free field)
//
// so per unit mass (ρ 4/3 π a³) its outward (radial) acceleration is
//
//      a_mag = (3 β / (2 μ0 ρ)) ∂(B²)/∂r
//
// at the bead's centre, r = R_sleeve + a. A bead carried round by the sleeve needs ω² r
// inward (the centrifugal term, outward in the sleeve's frame), and gravity g adds its
// outward component g · r̂. The bead is held while
//
//      a_net = a_mag + ω² r + g · r̂ < 0,
//
// and released where a_net > 0: the release arc. The field is the exact multipole ring of the
// case's poles (the stored FEM field reproduces it to ~2e-4 of the peak). What the criterion
// leaves out: the beads' mutual induction (a chain is held more strongly than one bead, the
// chain's moment per bead is larger), friction, the developer's own weight above the bead
// and its flow; it ranks layouts and places the lift-off, it does not give a released fraction.
#pragma once

#include "case/case_model.h"
#include "fields/multipole_ring.h"

#include <vector>

namespace magbrush {

struct ReleaseInputs
{
  double bead_radius = 0, bead_density = 0, bead_mu_r = 1; // [m], [kg/m³]
  double sleeve_radius = 0, omega = 0;                     // [m], [rad/s]
  double gx = 0, gy = -9.81;                               // gravity in the roller frame [m/s²]
  // The case's carrier population (mean diameter, its material), sleeve and dem.gravity.
  static ReleaseInputs from(const Case &c);
};

struct ReleaseProfile
{
  std::vector<double> angle;                              // [rad], [0, 2π)
  std::vector<double> B;                                  // |B| at the bead's centre [T]
  std::vector<double> magnetic, centrifugal, gravity, net; // outward accelerations [m/s²]
  struct Arc
  {
    double from = 0, to = 0; // [rad], counter-clockwise; `to` may exceed 2π
    double peak = 0, at = 0; // largest a_net on it [m/s²] and where
  };
  std::vector<Arc> arcs;     // where a_net > 0: not held
};

ReleaseProfile release_profile(const MultipoleRing &ring, const ReleaseInputs &in, double step);

// Within the window from → to (counter-clockwise): the release arcs that overlap it, and the
// largest a_net there (≤ 0: held all through it, by that margin).
struct ReleaseVerdict
{
  bool releases = false;
  double peak = 0, at = 0;                // largest a_net in the window [m/s²] and where
  std::vector<ReleaseProfile::Arc> arcs;  // clipped to the window
};
ReleaseVerdict release_in_window(const ReleaseProfile &p, double from, double to);

} // namespace magbrush
