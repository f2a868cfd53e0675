// The coordinate frame of the development nip, shared by the nip measurements.
//
//        sleeve centre S ──────── n ────────► drum centre C          (line of centres)
//                        |← Rs →|← gap →|← Rd →|
//                               P0 = S + (Rs + gap/2) n   (the gap centre)
//
// * n: unit vector from the sleeve centre to the drum centre;
// * t: the common tangent at the nip, oriented DOWNSTREAM (the way the sleeve surface moves
//   through the gap; counter-clockwise sleeve: t = ẑ × n);
// * x = (p − P0)·t: position along the nip, the paper's "distance from the centre of the
//   development gap" (Kawamoto Fig. 17–20). Negative x: inlet, positive x: outlet.
// * sleeve angle θ(p) = atan2((p−S)·t, (p−S)·n): angle at the sleeve centre from the line of
//   centres, positive downstream (chain inclination is binned by it).
// * drum angle ψ(p) = atan2((p−C)·t, (p−C)·(−n)): the same at the drum centre; a drum surface
//   point at ψ has x = Rd sin ψ and arc length Rd ψ from the gap centre.
//
// The roller axis is z; everything here works in the x-y plane of the case.
#pragma once

#include "dem/vector3.h"

#include "case/case_model.h"

namespace magbrush::dem {

struct NipFrame
{
  double sx = 0, sy = 0, sleeve_radius = 0; // sleeve centre and radius [m]
  double cx = 0, cy = 0, drum_radius = 0;   // drum centre and radius [m]
  double nx = 1, ny = 0;                    // unit line of centres, sleeve → drum
  double tx = 0, ty = 1;                    // unit downstream tangent at the nip
  double gap = 0;                           // development gap [m]
  double sleeve_omega = 0, drum_omega = 0;  // [rad/s], counter-clockwise positive
  double slab_depth = 0;                    // periodic length along z [m]

  // The frame of a case with a sleeve and a drum; throws (saying which is missing) otherwise.
  static NipFrame from_case(const Case &c);
  // Whether a case has what a nip frame needs (sleeve, drum, periodic slab along z).
  static bool applies(const Case &c);

  double x_along(double px, double py) const;       // [m]
  double sleeve_angle(double px, double py) const;  // [rad]
  double drum_angle(double px, double py) const;    // [rad]
  // The drum surface point at nip coordinate x: its arc length from the gap centre [m] and
  // the angle at the drum centre [rad]; the sleeve angle of the sleeve surface point at x.
  double drum_arc_of_x(double x) const;
  double drum_angle_of_x(double x) const;
  double sleeve_angle_of_x(double x) const;
  // The gap along the sleeve's radius at sleeve angle θ: from the sleeve surface to the drum
  // surface [m] (the development gap at θ = 0; NaN where that radius misses the drum).
  double radial_gap(double theta) const;
  // Sleeve surface speed minus drum surface speed along t at the nip (0.135 m/s in the paper).
  double relative_surface_speed() const;
  // Velocity of the drum surface material at (px, py) [m/s].
  Vector3 drum_surface_velocity(double px, double py) const;
};

} // namespace magbrush::dem
