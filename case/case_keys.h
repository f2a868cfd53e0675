// The case keys, declared by the module whose code reads them.
//
// Each module declares its keys once, with type, unit, default, range, documentation and the
// stored field they change, in its own file case/case_keys_<module>.cpp. The schema
// (case_schema()) is the union of these declarations, in the order of key_declarations()
// below, which is also the order of docs/case_reference.md and of `magbrush check --explain`:
//
//   scene          case_keys_scene.cpp          name, scene, measured_flux_file   (the driver, the report)
//   geometry       case_keys_geometry.cpp       roller, sleeve, drum, blades, planes
//                                               (geometry/ meshes and walls, the field solver)
//   particles      case_keys_particles.cpp      materials, populations (dem/ contacts and insertion,
//                                               the magnetics' mu_r and saturation)
//   electric       case_keys_electric.cpp       electric             (field_solver/ electrostatics)
//   applied_field  case_keys_applied_field.cpp  applied_field        (fields/applied_magnetic_field)
//   field_solver   case_keys_field_solver.cpp   field                (field_solver/, the field grids)
//   dem            case_keys_dem.cpp            dem.* of the engine  (dem/: step, walls, guards)
//   magnetics      case_keys_magnetics.cpp      dem.magnetic_*       (magnetics/magnetic_settings)
//   flow           case_keys_flow.cpp           inflow, outflow, flow_report (dem/ particles entering and leaving)
//   measurements   case_keys_measurements.cpp   nip, compression     (dem/measurements/)
//   output         case_keys_output.cpp         output               (the driver, dem/ snapshots)
//
// A section is declared by the module that declares its first keys; a module may add keys to
// another's section (the magnetics' dem.magnetic_* keys live in the dem section), as long as
// the section comes earlier in the list: parents before children.
//
// Why an explicit list, and why every file is in case/:
//  * Every program that reads a case must validate it against ALL keys: the driver
//    (`magbrush`), magbrush-field (which never links the DEM), magbrush-dem and the tests that
//    only link magbrush_case. case/ is the lowest library: it cannot call into dem/ or
//    magnetics/, and magbrush-field does not link them, so declarations placed there would be
//    missing from some programs. Hence the per-module files sit in case/, named after the
//    module that reads the keys.
//  * Self-registration (a static object in each file that adds its keys at start-up) would
//    be lost silently: magbrush_case is a static library, and the linker leaves out an
//    object file that nothing refers to, so a program would run with a schema missing a
//    module, and unknown-key errors would appear only in that program. An explicit list of
//    functions cannot lose a module quietly: a declaration file left out of the build is a
//    link error; a function left out of the list fails every case load, because the parser
//    reads every key and an undeclared one is a logic error ("case parser: no schema key
//    dem.magnetic_model"). The schema also checks on assembly that no key is declared twice
//    and that every key's section comes before it, and tests/case/test_module_defaults.cpp
//    checks that the schema is exactly the declarations, in order.
#pragma once

#include "case/case_schema.h"

#include <string>
#include <utility>
#include <vector>

namespace magbrush {

// One module's declarations: its name, its file (for messages and the docs) and the function
// that lists its keys, parents before children.
struct KeyDeclaration
{
  const char *module;
  const char *file;
  std::vector<KeySpec> (*declare)();
};

// All modules' declarations, in the order of the reference documentation.
const std::vector<KeyDeclaration> &key_declarations();

// The per-module declaration functions (one in each case/case_keys_<module>.cpp).
namespace case_keys {
std::vector<KeySpec> scene_keys();
std::vector<KeySpec> geometry_keys();
std::vector<KeySpec> particle_keys();
std::vector<KeySpec> electric_keys();
std::vector<KeySpec> applied_field_keys();
std::vector<KeySpec> field_solver_keys();
std::vector<KeySpec> dem_keys();
std::vector<KeySpec> magnetic_keys();
std::vector<KeySpec> flow_keys();
std::vector<KeySpec> measurement_keys();
std::vector<KeySpec> output_keys();
} // namespace case_keys

// A small builder, so that each declaration file reads like a reference card:
//   quantity("sleeve.thickness", D::length, "Wall thickness.").def("0 mm").non_negative()
// Defaults are written as in a case file and parsed by the same code as user input.
namespace case_keys {

constexpr double pi = 3.14159265358979323846;

struct Key
{
  KeySpec spec;
  Key(std::string path, KeyType type, std::string doc)
  {
    spec.path = std::move(path);
    spec.type = type;
    spec.doc = std::move(doc);
  }
  Key &dim(Dimension d) { spec.dimension = d; return *this; }
  Key &def(std::string text) { spec.default_text = std::move(text); return *this; }
  Key &required() { spec.required = true; return *this; }
  Key &min(double v, bool inclusive = true) { spec.min = v; spec.min_inclusive = inclusive; return *this; }
  Key &max(double v, bool inclusive = true) { spec.max = v; spec.max_inclusive = inclusive; return *this; }
  Key &positive() { return min(0.0, false); }
  Key &non_negative() { return min(0.0, true); }
  Key &choices(std::vector<std::string> c) { spec.choices = std::move(c); return *this; }
  Key &affects(Affects a) { spec.affects = a; return *this; }
  operator KeySpec() const { return spec; }
};

inline Key section(std::string path, std::string doc) { return Key(std::move(path), KeyType::section, std::move(doc)); }
inline Key list(std::string path, std::string doc) { return Key(std::move(path), KeyType::list, std::move(doc)); }
inline Key map(std::string path, std::string doc) { return Key(std::move(path), KeyType::map, std::move(doc)); }
inline Key quantity(std::string path, Dimension d, std::string doc)
{
  return Key(std::move(path), KeyType::quantity, std::move(doc)).dim(d);
}
inline Key number(std::string path, std::string doc)
{
  return quantity(std::move(path), Dimension::dimensionless, std::move(doc));
}
inline Key integer(std::string path, std::string doc) { return Key(std::move(path), KeyType::integer, std::move(doc)); }
inline Key boolean(std::string path, std::string doc) { return Key(std::move(path), KeyType::boolean, std::move(doc)); }
inline Key text(std::string path, std::string doc) { return Key(std::move(path), KeyType::string, std::move(doc)); }
inline Key choice(std::string path, std::vector<std::string> c, std::string doc)
{
  return Key(std::move(path), KeyType::choice, std::move(doc)).choices(std::move(c));
}
inline Key vector3(std::string path, Dimension d, std::string doc)
{
  return Key(std::move(path), KeyType::vector3, std::move(doc)).dim(d);
}

using D = Dimension;
using A = Affects;

} // namespace case_keys

} // namespace magbrush
