// Case keys of module "geometry" (the list of modules and why it is explicit: case_keys.h).
// The geometry of the developer unit: magnet roller, sleeve, drum, blades and guides, plane
// walls. Read by geometry/ (the Gmsh meshes and the analytic DEM walls), by the field solver
// (materials of the magnetostatic and electrostatic problems) and by the DEM (wall motion).
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> geometry_keys()
{
  return {
      section("roller", "The magnet roller: a magnetised annulus on an optional soft-iron shaft (Kweon eq. 9-10)."),
      quantity("roller.shaft_radius", D::length, "Radius of the soft-iron shaft (0 = none).")
          .def("0 mm").non_negative().affects(A::magnetic),
      number("roller.shaft_mu_r", "Relative permeability of the shaft (large = ideal iron).")
          .def("1000").min(1.0).affects(A::magnetic),
      quantity("roller.magnet_radius", D::length, "Outer radius of the magnet annulus.")
          .required().positive().affects(A::magnetic),
      number("roller.magnet_mu_r", "Recoil permeability of the magnet material.")
          .def("1").min(1.0).affects(A::magnetic),
      quantity("roller.shape_factor", D::inverse_angle_squared,
               "Default Gaussian shape factor alpha of the poles, M(theta) ~ exp(-alpha (theta-phi)^2).")
          .def("10 rad^-2").positive().affects(A::magnetic),
      list("roller.poles", "The poles: name, angle, strength (sign or polarity gives N/S), shape factor.")
          .required().affects(A::magnetic),
      text("roller.poles[].name", "Pole name, e.g. N1 (address it in overrides: roller.poles.N1.angle).")
          .required().affects(A::magnetic),
      quantity("roller.poles[].angle", D::angle, "Pole centre, counter-clockwise from +x.")
          .required().min(0.0).max(2.0 * pi, false).affects(A::magnetic),
      quantity("roller.poles[].strength", D::magnetisation,
               "Peak radial magnetisation M_i; > 0 north (outward), < 0 south, or give polarity.")
          .required().affects(A::magnetic),
      choice("roller.poles[].polarity", {"N", "S"},
             "Optional: N or S; the strength's sign must agree or the strength is unsigned.")
          .affects(A::magnetic),
      quantity("roller.poles[].shape_factor", D::inverse_angle_squared, "Shape factor alpha of this pole.")
          .def("<roller.shape_factor>").positive().affects(A::magnetic),

      section("sleeve", "The non-magnetic rotating sleeve around the roller (give radius or diameter)."),
      quantity("sleeve.radius", D::length, "Outer radius.").positive().affects(A::both),
      quantity("sleeve.diameter", D::length, "Outer diameter (alternative to radius).")
          .positive().affects(A::both),
      quantity("sleeve.thickness", D::length, "Wall thickness (the magnet must fit inside).")
          .def("0 mm").non_negative().affects(A::both),
      quantity("sleeve.rpm", D::angular_velocity, "Rotation speed; > 0 counter-clockwise seen from +z.")
          .def("0 rpm"),
      quantity("sleeve.spin_up_time", D::time,
               "DEM: the sleeve starts from rest at t = 0 and reaches its speed linearly over this time (0 = at once).")
          .def("0 s").non_negative(),

      section("drum", "The photoreceptor drum facing the sleeve across the development gap (give radius or diameter)."),
      quantity("drum.radius", D::length, "Outer radius of the photoconductor surface.")
          .positive().affects(A::electric),
      quantity("drum.diameter", D::length, "Outer diameter (alternative to radius).")
          .positive().affects(A::electric),
      quantity("drum.rpm", D::angular_velocity, "Rotation speed; > 0 counter-clockwise seen from +z.")
          .def("0 rpm"),
      quantity("drum.spin_up_time", D::time,
               "DEM: the drum starts from rest at t = 0 and reaches its speed linearly over this time (0 = at once).")
          .def("0 s").non_negative(),
      quantity("drum.gap", D::length, "Development gap: sleeve surface to drum surface along the line of centres.")
          .required().affects(A::electric),
      quantity("drum.angle", D::angle, "Direction of the drum centre seen from the roller centre.")
          .def("0 deg").min(0.0).max(2.0 * pi, false).affects(A::electric),
      quantity("drum.pc_thickness", D::length, "Photoconductor layer thickness (0 = bare conductor).")
          .def("0 um").non_negative().affects(A::electric),
      number("drum.pc_eps_r", "Photoconductor relative permittivity.").def("3").min(1.0).affects(A::electric),

      list("blades", "Doctor blade and guide walls: either a profile polygon, or angle + gap + thickness + length "
                     "(a radial plate whose tip is `gap` from the sleeve)."),
      text("blades[].name", "Wall name.").required(),
      choice("blades[].kind", {"doctor_blade", "guide"}, "A doctor blade meters the developer; a guide only walls it.")
          .def("guide"),
      Key("blades[].profile", KeyType::polygon, "Counter-clockwise polygon [[x, y], ...] in the roller frame.")
          .dim(D::length).affects(A::magnetic),
      quantity("blades[].angle", D::angle, "Generated blade: direction of its centre line from the roller centre.")
          .min(0.0).max(2.0 * pi, false).affects(A::magnetic),
      quantity("blades[].gap", D::length,
               "Nearest distance to the sleeve surface (required for generated blades; checked against a profile).")
          .affects(A::magnetic),
      quantity("blades[].thickness", D::length, "Generated blade: thickness across the centre line.")
          .positive().affects(A::magnetic),
      quantity("blades[].length", D::length, "Generated blade: radial length from the tip outward.")
          .positive().affects(A::magnetic),
      number("blades[].mu_r", "Relative permeability; > 1 makes a magnetic blade (enters the magnetostatic problem).")
          .def("1").min(1.0).affects(A::magnetic),
      text("blades[].material", "Contact material (key in materials).").def("wall"),

      list("planes", "Explicit plane walls (box scenes): point, normal into the particle side, optional path."),
      text("planes[].name", "Wall name.").required(),
      vector3("planes[].point", D::length, "A point on the plane at t = 0.").def("[0, 0, 0]"),
      vector3("planes[].normal", D::dimensionless, "Normal pointing into the particle side (normalised).")
          .def("[0, 0, 1]"),
      text("planes[].material", "Contact material (key in materials).").def("wall"),
      list("planes[].path", "Prescribed motion: piecewise-linear (time, displacement) samples, times increasing."),
      quantity("planes[].path[].time", D::time, "Sample time.").required().non_negative(),
      vector3("planes[].path[].displacement", D::length, "Displacement of the plane point at that time.")
          .required(),
  };
}

} // namespace magbrush::case_keys
